//! What every command shares: the designer opened from the common
//! arguments, a report printed as JSON or text, and the run over a device
//! file's axes.

use crate::args::*;
use serde::Serialize;
use serde_json::{json, Value};
use std::fmt::Display;
use twoport_design::designer::Pose;
use twoport_design::device::DeviceAxis;
use twoport_design::network::HumanBound;
use twoport_design::{Designer, Device, DeviceModel};

/// The designer on the command's poses: the axis of a device file it runs
/// on, or its `--model` files.
pub(crate) fn designer(c: &Common, axis: Option<&DeviceAxis>) -> Result<Designer, String> {
    if let Some(t) = c.period.filter(|t| !(t.is_finite() && *t > 0.0)) {
        return Err(format!(
            "--period {t}: must be a positive number of seconds"
        ));
    }
    let mut models = match axis {
        Some(a) => a.models.clone(),
        None => c
            .model
            .iter()
            .map(|path| DeviceModel::load_or_excalibur(path).map_err(|e| e.to_string()))
            .collect::<Result<Vec<_>, _>>()?,
    };
    if let Some(l) = c.latency {
        for m in &mut models {
            let s = l.seconds(c.period.unwrap_or(m.period_s));
            if s > twoport_design::model::MAX_LATENCY_S {
                return Err(format!(
                    "--latency {s} s: at most {} s",
                    twoport_design::model::MAX_LATENCY_S
                ));
            }
            m.latency_s = s;
        }
    }
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
    if let Some(l) = c.latency {
        let s = l.seconds(file.period_s);
        if s > twoport_design::model::MAX_LATENCY_S {
            return Err(format!(
                "--latency {s} s: at most {} s",
                twoport_design::model::MAX_LATENCY_S
            ));
        }
        file.latency_s = s;
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

/// What a command answers: one value that prints as JSON (`--json`) or as
/// text, so that the two never say different things.
pub(crate) trait Report {
    /// The report as one JSON value.
    fn json(&self) -> Result<Value, String>;
    /// The report as text.
    fn text(&self) -> String;
}

impl<T: Serialize + Display> Report for T {
    fn json(&self) -> Result<Value, String> {
        serde_json::to_value(self).map_err(|e| e.to_string())
    }
    fn text(&self) -> String {
        self.to_string()
    }
}

/// A command's report, or why it has none.
pub(crate) type Reported = Result<Box<dyn Report>, String>;

/// `report`, boxed as a command returns it.
pub(crate) fn reported(report: impl Report + 'static) -> Reported {
    Ok(Box::new(report))
}

/// Print `report` as JSON or as text.
pub(crate) fn print(json: bool, report: &dyn Report) -> Result<(), String> {
    if json {
        say!("{}\n", report.json()?);
    } else {
        say!("{}\n", report.text());
    }
    Ok(())
}

/// Print a command's report, or pass on why it has none.
pub(crate) fn show(json: bool, report: Reported) -> Result<(), String> {
    print(json, &*report?)
}

/// A command run on the `--model` files (no axis), or on one axis of a
/// device file.
pub(crate) type OnAxis<A> = fn(&A, Option<&DeviceAxis>) -> Reported;

/// `run` on `args` and its report printed; given a device file, `run` on
/// each of its axes in turn: the text under a heading per axis, the JSON
/// as one object with an entry per axis.
pub(crate) fn each_axis<A: HasCommon>(args: &A, run: OnAxis<A>) -> Result<(), String> {
    let c = args.common();
    let Some(path) = &c.device else {
        return show(c.json, run(args, None));
    };
    let device = Device::load(path).map_err(|e| e.to_string())?;
    let mut axes = Vec::new();
    for axis in &device.axes {
        let report = run(args, Some(axis))
            .map_err(|e| format!("{}, axis {}: {e}", path.display(), axis.name))?;
        if c.json {
            let mut v = report.json()?;
            v["axis"] = json!(axis.name);
            axes.push(v);
        } else {
            if !args.rust() {
                say!("axis {}:\n", axis.name);
            }
            print(false, &*report)?;
        }
    }
    if c.json {
        say!("{}\n", json!({"device": device.name, "axes": axes}));
    }
    Ok(())
}

/// `run` on `args`, refusing a device file: the command draws one axis.
pub(crate) fn one_axis<A: HasCommon>(args: &A, run: OnAxis<A>) -> Result<(), String> {
    let c = args.common();
    match &c.device {
        Some(p) => Err(format!(
            "--device {}: this command draws one axis; give that axis's --model",
            p.display()
        )),
        None => show(c.json, run(args, None)),
    }
}
