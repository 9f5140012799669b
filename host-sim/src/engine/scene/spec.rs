//! The scene's sections: plant, integrator, passivity layer, coupling,
//! VE and human.

use crate::engine::human::{AxisValue, Event, GraspKind};
use crate::engine::plant::Method;
use serde::Deserialize;
use std::path::PathBuf;
use twoport_control::servo::{AdmittanceGains, Display, Gains, ImpedanceGains};
use twoport_control::ve::Solid;

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
    /// Cross-axis coupling on a device of several axes: the fraction of
    /// each actuator's force that also pushes every other axis's actuator
    /// (0, the default: independent axes).
    #[serde(default)]
    pub cross_coupling: f64,
    /// A linkage's device file (`models/linkages/`): its nonlinear arm in
    /// place of the axes' models, run through the board's linkage servo.
    /// The scene's axes are its Cartesian axes, measured from where the
    /// handle starts.
    #[serde(default)]
    pub linkage: Option<PathBuf>,
    /// The linkage's joint angles at the start (rad).
    #[serde(default)]
    pub pose_rad: Vec<f64>,
    /// Gravity along `-z` on the linkage's moving masses (m/s²), which its
    /// servo holds up; 0, the default, leaves it out.
    #[serde(default)]
    pub gravity_mps2: f64,
    /// Whether the linkage's joints have their file's Coulomb friction
    /// (true by default; the proof counts only viscous damping).
    #[serde(default)]
    pub friction: Option<bool>,
    /// A known rigid mass clamped on the handle (kg; 0, the default, for
    /// none): the loaded run of an identification experiment, which shows
    /// the handle's side of the device. Not on a linkage.
    #[serde(default)]
    pub handle_mass_kg: f64,
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
            cross_coupling: 0.0,
            linkage: None,
            pose_rad: Vec::new(),
            gravity_mps2: 0.0,
            friction: None,
            handle_mass_kg: 0.0,
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

/// One axis's coupling as a scene file gives it: `k` and `b` for the
/// impedance display, `kp`, `bp`, `m` and `b` for the admittance display.
/// Which one the keys make must be the scene's `display`.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(try_from = "CouplingKeys")]
pub enum Coupling {
    /// The impedance display's coupling `Z_cI`.
    Impedance {
        /// Stiffness (N/m).
        k: f64,
        /// Damping (N s/m).
        b: f64,
    },
    /// The admittance display's regulator `K_p` and coupling `Z_cA`.
    Admittance {
        /// Regulator stiffness (N/m).
        kp: f64,
        /// Regulator damping (N s/m).
        bp: f64,
        /// Coupling mass (kg).
        m: f64,
        /// Coupling damping (N s/m).
        b: f64,
    },
}

impl Coupling {
    /// Which display it is for.
    pub fn display(&self) -> Display {
        match self {
            Coupling::Impedance { .. } => Display::Impedance,
            Coupling::Admittance { .. } => Display::Admittance,
        }
    }

    /// The servo's gains (rounded to the board's f32).
    pub fn gains(&self) -> Gains {
        match *self {
            Coupling::Impedance { k, b } => ImpedanceGains::new(k as f32, b as f32).into(),
            Coupling::Admittance { kp, bp, m, b } => {
                AdmittanceGains::new(kp as f32, bp as f32, m as f32, b as f32).into()
            }
        }
    }
}

/// The keys a `[coupling]` table may hold, before they are read as one
/// display's coupling.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct CouplingKeys {
    k: Option<f64>,
    b: f64,
    m: Option<f64>,
    kp: Option<f64>,
    bp: Option<f64>,
}

impl TryFrom<CouplingKeys> for Coupling {
    type Error = String;

    fn try_from(c: CouplingKeys) -> Result<Self, String> {
        let admittance = [("m", c.m), ("kp", c.kp), ("bp", c.bp)];
        match c.k {
            Some(k) => match admittance.iter().find(|(_, v)| v.is_some()) {
                Some((n, _)) => Err(format!(
                    "coupling: {n} belongs to an admittance display's coupling; an impedance display's has k and b"
                )),
                None => Ok(Coupling::Impedance { k, b: c.b }),
            },
            None => match admittance {
                [(_, Some(m)), (_, Some(kp)), (_, Some(bp))] => Ok(Coupling::Admittance {
                    kp,
                    bp,
                    m,
                    b: c.b,
                }),
                _ if admittance.iter().all(|(_, v)| v.is_none()) => Err(
                    "coupling: give k and b (impedance display), or kp, bp, m and b (admittance display)"
                        .into(),
                ),
                _ => {
                    let missing: Vec<_> = admittance
                        .iter()
                        .filter(|(_, v)| v.is_none())
                        .map(|(n, _)| *n)
                        .collect();
                    Err(format!(
                        "coupling: {} is required for an admittance display's coupling",
                        missing.join(" and ")
                    ))
                }
            },
        }
    }
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
    /// The force integrated by the trapezoidal rule: lossless, the edge of
    /// the passive masses (what `twoport verify` may terminate a loop
    /// with).
    Lossless,
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
        solid: Solid,
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
    Blocks(BlocksSpec),
    /// The building-block world in 3-D, on a three-axis device: a cursor,
    /// blocks on a floor, gravity. With no blocks it is a free cursor over
    /// a floor. The device's zero is where the cursor starts (the
    /// workspace's centre, 10 mm above the floor).
    World {
        /// The blocks, at most 50.
        #[serde(default)]
        blocks: Vec<WorldBlock>,
        /// Cursor mass (kg).
        #[serde(default = "default_cursor")]
        cursor_mass_kg: f64,
        /// Friction coefficient of the faces.
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
}

/// The 1-D building-block world: a cursor among blocks between two walls.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BlocksSpec {
    /// Cursor mass (kg).
    pub cursor_mass_kg: f64,
    /// The blocks, left to right, not overlapping.
    pub blocks: Vec<BlockSpec>,
    /// World limits (m): blocks stop at these walls.
    pub limits_m: [f64; 2],
    /// Force that separates two touching blocks (N).
    pub stick_force_n: f64,
    /// Viscous drag of free blocks on the floor (N s/m).
    #[serde(default = "default_floor")]
    pub floor_damping_nspm: f64,
    /// Grab the block under the cursor at this time (s).
    pub grab_at_s: Option<f64>,
    /// Release it at this time (s).
    pub release_at_s: Option<f64>,
}

/// One block of the 3-D world.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WorldBlock {
    /// Its lowest corner (m).
    pub at_m: [f64; 3],
    /// Its size (m).
    pub size_m: [f64; 3],
    /// Its mass (kg).
    pub mass_kg: f64,
}

/// The most blocks the 3-D world holds.
pub const MAX_BLOCKS: usize = 50;

fn default_cursor() -> f64 {
    0.25
}
fn default_friction() -> f64 {
    0.3
}

fn default_solid() -> Solid {
    Solid::Above
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
    /// Scripted events; their positions and forces are numbers on a
    /// one-axis device, arrays of one per axis on a device of several.
    #[serde(default)]
    pub script: Vec<Event<AxisValue>>,
    /// A passive arm behind the grasp (paper Fig. 3's `Z_p`), on every
    /// axis.
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
