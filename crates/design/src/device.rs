//! Device files: a device of several Cartesian axes, each with the model
//! (or the poses) its couplings are designed for.
//!
//! ```toml
//! name = "Excalibur, three Cartesian axes"
//! [[axis]]
//! name = "x"
//! models = ["excalibur.toml"]   # relative to this file; several = poses
//! [[axis]]
//! name = "y"
//! models = ["excalibur.toml"]
//! ```

use crate::model::{DeviceModel, ModelError};
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// The most axes a device file may give: what a board's frames carry.
pub const MAX_AXES: usize = 3;

/// A device of 1 to [`MAX_AXES`] Cartesian axes.
#[derive(Clone, Debug, PartialEq)]
pub struct Device {
    /// A human-readable name.
    pub name: String,
    /// Each axis, x first.
    pub axes: Vec<DeviceAxis>,
}

/// One axis of a [`Device`]: the model of each pose its coupling must be
/// stable in (one model: one pose).
#[derive(Clone, Debug, PartialEq)]
pub struct DeviceAxis {
    /// The axis's name (`x`, `y`, `z`, ...), unique in the device.
    pub name: String,
    /// The model files, resolved against the device file's folder.
    pub model_paths: Vec<PathBuf>,
    /// The models, read and checked.
    pub models: Vec<DeviceModel>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawDevice {
    name: Option<String>,
    axis: Vec<RawAxis>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawAxis {
    name: String,
    models: Vec<PathBuf>,
}

impl Device {
    /// Read a device file and every model it names; an error names the
    /// file, the axis and what is wrong.
    pub fn load(path: &Path) -> Result<Self, ModelError> {
        let (text, source) = crate::model::read(path)?;
        let folder = path.parent().unwrap_or(Path::new("."));
        Self::from_toml(&text, &source, |p| {
            let p = folder.join(p);
            DeviceModel::load(&p).map(|m| (p, m))
        })
    }

    /// Parse device text; `source` names it in errors and `load` reads a
    /// model path as written in the file.
    ///
    /// # Examples
    ///
    /// ```
    /// use twoport_design::{Device, DeviceModel};
    /// let text = "name = \"xy table\"\n\
    ///             [[axis]]\nname = \"x\"\nmodels = [\"a.toml\"]\n\
    ///             [[axis]]\nname = \"y\"\nmodels = [\"a.toml\", \"b.toml\"]\n";
    /// let load = |p: &std::path::Path| DeviceModel::excalibur().map(|m| (p.to_path_buf(), m));
    /// let d = Device::from_toml(text, "xy.toml", load)?;
    /// assert_eq!(d.axes.len(), 2);
    /// assert_eq!(d.axes[1].models.len(), 2); // y is proven in two poses
    /// let twice = text.replace("\"y\"", "\"x\"");
    /// let e = Device::from_toml(&twice, "xy.toml", load).unwrap_err();
    /// assert!(e.to_string().contains("axis 1 (x): the name is already axis 0's"));
    /// # Ok::<(), twoport_design::ModelError>(())
    /// ```
    pub fn from_toml(
        text: &str,
        source: &str,
        mut load: impl FnMut(&Path) -> Result<(PathBuf, DeviceModel), ModelError>,
    ) -> Result<Self, ModelError> {
        let err = |message: String| ModelError {
            source: source.to_string(),
            message,
        };
        let raw: RawDevice = toml::from_str(text).map_err(|e| err(e.to_string()))?;
        if raw.axis.is_empty() || raw.axis.len() > MAX_AXES {
            return Err(err(format!(
                "{} [[axis]] tables: a device has 1 to {MAX_AXES}",
                raw.axis.len()
            )));
        }
        let mut axes: Vec<DeviceAxis> = Vec::with_capacity(raw.axis.len());
        for (i, a) in raw.axis.into_iter().enumerate() {
            let at = |what: &str| err(format!("axis {i} ({}): {what}", a.name));
            if a.name.trim().is_empty() {
                return Err(at("the name is empty"));
            }
            if let Some(j) = axes.iter().position(|b| b.name == a.name) {
                return Err(at(&format!("the name is already axis {j}'s")));
            }
            if a.models.is_empty() {
                return Err(at("models is empty: give at least one model file"));
            }
            let mut axis = DeviceAxis {
                name: a.name.clone(),
                model_paths: Vec::new(),
                models: Vec::new(),
            };
            for p in &a.models {
                let (path, model) = load(p).map_err(|e| at(&e.to_string()))?;
                axis.model_paths.push(path);
                axis.models.push(model);
            }
            axes.push(axis);
        }
        let period = axes[0].models[0].period_s;
        for (i, a) in axes.iter().enumerate() {
            if let Some(m) = a.models.iter().find(|m| m.period_s != period) {
                return Err(err(format!(
                    "axis {i} ({}): {} has period_s = {} but axis 0's first model {period}: \
                     the axes share one control tick",
                    a.name, m.name, m.period_s
                )));
            }
        }
        Ok(Device {
            name: raw.name.unwrap_or_else(|| source.to_string()),
            axes,
        })
    }
}
