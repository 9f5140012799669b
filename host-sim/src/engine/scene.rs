//! Scene files: what to simulate, and only the effects named.

use crate::engine::human::{Event, GraspKind};
use crate::engine::plant::Method;
use serde::Deserialize;
use std::path::{Path, PathBuf};
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

/// The passivity layer between the device's port and the display's
/// element: the series damper on an impedance display, the parallel damper
/// on an admittance display (see `docs/passivity.md`).
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PassivitySpec {
    /// Whether the layer runs (`--set passivity.enabled=false` turns a
    /// scene's layer off, everything else equal).
    #[serde(default = "default_true")]
    pub enabled: bool,
    /// Which port it watches: `device` (the default: the series damper at
    /// the encoder) or `ve` (a parallel damper between the coupling and an
    /// admittance VE, for a VE that is unstable on its own).
    #[serde(default)]
    pub port: LayerPort,
    /// Moving mass at the port (kg), which sets the damping cap; the
    /// plant's `rigid_mass_kg` by default.
    pub mass_kg: Option<f64>,
    /// The device's own viscous damping credited to the element (N s/m):
    /// a lower bound of it. 0 by default.
    #[serde(default)]
    pub device_damping_nspm: f64,
    /// Velocity floor (m/s); a few encoder counts per tick. 1 mm/s by
    /// default.
    pub min_velocity_mps: Option<f64>,
    /// Energy reserve (J); 0.5 J by default.
    pub max_reserve_j: Option<f64>,
    /// The `--set` assignments that make this scene passive without the
    /// layer (an implicit VE, the proven gains, no delay): the reference
    /// the layer's transparency cost is measured against.
    #[serde(default)]
    pub reference: Vec<String>,
}

/// Where the passivity layer sits.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LayerPort {
    /// At the device's port (the encoder).
    #[default]
    Device,
    /// Between the coupling and the VE.
    Ve,
}

fn default_true() -> bool {
    true
}

fn default_duration() -> f64 {
    10.0
}

/// Which device model.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlantSpec {
    /// Model file for the flexible plant (with the `flexibility` effect).
    #[serde(default = "default_model")]
    pub model: PathBuf,
    /// Rigid reduction's mass (kg).
    #[serde(default = "default_rigid_mass")]
    pub rigid_mass_kg: f64,
    /// Rigid reduction's damping (N s/m).
    #[serde(default = "default_rigid_damping")]
    pub rigid_damping_nspm: f64,
}

fn default_model() -> PathBuf {
    PathBuf::from("models/excalibur.toml")
}
fn default_rigid_mass() -> f64 {
    3.9
}
fn default_rigid_damping() -> f64 {
    20.0
}

impl Default for PlantSpec {
    fn default() -> Self {
        PlantSpec {
            model: default_model(),
            rigid_mass_kg: default_rigid_mass(),
            rigid_damping_nspm: default_rigid_damping(),
        }
    }
}

/// Integration method and sub-steps per control tick.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IntegratorSpec {
    /// Method (a linear scene always runs exact ZOH in one step).
    #[serde(default = "default_method")]
    pub method: Method,
    /// Sub-steps per control tick when sub-stepping.
    #[serde(default = "default_substeps")]
    pub substeps: u32,
    /// Use this integrator even for a linear scene (to study its accuracy).
    #[serde(default)]
    pub on_linear: bool,
    /// The controller's float type: `"f32"` (the board's, the default) or
    /// `"f64"` (the same laws, to see what the board's rounding costs).
    #[serde(default)]
    pub controller: Precision,
}

/// A float type for the controller.
#[derive(Clone, Copy, Debug, Default, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum Precision {
    /// `f32`, as on the board.
    #[default]
    F32,
    /// `f64`.
    F64,
}

impl Precision {
    /// `"f32"` or `"f64"`.
    pub fn name(self) -> &'static str {
        match self {
            Precision::F32 => "f32",
            Precision::F64 => "f64",
        }
    }
}

fn default_method() -> Method {
    Method::Rk4
}
fn default_substeps() -> u32 {
    20
}

impl Default for IntegratorSpec {
    fn default() -> Self {
        IntegratorSpec {
            method: default_method(),
            substeps: default_substeps(),
            on_linear: false,
            controller: Precision::F32,
        }
    }
}

