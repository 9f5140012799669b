// (Indexing by axis reads as the maths does.)
#![allow(clippy::needless_range_loop)]

use super::*;
use crate::kinematics::{Delta, SerialArm};
use crate::servo::ImpedanceGains;
use crate::ve::BilateralConstraint;
use crate::world::PerAxis;

const CPR: f32 = 26_600.0;
const LIMITS: JointLimits<3> = [[-1.6, 1.6], [-2.2, 2.1], [-0.5, 3.7]];
const Q0: [f32; 3] = [0.1, 0.2, 0.9];

fn arm() -> SerialArm {
    SerialArm::new(0.215, 0.17).unwrap()
}

fn here(q: [f32; 3]) -> [Position; 3] {
    let x = Kinematics::<f32, 3>::forward(&arm(), &q)
        .unwrap()
        .position_m;
    x.map(|x| Position::from_m(x).unwrap())
}

fn servo(
    k_npm: f32,
    motors: [MotorConfig; 3],
) -> LinkageServo<SerialArm, PerAxis<BilateralConstraint, 3>> {
    let joints = Q0.map(|q| JointEncoder::new(16, CPR, 0, q).unwrap());
    let world = PerAxis(here(Q0).map(BilateralConstraint::new));
    let gains = [ImpedanceGains::new(k_npm, 2.0).into(); 3];
    let mut safety = [SafetyConfig::new(1e-3, 20.0, 10.0); 3];
    for s in &mut safety {
        // (The tests step the joints by many counts a tick.)
        s.ramp_ticks = 1;
        s.max_velocity_mps = 50.0;
    }
    let mut s = LinkageServo::new(arm(), joints, LIMITS, gains, safety, motors, world).unwrap();
    s.enable().unwrap();
    s
}

fn frame(k: u32, counts: [i32; 3]) -> SensorFrame<f32, 3> {
    SensorFrame::held(k, counts.map(|c| c as u32 & 0xFFFF), [0.0; 3])
}

fn angles(counts: [i32; 3]) -> [f32; 3] {
    core::array::from_fn(|i| Q0[i] + counts[i] as f32 * core::f32::consts::TAU / CPR)
}

/// The handle the Cartesian servo sees is the kinematics' at the joint
/// angles the encoders read, to the nanometre, and the motors hold
/// `J^T f` of the force it commands.
#[test]
fn joints_in_torques_out_through_the_jacobian() {
    let mut s = servo(500.0, [MotorConfig::new(50.0, 20.0); 3]);
    for k in 0..300u32 {
        let c = [
            (k as i32 * 7) % 90 - 40,
            30 - (k as i32 * 3) % 70,
            (k as i32) % 50,
        ];
        let out = s.tick(&frame(k, c));
        assert!(out.cartesian.faults.is_empty(), "{}", out.cartesian.faults);
        let pose = Kinematics::<f32, 3>::forward(&arm(), &angles(c)).unwrap();
        for i in 0..3 {
            let want = Position::from_m(pose.position_m[i]).unwrap().nm();
            // (f32 metres hold a position near 0.3 m to 30 nm.)
            let got = out.cartesian.position[i].nm();
            assert!(
                (got - want).abs() <= 32,
                "tick {k} axis {i}: {got} vs {want}"
            );
        }
        // The servo's Jacobian is the kinematics' at what its encoders read.
        let used = s.pose();
        for (r, w) in used
            .jacobian
            .iter()
            .flatten()
            .zip(pose.jacobian.iter().flatten())
        {
            assert!((r - w).abs() < 1e-5, "tick {k}");
        }
        assert_eq!(
            out.torque_nm,
            used.torques_nm(&out.cartesian.actuator_force_n)
        );
        assert!(!out.torque_limited);
    }
}

/// The Cartesian laws are the N-axis servo's: a Cartesian servo fed the
/// same handle positions commands the same forces, bit for bit.
#[test]
fn the_cartesian_servo_is_the_one_path() {
    let mut s = servo(500.0, [MotorConfig::new(5.0, 2.0); 3]);
    let start = s.cartesian().position();
    let encoders = start.map(Encoder::nanometre_counter);
    let world = PerAxis(start.map(BilateralConstraint::new));
    let mut safety = [SafetyConfig::new(1e-3, 20.0, 10.0); 3];
    for s in &mut safety {
        // (The tests step the joints by many counts a tick.)
        s.ramp_ticks = 1;
        s.max_velocity_mps = 50.0;
    }
    let mut plain = Servo::new(
        [ImpedanceGains::new(500.0, 2.0).into(); 3],
        encoders,
        safety,
        world,
    )
    .unwrap();
    plain.enable().unwrap();
    for k in 0..200u32 {
        let c = [(k as i32 * 5) % 60, -(k as i32 % 40), (k as i32 * 2) % 30];
        let out = s.tick(&frame(k, c));
        let raw = out.cartesian.position.map(|p| p.nm() as u32);
        let twin = plain.tick(&SensorFrame::held(k, raw, [0.0; 3]));
        assert_eq!(
            out.cartesian.actuator_force_n, twin.actuator_force_n,
            "tick {k}"
        );
    }
}

