//! Three-axis scene files: `axes = 3` at the top level.

use crate::engine::human::{Event, GraspKind, Human};
use crate::engine::scene::{checked, parse_toml, read, Coupling, SceneError};
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// A three-axis scene, as read from TOML; unknown keys are errors.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct XyzScene {
    /// A name for reports.
    #[serde(default)]
    pub name: String,
    /// Must be 3.
    pub axes: u8,
    /// Simulated time (s).
    pub duration_s: f64,
    /// The device.
    #[serde(default)]
    pub plant: XyzPlant,
    /// The impedance display's coupling, the same on every axis unless
    /// `coupling_per_axis` gives each its own.
    pub coupling: Coupling,
    /// Each axis's coupling, x first.
    pub coupling_per_axis: Option<[Coupling; 3]>,
    /// The virtual environment.
    pub ve: XyzVe,
    /// The human operator.
    #[serde(default)]
    pub human: XyzHuman,
}

/// The device: one model per axis.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct XyzPlant {
    /// The model of every axis (the Excalibur's x-axis worst case by
    /// default, which the paper argues serves y and z).
    #[serde(default = "default_model")]
    pub model: PathBuf,
    /// Cross-axis coupling: the fraction of each actuator's force that
    /// also pushes the other two axes' actuators (0: independent axes).
    #[serde(default)]
    pub cross_coupling: f64,
}

impl Default for XyzPlant {
    fn default() -> Self {
        XyzPlant {
            model: default_model(),
            cross_coupling: 0.0,
        }
    }
}

fn default_model() -> PathBuf {
    PathBuf::from(twoport_design::model::EXCALIBUR_PATH)
}

/// One block of the world.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct XyzBlock {
    /// Its lowest corner (m).
    pub at_m: [f64; 3],
    /// Its size (m).
    pub size_m: [f64; 3],
    /// Its mass (kg).
    pub mass_kg: f64,
}

/// The virtual environment of a three-axis scene.
#[derive(Clone, Debug, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum XyzVe {
    /// The building-block world: a cursor, blocks on a floor, gravity.
    /// With no blocks it is a free cursor over a floor.
    Blocks {
        /// The blocks, at most 50.
        #[serde(default)]
        blocks: Vec<XyzBlock>,
        /// Cursor mass (kg).
        #[serde(default = "default_cursor")]
        cursor_mass_kg: f64,
        /// Friction coefficient of faces.
        #[serde(default = "default_friction")]
        friction: f64,
        /// Knobs on the blocks' tops.
        #[serde(default = "default_true")]
        knobs: bool,
        /// The paper's explicit integration instead of the passive one.
        #[serde(default)]
        explicit: bool,
        /// Grab the touched block at these times (s).
        #[serde(default)]
        grab_at_s: Vec<f64>,
        /// Let go at these times (s).
        #[serde(default)]
        release_at_s: Vec<f64>,
    },
    /// A rigid bilateral constraint on every axis: the VE point never moves.
    Bilateral,
}

fn default_cursor() -> f64 {
    0.25
}
fn default_friction() -> f64 {
    0.3
}
fn default_true() -> bool {
    true
}

/// One scripted event of the hand: positions and forces per axis.
pub type XyzEvent = Event<[f64; 3]>;

/// The human operator of a three-axis scene.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct XyzHuman {
    /// Initial grasp, the same impedance on every axis.
    #[serde(default)]
    pub grasp: Option<GraspKind>,
    /// Scripted events.
    #[serde(default)]
    pub script: Vec<XyzEvent>,
}

/// The most blocks a scene's world holds.
pub const MAX_BLOCKS: usize = 50;

impl XyzScene {
    /// Read a three-axis scene file, apply `--set` overrides, and check it.
    pub fn load(path: &Path, sets: &[String]) -> Result<Self, SceneError> {
        Self::parse(&read(path)?, &path.display().to_string(), sets)
    }

    /// Parse three-axis scene text; `source` names it in errors.
    pub fn parse(text: &str, source: &str, sets: &[String]) -> Result<Self, SceneError> {
        checked(parse_toml(text, source, sets)?, source, Self::check)
    }

    /// Each axis's coupling.
    pub fn couplings(&self) -> [Coupling; 3] {
        self.coupling_per_axis.unwrap_or([self.coupling; 3])
    }

    /// The hand as three one-axis hands, one per axis, each with the
    /// script's events along its axis (checked as a one-axis script is,
    /// naming `human.script[i]`).
    pub fn humans(&self) -> Result<[Human; 3], String> {
        let grasp = self.human.grasp.unwrap_or(GraspKind::HandsOff);
        let along = |a: usize| -> Vec<Event> {
            self.human
                .script
                .iter()
                .map(|e| e.along(|v| v[a]))
                .collect()
        };
        Ok([
            Human::new(grasp, along(0))?,
            Human::new(grasp, along(1))?,
            Human::new(grasp, along(2))?,
        ])
    }

    fn check(&self) -> Result<(), String> {
        if self.axes != 3 {
            return Err(format!(
                "axes = {}: a three-axis scene has axes = 3",
                self.axes
            ));
        }
        if !(self.duration_s.is_finite() && self.duration_s > 0.0 && self.duration_s <= 3600.0) {
            return Err(format!(
                "duration_s = {} must be in (0, 3600]",
                self.duration_s
            ));
        }
        for (a, c) in self.couplings().iter().enumerate() {
            match c.k {
                Some(k) if k.is_finite() && k >= 0.0 && c.b.is_finite() && c.b >= 0.0 => {}
                _ => {
                    return Err(format!(
                        "coupling of axis {a}: an impedance coupling needs finite k >= 0 and b >= 0"
                    ))
                }
            }
        }
        let cc = self.plant.cross_coupling;
        if !(cc.is_finite() && (0.0..0.5).contains(&cc)) {
            return Err(format!("plant.cross_coupling = {cc} must be in [0, 0.5)"));
        }
        if let XyzVe::Blocks {
            blocks,
            cursor_mass_kg,
            friction,
            grab_at_s,
            release_at_s,
            ..
        } = &self.ve
        {
            for (name, times) in [("grab_at_s", grab_at_s), ("release_at_s", release_at_s)] {
                if let Some(t) = times.iter().find(|t| !(t.is_finite() && **t >= 0.0)) {
                    return Err(format!("ve.{name}: {t} is not a time >= 0 (s)"));
                }
            }
            if blocks.len() > MAX_BLOCKS {
                return Err(format!(
                    "ve.blocks: {} blocks, the world holds {MAX_BLOCKS}",
                    blocks.len()
                ));
            }
            for (i, b) in blocks.iter().enumerate() {
                let ok = b.at_m.iter().all(|x| x.is_finite() && x.abs() < 2.0)
                    && b.size_m
                        .iter()
                        .all(|s| s.is_finite() && *s > 0.0 && *s < 2.0)
                    && b.mass_kg.is_finite()
                    && b.mass_kg > 0.0;
                if !ok {
                    return Err(format!(
                        "ve.blocks[{i}]: at_m within 2 m, size_m in (0, 2) m and mass_kg > 0"
                    ));
                }
            }
            if !(cursor_mass_kg.is_finite() && *cursor_mass_kg > 0.0) {
                return Err(format!("ve.cursor_mass_kg = {cursor_mass_kg} must be > 0"));
            }
            if !(friction.is_finite() && *friction >= 0.0) {
                return Err(format!("ve.friction = {friction} must be >= 0"));
            }
        }
        self.humans()?;
        Ok(())
    }
}