/// Gains. Impedance display: `k`, `b`. Admittance display: `kp`, `bp`, `m`, `b`.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Coupling {
    /// Impedance coupling stiffness (N/m).
    pub k: Option<f64>,
    /// Coupling damping (N s/m), both displays.
    pub b: f64,
    /// Admittance coupling mass (kg).
    pub m: Option<f64>,
    /// Position regulator stiffness (N/m).
    pub kp: Option<f64>,
    /// Position regulator damping (N s/m).
    pub bp: Option<f64>,
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

/// Which side of a wall is solid.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SolidSide {
    /// Positions above the surface are inside.
    Above,
    /// Positions below the surface are inside.
    Below,
}

/// One block of the building-block world.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BlockSpec {
    /// Left edge (m).
    pub at_m: f64,
    /// Width (m).
    pub width_m: f64,
    /// Mass (kg).
    pub mass_kg: f64,
}

/// How a spring VE's probe position is integrated on the board.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Discretization {
    /// `x[k] = x[k-1] + T v[k]`: adds damping `kT/2` at high frequency.
    #[default]
    BackwardEuler,
    /// `x[k] = x[k-1] + T (v[k] + v[k-1])/2`: lossless.
    Trapezoidal,
}

/// How a VE body is integrated on the board.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Integration {
    /// Backward Euler on this tick's force: passive for every mass.
    #[default]
    Implicit,
    /// The paper's building blocks: the velocity from last tick's force
    /// (forward Euler), the position by the trapezoidal rule. Not passive.
    Explicit,
}

/// The virtual environment.
#[derive(Clone, Debug, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum VeSpec {
    /// A free cursor mass.
    Cursor {
        /// Mass (kg); the paper's minimum is 0.25.
        mass_kg: f64,
        /// How the board integrates it: `implicit` (backward Euler,
        /// passive, the default) or `explicit` (the paper's: Euler
        /// velocity, trapezoidal position).
        #[serde(default)]
        integration: Integration,
    },
    /// A unilateral spring-damper wall.
    Wall {
        /// Surface position (m).
        position_m: f64,
        /// Stiffness (N/m).
        stiffness_npm: f64,
        /// Damping (N s/m).
        damping_nspm: f64,
        /// Solid side.
        #[serde(default = "default_solid")]
        solid: SolidSide,
    },
    /// A fixed point.
    Bilateral,
    /// A spring-damper to an anchor, pulling and pushing (the wall in
    /// permanent contact): a linear passive VE.
    Spring {
        /// Anchor position (m).
        anchor_m: f64,
        /// Stiffness (N/m).
        stiffness_npm: f64,
        /// Damping (N s/m).
        damping_nspm: f64,
        /// How the board integrates the probe: `backward_euler` (the
        /// default, like the wall) or `trapezoidal` (a lossless spring).
        #[serde(default)]
        discretization: Discretization,
    },
    /// The 1-D building-block world.
    Blocks {
        /// Cursor mass (kg).
        cursor_mass_kg: f64,
        /// The blocks, left to right, not overlapping.
        blocks: Vec<BlockSpec>,
        /// World limits (m): blocks stop at these walls.
        limits_m: [f64; 2],
        /// Force that separates two touching blocks (N).
        stick_force_n: f64,
        /// Viscous drag of free blocks on the floor (N s/m).
        #[serde(default = "default_floor")]
        floor_damping_nspm: f64,
        /// Grab the block under the cursor at this time (s).
        grab_at_s: Option<f64>,
        /// Release it at this time (s).
        release_at_s: Option<f64>,
    },
}

fn default_solid() -> SolidSide {
    SolidSide::Above
}
fn default_floor() -> f64 {
    5.0
}

/// The human operator section.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HumanSpec {
    /// Initial grasp.
    #[serde(default = "default_grasp")]
    pub grasp: GraspKind,
    /// Scripted events.
    #[serde(default)]
    pub script: Vec<Event>,
    /// A passive arm behind the grasp (paper Fig. 3's `Z_p`).
    pub arm: Option<crate::engine::plant::Arm>,
}

fn default_grasp() -> GraspKind {
    GraspKind::HandsOff
}

impl Default for HumanSpec {
    fn default() -> Self {
        HumanSpec {
            grasp: default_grasp(),
            script: Vec::new(),
            arm: None,
        }
    }
}