/// Into a singular pose (the forearm along the upper arm, q3 - q2 = 90°)
/// or past a joint limit: zero torque on every motor that tick, the
/// reason named, and it stays latched until cleared.
#[test]
fn a_pose_it_cannot_serve_means_zero_torque_named() {
    let mut s = servo(500.0, [MotorConfig::new(5.0, 2.0); 3]);
    let per_rad = CPR / core::f32::consts::TAU;
    let out = s.tick(&frame(0, [40, 0, 0]));
    assert!(out.torque_nm.iter().any(|t| t.abs() > 1e-3));
    // q3 = q2 + 90°: det J = 0.
    let to_singular = ((0.2 + core::f32::consts::FRAC_PI_2 - 0.9) * per_rad) as i32;
    let out = s.tick(&frame(1, [40, 0, to_singular]));
    assert_eq!(out.torque_nm, [0.0; 3]);
    assert!(out.cartesian.faults.contains(Faults::KINEMATICS));
    assert_eq!(s.kinematics_fault(), Some(KinematicsFault::Singular));
    let out = s.tick(&frame(2, [40, 0, 0]));
    assert_eq!(out.torque_nm, [0.0; 3]);
    s.clear();
    s.enable().unwrap();
    // (Clearing re-aligns the constraint to where the handle is.)
    assert!(s
        .tick(&frame(3, [60, 0, 0]))
        .torque_nm
        .iter()
        .any(|t| t.abs() > 1e-3));
    // The base past its 1.6 rad limit.
    let past = ((1.65 - 0.1) * per_rad) as i32;
    let out = s.tick(&frame(4, [past, 0, 0]));
    assert_eq!(out.torque_nm, [0.0; 3]);
    assert_eq!(s.kinematics_fault(), Some(KinematicsFault::OutsideLimits));
    // A raw count wider than the 16-bit counter: the encoder's fault.
    s.clear();
    s.enable().unwrap();
    let out = s.tick(&SensorFrame::held(5, [70_000, 0, 0], [0.0; 3]));
    assert_eq!(out.torque_nm, [0.0; 3]);
    assert!(out.cartesian.faults.contains(Faults::ENCODER_INVALID));
}

/// Past a motor's peak the torque vector shrinks as a whole: its direction
/// (and so the force's at the handle) is kept, and the motor at its limit
/// holds exactly its peak. Held there, the I²t budget folds it back to
/// the continuous torque.
#[test]
fn motor_limits_scale_the_torque_vector() {
    let peak = 0.5;
    let mut s = servo(4_000.0, [MotorConfig::new(peak, 0.2); 3]);
    let c = [300, -200, 150];
    let mut unlimited = servo(4_000.0, [MotorConfig::new(50.0, 20.0); 3]);
    let out = s.tick(&frame(0, c));
    let want = unlimited.tick(&frame(0, c)).torque_nm;
    assert!(out.torque_limited);
    let big = want.iter().fold(0.0f32, |m, t| m.max(t.abs()));
    assert!(big > peak);
    let largest = out.torque_nm.iter().fold(0.0f32, |m, t| m.max(t.abs()));
    assert!((largest - peak).abs() < 1e-6 * peak, "{largest}");
    for i in 0..3 {
        assert!(
            (out.torque_nm[i] - want[i] * peak / big).abs() < 1e-6,
            "{out:?}"
        );
    }
    let mut last = out;
    for k in 1..4_000 {
        last = s.tick(&frame(k, c));
    }
    let largest = last.torque_nm.iter().fold(0.0f32, |m, t| m.max(t.abs()));
    assert!((largest - 0.2).abs() < 1e-6, "{largest}");
    assert!(s.motors().thermal_load(0) > 0.99 || s.motors().thermal_load(1) > 0.99);
}

/// Calibrating the joints moves the handle with them, and the next reads
/// go on from there with no step in the velocity.
#[test]
fn calibrating_the_joints_moves_the_handle() {
    let mut s = servo(500.0, [MotorConfig::new(5.0, 2.0); 3]);
    s.tick(&frame(0, [100, 0, 0]));
    s.disable();
    let q = [0.3, 0.1, 1.2];
    s.calibrate_joints(q);
    let at = Kinematics::<f32, 3>::forward(&arm(), &q)
        .unwrap()
        .position_m;
    let out = s.tick(&frame(1, [100, 0, 0]));
    for i in 0..3 {
        let want = Position::from_m(at[i]).unwrap().nm();
        let got = out.cartesian.position[i].nm();
        assert!((got - want).abs() <= 32, "axis {i}: {got} vs {want}");
        assert_eq!(out.cartesian.velocity_mps[i], 0.0);
    }
    // One count of the base: the handle swings `reach · 2π/CPR` in 1 ms.
    let out = s.tick(&frame(2, [101, 0, 0]));
    let [vx, vy, vz] = out.cartesian.velocity_mps;
    let reach = (at[0] * at[0] + at[1] * at[1]).sqrt();
    let want = reach * core::f32::consts::TAU / CPR / 1e-3;
    assert!(((vx * vx + vy * vy).sqrt() - want).abs() < 0.02 * want);
    assert!(vz.abs() < 1e-3 * want);
}

