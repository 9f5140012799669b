//! A linkage in closed loop with the board's servo: the nonlinear plant,
//! quantised joint encoders, the f32 [`LinkageServo`] and its joint
//! torques held over each period.

use super::plant::{CartesianHand, LinkagePlant, PlantError};
use nalgebra::DVector;
use twoport_control::kinematics::{Capstan, Delta, Kinematics, Pantograph, SerialArm};
use twoport_control::linkage::{JointEncoder, LinkageServo, MotorConfig};
use twoport_control::servo::{ImpedanceGains, SensorFrame};
use twoport_control::ve::BilateralConstraint;
use twoport_control::world::{PerAxis, World};
use twoport_control::{Position, SafetyConfig};
use twoport_design::linkage::{Geometry, LinkageFile};

/// A closed-loop run's setup: where it starts, the coupling, the hand.
#[derive(Clone, Debug)]
pub struct LinkageScene {
    /// Joint angles at the start, where the VE's rigid constraint holds
    /// the handle (rad).
    pub q0_rad: Vec<f64>,
    /// The handle's velocity at the start (m/s): the push that tests it.
    pub v0_mps: Vec<f64>,
    /// The coupling's stiffness (N/m) and damping (N s/m) on every axis.
    pub k_c_npm: f64,
    /// (N s/m).
    pub b_c_nspm: f64,
    /// The hand.
    pub hand: CartesianHand,
    /// Ticks to run.
    pub ticks: u32,
    /// Runge-Kutta sub-steps per tick.
    pub substeps: u32,
}

/// What a run recorded, one entry per tick.
#[derive(Clone, Debug, Default)]
pub struct LinkageTrace {
    /// The handle's position (m).
    pub handle_m: Vec<Vec<f64>>,
    /// The motors' torques (N m).
    pub torque_nm: Vec<Vec<f64>>,
    /// The servo's latched faults, by name, at the end; empty if none.
    pub faults: String,
}

impl LinkageTrace {
    /// The handle's displacement from its start along `u` (m), per tick.
    pub fn along(&self, u: &[f64]) -> Vec<f64> {
        let start = self.handle_m.first().cloned().unwrap_or_default();
        self.handle_m
            .iter()
            .map(|x| {
                x.iter()
                    .zip(&start)
                    .zip(u)
                    .map(|((x, s), u)| (x - s) * u)
                    .sum()
            })
            .collect()
    }
}

/// Why a run could not be made or went on.
#[derive(Clone, Debug, PartialEq)]
pub enum RunError {
    /// The servo refused its configuration.
    Servo(String),
    /// The plant left the poses it can integrate.
    Plant(PlantError),
    /// The scene does not fit the file (joint count, start pose).
    Scene(String),
}

/// Run `scene` on the device `file` describes.
pub fn run_linkage(file: &LinkageFile, scene: &LinkageScene) -> Result<LinkageTrace, RunError> {
    let f = |x: f64| x as f32;
    let bad = |e: twoport_control::ParamError| RunError::Servo(e.to_string());
    match file.geometry {
        Geometry::Capstan {
            r_h_m,
            r_p_m,
            r_s_m,
        } => {
            let k = Capstan::new(f(r_h_m), f(r_p_m), f(r_s_m)).map_err(bad)?;
            run::<_, _, 1>(file, k, scene, |[x]| BilateralConstraint::new(x))
        }
        Geometry::Pantograph { l_m, big_l_m, d_m } => {
            let k = Pantograph::new(f(l_m), f(big_l_m), f(d_m)).map_err(bad)?;
            run::<_, _, 2>(file, k, scene, constraints)
        }
        Geometry::SerialArm { l1_m, l2_m } => {
            let k = SerialArm::new(f(l1_m), f(l2_m)).map_err(bad)?;
            run::<_, _, 3>(file, k, scene, constraints)
        }
        Geometry::Delta {
            base_m,
            effector_m,
            upper_m,
            lower_m,
        } => {
            let k = Delta::new(f(base_m), f(effector_m), f(upper_m), f(lower_m)).map_err(bad)?;
            run::<_, _, 3>(file, k, scene, constraints)
        }
    }
}