/// The effects a scene may name. Absent means not simulated at all.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Effects {
    /// The flexible multi-mass model instead of the rigid reduction.
    #[serde(default)]
    pub flexibility: bool,
    /// The strain gauge and its analog filter (needed by an admittance display).
    #[serde(default)]
    pub load_cell: bool,
    /// Encoder quantisation.
    pub encoder: Option<EncoderEffect>,
    /// Load-cell ADC quantisation and noise.
    pub adc: Option<AdcEffect>,
    /// Amplifier saturation.
    pub saturation: Option<SaturationEffect>,
    /// Coulomb friction at the actuator.
    pub coulomb: Option<CoulombEffect>,
    /// Motor cogging.
    pub cogging: Option<CoggingEffect>,
    /// Slack in the cable between the actuator and the first link.
    pub cable_slack: Option<SlackEffect>,
    /// Sensor delay.
    pub delay: Option<DelayEffect>,
    /// A hard stop at the end of the actuator's travel (what homing finds).
    pub hard_stop: Option<HardStopEffect>,
    /// The coupling and VE see the device's position this many ticks late
    /// (a VE on a host behind a link), while the board's passivity layer
    /// reads it fresh.
    pub element_delay: Option<DelayEffect>,
}

/// Encoder quantisation.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EncoderEffect {
    /// Travel per count (m).
    pub resolution_m: f64,
    /// Counter width (bits).
    #[serde(default = "default_bits")]
    pub bits: u8,
    /// Where the encoder's index mark is (m), if it has one: passing it
    /// latches the count for a board that homes on the index.
    #[serde(default)]
    pub index_m: Option<f64>,
}
fn default_bits() -> u8 {
    16
}

/// ADC quantisation and seeded Gaussian noise on the load cell.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AdcEffect {
    /// Force per least significant bit (N).
    pub lsb_n: f64,
    /// Noise standard deviation (N).
    #[serde(default)]
    pub noise_rms_n: f64,
    /// Noise seed.
    #[serde(default)]
    pub seed: u64,
}

/// Amplifier force limit.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SaturationEffect {
    /// Largest force the amplifier delivers (N).
    pub limit_n: f64,
}

/// Coulomb friction at the actuator.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CoulombEffect {
    /// Friction force (N).
    pub force_n: f64,
    /// Velocity over which it is smoothed (m/s).
    #[serde(default = "default_smooth")]
    pub smoothing_mps: f64,
}
fn default_smooth() -> f64 {
    1e-3
}

/// Motor cogging: `A sin(2π x_a / period)`.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CoggingEffect {
    /// Amplitude (N).
    pub amplitude_n: f64,
    /// Spatial period at the actuator (m).
    pub period_m: f64,
}

/// A dead band in the cable between the actuator and the first link.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SlackEffect {
    /// Total free play (m).
    pub width_m: f64,
}

/// A hard stop on the actuator: a stiff, damped spring that only pushes,
/// where the actuator passes `position_m`.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HardStopEffect {
    /// Where the stop's face is (m).
    pub position_m: f64,
    /// Which side of the face is solid.
    #[serde(default = "default_stop_side")]
    pub solid: StopSide,
    /// Its stiffness (N/m).
    #[serde(default = "default_stop_stiffness")]
    pub stiffness_npm: f64,
    /// Its damping while pressed (N s/m).
    #[serde(default = "default_stop_damping")]
    pub damping_nspm: f64,
}
fn default_stop_side() -> StopSide {
    StopSide::Below
}
fn default_stop_stiffness() -> f64 {
    2.0e5
}
fn default_stop_damping() -> f64 {
    50.0
}

/// The solid side of a hard stop.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StopSide {
    /// It stops travel toward negative positions.
    Below,
    /// It stops travel toward positive positions.
    Above,
}

/// Sensor delay.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DelayEffect {
    /// Ticks of delay.
    pub ticks: u32,
}

/// Why a scene was refused: the file, and the line or the field.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneError(pub String);

impl std::fmt::Display for SceneError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for SceneError {}

