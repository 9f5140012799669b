//! What every command shares: the designer opened from the common
//! arguments, and a report printed as JSON or text.

use crate::args::*;
use serde::Serialize;
use serde_json::json;
use std::fmt::Display;
use twoport_design::designer::Pose;
use twoport_design::network::HumanBound;
use twoport_design::{Designer, DeviceModel};

/// The designer on the command's poses: its `--model` files, or the axis
/// of a device file it runs on.
pub(crate) fn designer(c: &Common) -> Result<Designer, String> {
    let models = match &c.axis {
        Some(a) => a.models.iter().map(|(_, m)| m.clone()).collect(),
        None => c
            .model
            .iter()
            .map(|path| DeviceModel::load_or_excalibur(path).map_err(|e| e.to_string()))
            .collect::<Result<Vec<_>, _>>()?,
    };
    let human = (!c.no_human).then_some(HumanBound::PAPER);
    Designer::new(models, c.period, human).map_err(|e| e.to_string())
}

/// The linkage file of `--device`, at `--period` where one is given.
pub(crate) fn linkage_file(c: &Common) -> Result<twoport_design::linkage::LinkageFile, String> {
    let path = c.device.as_ref().ok_or("--device: a linkage file")?;
    let mut file = twoport_design::linkage::LinkageFile::load(path).map_err(|e| e.to_string())?;
    if let Some(t) = c.period {
        if !(t.is_finite() && t > 0.0) {
            return Err(format!("--period {t}: must be finite and > 0"));
        }
        file.period_s = t;
    }
    Ok(file)
}

/// The one pose of a command that takes one.
pub(crate) fn single<'a>(d: &'a Designer, command: &str) -> Result<&'a Pose, String> {
    match d.poses() {
        [p] => Ok(p),
        _ => Err(format!("{command} takes one --model")),
    }
}

/// Print `report`: its JSON (into the device's one object, on a device
/// file's axis), or its text.
pub(crate) fn emit(c: &Common, report: &(impl Serialize + Display)) -> Result<(), String> {
    if !c.json {
        say!("{report}\n");
        return Ok(());
    }
    let mut v = serde_json::to_value(report).map_err(|e| e.to_string())?;
    match &c.axis {
        Some(a) => {
            v["axis"] = json!(a.name);
            a.out.borrow_mut().push(v);
        }
        None => say!("{v}\n"),
    }
    Ok(())
}

/// A command's own output: its JSON and its text.
pub(crate) struct Printed(pub(crate) serde_json::Value, pub(crate) String);

impl Serialize for Printed {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.0.serialize(s)
    }
}

impl Display for Printed {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.1)
    }
}
