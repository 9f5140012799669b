//! Scene files: what to simulate, and only the effects named.

mod check;
mod effects;
mod parse;
mod spec;

pub use effects::*;
pub use parse::{apply_set, checked, parse_toml, read, SceneError};
pub use spec::*;

use serde::Deserialize;
use std::path::Path;
use twoport_control::servo::{AdmittanceGains, Display, Gains, ImpedanceGains};

/// A scene, as read from TOML. Every section but `display`, `coupling` and
/// `ve` has defaults; unknown keys are errors.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// A name for reports.
    #[serde(default)]
    pub name: String,
    /// How many axes the device has: 1 here (absent means 1); a scene of
    /// three is an [`XyzScene`](crate::engine::xyz::XyzScene).
    pub axes: Option<u8>,
    /// Simulated time (s).
    #[serde(default = "default_duration")]
    pub duration_s: f64,
    /// Control period (s); 1 ms by default (see [`Scene::period`]).
    pub period_s: Option<f64>,
    /// The device.
    #[serde(default)]
    pub plant: PlantSpec,
    /// How the plant is advanced.
    #[serde(default)]
    pub integrator: IntegratorSpec,
    /// Impedance or admittance display.
    pub display: Display,
    /// Coupling (and regulator) gains.
    pub coupling: Coupling,
    /// The virtual environment.
    pub ve: VeSpec,
    /// The human operator.
    #[serde(default)]
    pub human: HumanSpec,
    /// Effects to simulate; none by default.
    #[serde(default)]
    pub effects: Effects,
    /// The time-domain passivity layer; absent means none.
    pub passivity: Option<PassivitySpec>,
}

impl Scene {
    /// The control period the scene runs at (s).
    pub fn period(&self) -> f64 {
        self.period_s.unwrap_or(1e-3)
    }

    /// The scene's device model, [`twoport_design::DeviceModel::load_or_excalibur`]; the
    /// error names `plant.model`.
    pub fn device_model(&self) -> Result<twoport_design::DeviceModel, String> {
        twoport_design::DeviceModel::load_or_excalibur(&self.plant.model)
            .map_err(|e| format!("plant.model: {e}"))
    }

    /// Read a scene file, apply `--set` overrides, and check it.
    pub fn load(path: &Path, sets: &[String]) -> Result<Self, SceneError> {
        Self::parse(&read(path)?, &path.display().to_string(), sets)
    }

    /// Parse scene text; `source` names it in errors.
    pub fn parse(text: &str, source: &str, sets: &[String]) -> Result<Self, SceneError> {
        checked(parse_toml(text, source, sets)?, source, Self::check)
    }
    /// Whether any effect makes the plant nonlinear (and so sub-stepped).
    pub fn nonlinear(&self) -> bool {
        let e = &self.effects;
        e.coulomb.is_some()
            || e.cogging.is_some()
            || e.cable_slack.is_some()
            || e.hard_stop.is_some()
    }
}

impl Scene {
    /// The servo's gains: the one reading of `[coupling]` (checked by
    /// validation, so a missing gain cannot reach here from a loaded scene;
    /// it reads as zero, which the laws refuse where zero is invalid).
    pub fn gains(&self) -> Gains {
        let c = &self.coupling;
        let g = |v: Option<f64>| v.unwrap_or(0.0) as f32;
        match self.display {
            Display::Impedance => ImpedanceGains::new(g(c.k), c.b as f32).into(),
            Display::Admittance => {
                AdmittanceGains::new(g(c.kp), g(c.bp), g(c.m), c.b as f32).into()
            }
        }
    }
}

fn default_duration() -> f64 {
    10.0
}