/// Apply `key.path=value` to a TOML tree; the value is read as TOML
/// (number, boolean, string, array) or else taken as a string.
pub fn apply_set(root: &mut toml::Table, assignment: &str) -> Result<(), SceneError> {
    let bad = |m: String| SceneError(format!("--set {assignment}: {m}"));
    let (path, value) = assignment
        .split_once('=')
        .ok_or_else(|| bad("expected key=value".into()))?;
    let keys: Vec<&str> = path.trim().split('.').collect();
    if keys.iter().any(|k| k.is_empty()) {
        return Err(bad("empty key".into()));
    }
    let parsed: toml::Value = toml::from_str::<toml::Table>(&format!("v = {}", value.trim()))
        .ok()
        .and_then(|mut t| t.remove("v"))
        .unwrap_or_else(|| toml::Value::String(value.trim().to_string()));
    let mut table = root;
    for k in &keys[..keys.len() - 1] {
        table = table
            .entry(k.to_string())
            .or_insert_with(|| toml::Value::Table(toml::Table::new()))
            .as_table_mut()
            .ok_or_else(|| bad(format!("{k} is not a table")))?;
    }
    table.insert(keys[keys.len() - 1].to_string(), parsed);
    Ok(())
}

/// Where a bad value sits when serde can only name its table (`ve` is an
/// internally tagged enum, whose fields serde reads from a buffer): the
/// line in that table holding the value the message quotes, and its key.
fn locate(text: &str, table: &str, message: &str) -> Option<(usize, String)> {
    let quoted = message.split('"').nth(1)?;
    let header = format!("[{table}]");
    let start = text.lines().position(|l| l.trim() == header)?;
    text.lines()
        .enumerate()
        .skip(start + 1)
        .take_while(|(_, l)| !l.trim_start().starts_with('['))
        .find(|(_, l)| l.contains(&format!("\"{quoted}\"")))
        .and_then(|(i, l)| Some((i + 1, format!("{table}.{}", l.split('=').next()?.trim()))))
}

/// A scene file's text; the error names the file.
pub fn read(path: &Path) -> Result<String, SceneError> {
    std::fs::read_to_string(path)
        .map_err(|e| SceneError(format!("{}: cannot read: {e}", path.display())))
}

/// `scene` if `check` passes it; the error names `source`.
pub fn checked<T>(
    scene: T,
    source: &str,
    check: impl FnOnce(&T) -> Result<(), String>,
) -> Result<T, SceneError> {
    check(&scene).map_err(|m| SceneError(format!("{source}: {m}")))?;
    Ok(scene)
}