/// A rigid constraint at `x` on every axis.
fn constraints<const N: usize>(x: [Position; N]) -> PerAxis<BilateralConstraint, N> {
    PerAxis(x.map(BilateralConstraint::new))
}

fn run<K: Kinematics<f32, N>, W: World<f32, N>, const N: usize>(
    file: &LinkageFile,
    kinematics: K,
    scene: &LinkageScene,
    world: impl FnOnce([Position; N]) -> W,
) -> Result<LinkageTrace, RunError> {
    if scene.q0_rad.len() != N || scene.v0_mps.len() != N || scene.hand.anchor_m.len() != N {
        return Err(RunError::Scene(format!("the device has {N} joints")));
    }
    let t = file.period_s;
    let cpr: [f64; N] =
        core::array::from_fn(|i| file.motors.encoder_counts_per_rev as f64 * file.motors.ratios[i]);
    let q0: [f64; N] = core::array::from_fn(|i| scene.q0_rad[i]);
    let joint = |i: usize| {
        JointEncoder::new(32, cpr[i] as f32, 0, q0[i] as f32)
            .map_err(|e| RunError::Servo(format!("joint {i}: {e}")))
    };
    let mut js = [joint(0)?; N];
    for (i, slot) in js.iter_mut().enumerate() {
        *slot = joint(i)?;
    }
    let start = kinematics
        .forward(&q0.map(|q| q as f32))
        .map_err(|e| RunError::Scene(format!("start pose: {e:?}")))?;
    let world = world(
        start
            .position_m
            .map(|x| Position::from_m(x).unwrap_or(Position::ZERO)),
    );
    let mut safety = SafetyConfig::new(t as f32, 100.0, 40.0);
    safety.max_velocity_mps = 5.0;
    safety.ramp_ticks = 1;
    let motors: [MotorConfig; N] = core::array::from_fn(|i| {
        let n = file.motors.ratios[i];
        MotorConfig::new(
            (file.motors.peak_torque_nm * n) as f32,
            (file.motors.continuous_torque_nm * n) as f32,
        )
    });
    let limits = core::array::from_fn(|i| {
        let [lo, hi] = file.joints.limits_rad[i];
        [lo as f32, hi as f32]
    });
    let gains = ImpedanceGains::new(scene.k_c_npm as f32, scene.b_c_nspm as f32).into();
    let mut servo = LinkageServo::new(
        kinematics,
        js,
        limits,
        [gains; N],
        [safety; N],
        motors,
        world,
    )
    .map_err(|e| RunError::Servo(e.to_string()))?;
    servo.enable().map_err(|f| RunError::Servo(f.to_string()))?;

    let mut plant = LinkagePlant::at_rest(file, &scene.q0_rad);
    let (_, j) = plant.kinematics(&plant.q).map_err(RunError::Plant)?;
    let v0 = DVector::from_column_slice(&scene.v0_mps);
    plant.qd = j
        .lu()
        .solve(&v0)
        .ok_or_else(|| RunError::Scene("start pose is singular".into()))?;
    let mut trace = LinkageTrace::default();
    for tick in 0..scene.ticks {
        let raw: [u32; N] = core::array::from_fn(|i| {
            let c = ((plant.q[i] - q0[i]) * cpr[i] / std::f64::consts::TAU).round();
            c as i64 as i32 as u32
        });
        let out = servo.tick(&SensorFrame::held(tick, raw, [0.0; N]));
        let tau = out.torque_nm.map(f64::from);
        let (x, _) = plant.kinematics(&plant.q).map_err(RunError::Plant)?;
        trace.handle_m.push(x);
        trace.torque_nm.push(tau.to_vec());
        plant
            .step(&tau, &scene.hand, t, scene.substeps)
            .map_err(RunError::Plant)?;
        if !out.cartesian.faults.is_empty() {
            trace.faults = out.cartesian.faults.to_string();
            break;
        }
    }
    Ok(trace)
}
