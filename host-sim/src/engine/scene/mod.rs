//! Scene files: what to simulate, and only the effects named.

mod check;
mod effects;
mod identify;
mod parse;
mod spec;

pub use effects::*;
pub use identify::IdentifySpec;
pub use parse::{apply_set, checked, parse_toml, read};
pub use spec::*;

use crate::engine::human::Human;
use crate::Error;
use serde::Deserialize;
use std::path::Path;
use twoport_control::servo::{Display, Gains};

/// A scene, as read from TOML. Every section but `display`, `coupling` and
/// `ve` has defaults; unknown keys are errors.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// A name for reports.
    #[serde(default)]
    pub name: String,
    /// How many Cartesian axes the device has (1 to [`MAX_AXES`]; 1 when
    /// absent). Every axis runs the same device model, VE kind, effects
    /// and hand, each with its own state.
    #[serde(default = "one_axis")]
    pub axes: u8,
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
    /// Coupling (and regulator) gains, the same on every axis unless
    /// `coupling_per_axis` gives each its own.
    pub coupling: Coupling,
    /// Each axis's coupling, x first: one per axis.
    pub coupling_per_axis: Option<Vec<Coupling>>,
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
    /// An identification experiment the board plays once armed
    /// (processor in the loop); absent means none.
    pub identify: Option<IdentifySpec>,
}

impl Scene {
    /// The control period the scene runs at (s).
    pub fn period(&self) -> f64 {
        self.period_s.unwrap_or(1e-3)
    }

    /// The scene's device model, [`twoport_design::DeviceModel::load_or_excalibur`],
    /// with `plant.handle_mass_kg` on its handle; the error names the field.
    pub fn device_model(&self) -> Result<twoport_design::DeviceModel, Error> {
        let m = twoport_design::DeviceModel::load_or_excalibur(&self.plant.model)
            .map_err(|e| sim_err!("plant.model: {e}"))?;
        match self.plant.handle_mass_kg {
            0.0 => Ok(m),
            kg => m
                .with_handle_mass(kg)
                .map_err(|e| sim_err!("plant.handle_mass_kg: {e}")),
        }
    }

    /// Read a scene file, apply `--set` overrides, and check it.
    pub fn load(path: &Path, sets: &[String]) -> Result<Self, crate::Error> {
        Self::parse(&read(path)?, &path.display().to_string(), sets)
    }

    /// Parse scene text; `source` names it in errors.
    pub fn parse(text: &str, source: &str, sets: &[String]) -> Result<Self, crate::Error> {
        checked(parse_toml(text, source, sets)?, source, Self::check)
    }

    /// The hand along each axis: the script's events with each axis's
    /// values (checked; the error names `human.script[i]`).
    pub fn humans(&self) -> Result<Vec<Human>, Error> {
        (0..self.axis_count())
            .map(|a| {
                let events = self.human.script.iter().map(|e| e.along(|v| v.on(a)));
                Human::new(self.human.grasp, events.collect())?.with_arm(self.human.arm)
            })
            .collect()
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
    /// How many axes the scene's device has.
    pub fn axis_count(&self) -> usize {
        usize::from(self.axes)
    }

    /// Axis `axis`'s coupling: its own in `coupling_per_axis`, else
    /// `coupling`.
    pub fn coupling_of(&self, axis: usize) -> &Coupling {
        self.coupling_per_axis
            .as_ref()
            .and_then(|c| c.get(axis))
            .unwrap_or(&self.coupling)
    }

    /// Axis `axis`'s servo gains.
    pub fn gains_of(&self, axis: usize) -> Gains {
        self.coupling_of(axis).gains()
    }
}

/// The most axes a scene's device may have.
pub const MAX_AXES: u8 = 3;

fn one_axis() -> u8 {
    1
}

fn default_duration() -> f64 {
    10.0
}