/// Parse TOML scene text into `T`, applying `--set` overrides; an error
/// names `source`, the line and the key. Both the one-axis and the
/// three-axis scenes are read through it.
pub fn parse_toml<T: serde::de::DeserializeOwned>(
    text: &str,
    source: &str,
    sets: &[String],
) -> Result<T, SceneError> {
    let line_of = |e: &toml::de::Error| {
        e.span()
            .map(|s| {
                format!(
                    "line {}: ",
                    text[..s.start.min(text.len())].matches('\n').count() + 1
                )
            })
            .unwrap_or_default()
    };
    let mut table: toml::Table = toml::from_str(text)
        .map_err(|e| SceneError(format!("{source}: {}{}", line_of(&e), e.message())))?;
    let value: T = if sets.is_empty() {
        // serde_path_to_error names the field; toml's span alone points
        // at the enclosing table for a bad value inside one.
        let de = toml::Deserializer::parse(text)
            .map_err(|e| SceneError(format!("{source}: {}{}", line_of(&e), e.message())))?;
        serde_path_to_error::deserialize(de).map_err(|e| {
            let path = e.path().to_string();
            let inner = e.into_inner();
            let (line, key) = locate(text, &path, inner.message())
                .map(|(l, k)| (format!("line {l}: "), format!("{k}: ")))
                .unwrap_or_else(|| {
                    let field = if path.is_empty() || path == "." {
                        String::new()
                    } else {
                        format!("{path}: ")
                    };
                    (line_of(&inner), field)
                });
            SceneError(format!("{source}: {line}{key}{}", inner.message()))
        })?
    } else {
        for s in sets {
            apply_set(&mut table, s)?;
        }
        // The overridden scene has no lines of its own: name the key.
        let merged = toml::to_string(&table).map_err(|e| SceneError(format!("{source}: {e}")))?;
        toml::from_str(&merged).map_err(|e| {
            let key = e
                .span()
                .and_then(|s| {
                    merged[..s.start.min(merged.len())]
                        .lines()
                        .last()
                        .map(str::to_string)
                })
                .unwrap_or_default();
            let quoted = e.message().split('"').nth(1).unwrap_or("\u{0}");
            if let Some(set) = sets
                .iter()
                .find(|s| s.split_once('=').is_some_and(|(_, v)| v.trim() == quoted))
            {
                return SceneError(format!("{source}: --set {set}: {}", e.message()));
            }
            let near = if key.trim().is_empty() {
                String::new()
            } else {
                format!(" (at `{}`)", key.trim())
            };
            SceneError(format!("{source} with --set: {}{near}", e.message()))
        })?
    };
    Ok(value)
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

    /// Physical checks beyond the types; the message names the field.
    fn check(&self) -> Result<(), String> {
        let pos = |name: &str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(format!("{name} = {v} must be finite and > 0"))
            }
        };
        let nonneg = |name: &str, v: f64| {
            if v.is_finite() && v >= 0.0 {
                Ok(())
            } else {
                Err(format!("{name} = {v} must be finite and >= 0"))
            }
        };
        // A spring VE anchored at `at` (m, named `at_name`).
        let spring = |at_name: &str, at: f64, k: f64, b: f64| {
            if !at.is_finite() {
                return Err(format!("{at_name} = {at} must be finite"));
            }
            nonneg("ve.stiffness_npm", k)?;
            nonneg("ve.damping_nspm", b)
        };
        if let Some(n) = self.axes.filter(|&n| n != 1) {
            return Err(format!(
                "axes = {n}: a one-axis scene has axes = 1; a three-axis scene is read as one"
            ));
        }
        pos("duration_s", self.duration_s)?;
        if let Some(t) = self.period_s {
            if !(t.is_finite() && (1e-6..=0.1).contains(&t)) {
                return Err(format!("period_s = {t} must be between 1e-6 and 0.1 s"));
            }
        }
        pos("plant.rigid_mass_kg", self.plant.rigid_mass_kg)?;
        nonneg("plant.rigid_damping_nspm", self.plant.rigid_damping_nspm)?;
        if self.integrator.substeps == 0 || self.integrator.substeps > 100_000 {
            return Err(format!(
                "integrator.substeps = {} must be 1..=100000",
                self.integrator.substeps
            ));
        }
        let c = &self.coupling;
        match self.display {
            Display::Impedance => {
                let k =
                    c.k.ok_or("coupling.k is required for an impedance display")?;
                nonneg("coupling.k", k)?;
                nonneg("coupling.b", c.b)?;
                for (n, v) in [
                    ("coupling.m", c.m),
                    ("coupling.kp", c.kp),
                    ("coupling.bp", c.bp),
                ] {
                    if v.is_some() {
                        return Err(format!("{n} belongs to an admittance display"));
                    }
                }
            }
            Display::Admittance => {
                for (n, v) in [
                    ("coupling.m", c.m),
                    ("coupling.kp", c.kp),
                    ("coupling.bp", c.bp),
                ] {
                    let v = v.ok_or(format!("{n} is required for an admittance display"))?;
                    nonneg(n, v)?;
                }
                pos("coupling.m", c.m.unwrap_or(0.0))?;
                pos("coupling.b", c.b)?;
                if c.k.is_some() {
                    return Err("coupling.k belongs to an impedance display (use kp)".into());
                }
                if !self.effects.load_cell {
                    return Err(
                        "an admittance display measures force: add `load_cell = true` to [effects]"
                            .into(),
                    );
                }
            }
        }
        match &self.ve {
            VeSpec::Cursor { mass_kg, .. } => pos("ve.mass_kg", *mass_kg)?,
            VeSpec::Wall {
                position_m: at,
                stiffness_npm: k,
                damping_nspm: b,
                ..
            } => spring("ve.position_m", *at, *k, *b)?,
            VeSpec::Bilateral => {}
            VeSpec::Spring {
                anchor_m: at,
                stiffness_npm: k,
                damping_nspm: b,
                ..
            } => spring("ve.anchor_m", *at, *k, *b)?,
            VeSpec::Blocks {
                cursor_mass_kg,
                blocks,
                limits_m,
                stick_force_n,
                floor_damping_nspm,
                ..
            } => {
                pos("ve.cursor_mass_kg", *cursor_mass_kg)?;
                nonneg("ve.stick_force_n", *stick_force_n)?;
                nonneg("ve.floor_damping_nspm", *floor_damping_nspm)?;
                if !(limits_m[0].is_finite()
                    && limits_m[1].is_finite()
                    && limits_m[0] < limits_m[1])
                {
                    return Err("ve.limits_m must be [low, high] with low < high".into());
                }
                let mut edge = limits_m[0];
                for (i, b) in blocks.iter().enumerate() {
                    pos(&format!("ve.blocks[{i}].width_m"), b.width_m)?;
                    pos(&format!("ve.blocks[{i}].mass_kg"), b.mass_kg)?;
                    if !(b.at_m.is_finite() && b.at_m >= edge - 1e-12) {
                        return Err(format!(
                            "ve.blocks[{i}] overlaps the block or limit to its left"
                        ));
                    }
                    edge = b.at_m + b.width_m;
                }
                if edge > limits_m[1] + 1e-12 {
                    return Err("ve.blocks extend past ve.limits_m[1]".into());
                }
            }
        }
        let e = &self.effects;
        if let Some(x) = e.encoder {
            pos("effects.encoder.resolution_m", x.resolution_m)?;
            if !(2..=32).contains(&x.bits) {
                return Err(format!("effects.encoder.bits = {} must be 2..=32", x.bits));
            }
            if let Some(m) = x.index_m {
                if !(m.is_finite() && m.abs() <= 1.0) {
                    return Err(format!("effects.encoder.index_m = {m} must be within ±1 m"));
                }
            }
        }
        if let Some(x) = e.hard_stop {
            if !(x.position_m.is_finite() && x.position_m.abs() <= 1.0) {
                return Err(format!(
                    "effects.hard_stop.position_m = {} must be within ±1 m",
                    x.position_m
                ));
            }
            pos("effects.hard_stop.stiffness_npm", x.stiffness_npm)?;
            nonneg("effects.hard_stop.damping_nspm", x.damping_nspm)?;
        }
        if let Some(x) = e.adc {
            pos("effects.adc.lsb_n", x.lsb_n)?;
            nonneg("effects.adc.noise_rms_n", x.noise_rms_n)?;
        }
        if let Some(x) = e.saturation {
            pos("effects.saturation.limit_n", x.limit_n)?;
        }
        if let Some(x) = e.coulomb {
            nonneg("effects.coulomb.force_n", x.force_n)?;
            pos("effects.coulomb.smoothing_mps", x.smoothing_mps)?;
        }
        if let Some(x) = e.cogging {
            nonneg("effects.cogging.amplitude_n", x.amplitude_n)?;
            pos("effects.cogging.period_m", x.period_m)?;
        }
        if let Some(x) = e.cable_slack {
            nonneg("effects.cable_slack.width_m", x.width_m)?;
            if !e.flexibility {
                return Err("effects.cable_slack needs the flexible model (flexibility = true): the rigid reduction has no cable".into());
            }
        }
        if let Some(x) = e.delay {
            if x.ticks > 1000 {
                return Err(format!("effects.delay.ticks = {} must be <= 1000", x.ticks));
            }
        }
        if let Some(x) = e.element_delay {
            if x.ticks > 1000 {
                return Err(format!(
                    "effects.element_delay.ticks = {} must be <= 1000",
                    x.ticks
                ));
            }
            if self.display != Display::Impedance {
                return Err("effects.element_delay delays the impedance display's element; an admittance display has none to delay".into());
            }
        }
        if let Some(p) = &self.passivity {
            if p.port == LayerPort::Ve {
                if self.display != Display::Impedance {
                    return Err("passivity.port = \"ve\" is for an impedance display (an admittance display's layer already sits at the load cell)".into());
                }
                if !matches!(self.ve, VeSpec::Cursor { .. }) {
                    return Err("passivity.port = \"ve\" needs a cursor VE (one that takes a force and answers with a velocity)".into());
                }
            }
            if let Some(m) = p.mass_kg {
                pos("passivity.mass_kg", m)?;
            }
            nonneg("passivity.device_damping_nspm", p.device_damping_nspm)?;
            if let Some(v) = p.min_velocity_mps {
                pos("passivity.min_velocity_mps", v)?;
            }
            if let Some(e) = p.max_reserve_j {
                nonneg("passivity.max_reserve_j", e)?;
            }
        }
        Ok(())
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