/// A delta serves the same servo: the handle follows its forward solve and
/// the motors hold `J^T f`.
#[test]
fn a_delta_runs_the_same_servo() {
    let delta = Delta::new(0.06, 0.0, 0.1025, 0.2).unwrap();
    let q0 = [0.5f32; 3];
    let at = Kinematics::<f32, 3>::forward(&delta, &q0).unwrap();
    let joints = q0.map(|q| JointEncoder::new(16, 2_470.0, 0, q).unwrap());
    let world = PerAxis(
        at.position_m
            .map(|x| BilateralConstraint::new(Position::from_m(x).unwrap())),
    );
    let gains = [ImpedanceGains::new(2_000.0, 0.0).into(); 3];
    let mut safety = [SafetyConfig::new(1e-3, 20.0, 10.0); 3];
    for s in &mut safety {
        s.max_velocity_mps = 50.0;
    }
    let limits = [[-0.8, 1.6]; 3];
    let mut s = LinkageServo::new(
        delta,
        joints,
        limits,
        gains,
        safety,
        [MotorConfig::new(5.0, 2.0); 3],
        PerAxis(world.0),
    )
    .unwrap();
    s.enable().unwrap();
    let mut out = s.tick(&frame(0, [10, 0, 0]));
    for k in 1..200 {
        out = s.tick(&frame(k, [10, 0, 0]));
    }
    let pose = *s.pose();
    let tau = pose.torques_nm(&out.cartesian.actuator_force_n);
    assert!(out.torque_nm[0].abs() > 1e-4);
    for i in 0..3 {
        assert!((out.torque_nm[i] - tau[i]).abs() < 1e-6);
    }
    // Resisting: the torque on the moved joint opposes its motion.
    assert!(out.torque_nm[0] > 0.0);
}

/// Bad limits are refused by name.
#[test]
fn bad_limits_are_refused() {
    let joints = Q0.map(|q| JointEncoder::new(16, CPR, 0, q).unwrap());
    let world = PerAxis(here(Q0).map(BilateralConstraint::new));
    let gains = [ImpedanceGains::new(500.0, 2.0).into(); 3];
    let safety = [SafetyConfig::new(1e-3, 20.0, 10.0); 3];
    let ok = [MotorConfig::new(5.0, 2.0); 3];
    let mut limits = LIMITS;
    limits[2] = [1.0, 1.0];
    let e = LinkageServo::<_, _, f32, 3>::new(arm(), joints, limits, gains, safety, ok, world)
        .unwrap_err();
    assert_eq!(e, LinkageError::JointLimit(2));
    let mut bad = ok;
    bad[1] = MotorConfig::new(1.0, 2.0);
    let e = LinkageServo::<_, _, f32, 3>::new(arm(), joints, LIMITS, gains, safety, bad, world)
        .unwrap_err();
    assert!(
        matches!(e, LinkageError::Motor(AxisError { axis: 1, .. })),
        "{e}"
    );
}

/// Gravity held up: with the handle where the VE holds it (no coupling
/// force), the motors give `-G(q)`, the serial arm's link moments through
/// `cos q2` and `sin q3`, and a handle's weight through the Jacobian's
/// height row; disabled, or with a fault latched, nothing at all.
#[test]
fn gravity_is_held_up_only_while_the_servo_may_push() {
    let (upper, fore) = (0.21, -0.05);
    let g = Gravity::SerialArm {
        upper_nm: upper,
        fore_nm: fore,
    };
    let mut s = servo(500.0, [MotorConfig::new(50.0, 20.0); 3])
        .with_gravity(g)
        .unwrap();
    let out = s.tick(&frame(0, [0; 3]));
    let want = [0.0, -upper * Q0[1].cos(), -fore * Q0[2].sin()];
    for i in 0..3 {
        assert!(
            (out.torque_nm[i] - want[i]).abs() < 1e-6,
            "{:?}",
            out.torque_nm
        );
    }
    let w = 0.6;
    let mut h = servo(500.0, [MotorConfig::new(50.0, 20.0); 3])
        .with_gravity(Gravity::Handle { weight_n: w })
        .unwrap();
    let out = h.tick(&frame(0, [0; 3]));
    let j = Kinematics::<f32, 3>::forward(&arm(), &Q0).unwrap().jacobian;
    for i in 0..3 {
        assert!((out.torque_nm[i] + w * j[2][i]).abs() < 1e-6);
    }
    s.disable();
    assert_eq!(s.tick(&frame(1, [0; 3])).torque_nm, [0.0; 3]);
    s.clear();
    s.enable().unwrap();
    s.trip(Faults::KINEMATICS);
    assert_eq!(s.tick(&frame(2, [0; 3])).torque_nm, [0.0; 3]);
    let bad = Gravity::Handle { weight_n: f32::NAN };
    assert!(servo(500.0, [MotorConfig::new(5.0, 2.0); 3])
        .with_gravity(bad)
        .is_err());
}
