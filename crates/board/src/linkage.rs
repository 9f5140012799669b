//! The linkage board images: a PHANToM-type serial arm and a Falcon-like
//! rotary delta, each a [`LinkageServo`] (joint encoders in, joint torques
//! out) around the three-axis Cartesian servo, with the coupling the
//! workspace proof gives for a grasp of at least [`GRASP_NSPM`] and a
//! floor under the handle, holding the moving masses up against gravity.
//! The numbers are the shipped device files'
//! (`models/linkages/`); a host test holds them to those files and to the
//! designer's proof.
//!
//! A linkage board is calibrated, not homed: the host puts the arm at a
//! known pose and sends its joint angles (`Calibrate`, in 1e-12 rad).

pub mod falcon_pc;
pub mod haply;
pub mod pc;
pub mod touch;

use crate::io::IoScale;
use crate::region::{Bound, Region};
use crate::{Board, BuildError, Wall};
use twoport_control::kinematics::{Delta, Kinematics, SerialArm};
use twoport_control::linkage::{Gravity, Hardware, LinkageServo};
use twoport_control::servo::ImpedanceGains;
use twoport_control::ve::{Solid, UnilateralWall};
use twoport_control::world::{PerAxis, World};
use twoport_control::{Position, SafetyConfig};

/// Control period (s): both devices' 1 kHz loop.
pub const PERIOD_S: f32 = 1.0e-3;
/// The least grasp the images' region assumes (N s/m): a dead-man switch
/// keeps force off without one.
pub const GRASP_NSPM: f32 = 2.0;
/// The coupling both images run: inside their regions at 2 N s/m.
pub const COUPLING: ImpedanceGains = ImpedanceGains::new(1_500.0, 0.5);
/// The floor a linkage image renders along its last axis: 5 mm under the
/// rest pose, 100 kN/m and 10 N s/m.
pub const FLOOR: Wall = Wall {
    surface_m: -0.005,
    solid: Solid::Below,
    stiffness_npm: 1.0e5,
    damping_nspm: 10.0,
};
/// Ticks without a host heartbeat before the board forces zero (50 ms).
pub const HEARTBEAT_TIMEOUT_TICKS: u32 = 50;
/// Telemetry every this many ticks (100 Hz).
pub const TELEMETRY_EVERY: u32 = 10;
/// The latency from sampling to the force (s) the images' regions are
/// proven for.
pub const LATENCY_S: f32 = 100e-6;
/// Grid points of a linkage image's region.
pub const REGION_POINTS: usize = 5;
/// The encoder counters' width (bits).
pub const COUNTER_BITS: u8 = 32;

/// What an image needs of its device file, for a linkage of `N` joints.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImageSpec<const N: usize = 3> {
    /// The encoders, transmissions, joint limits and motors.
    pub hardware: Hardware<N>,
    /// The least damping the handle has anywhere in the workspace, in its
    /// least damped direction (N s/m): the designer's certified lower
    /// bound on `λ_min(D_x)`, rounded down.
    pub least_damping_nspm: f32,
    /// The calibration pose (rad): where the host puts the arm.
    pub rest_rad: [f32; N],
    /// The moving masses the motors hold up (g = 9.81 m/s² along `-z`).
    pub gravity: Gravity,
}

/// The PHANToM Premium 1.5 (`phantom_premium_1_5.toml`).
// (The base's limits are the file's 1.5708 rad, as published, not π/2.)
#[allow(clippy::approx_constant)]
pub const PHANTOM: ImageSpec = ImageSpec {
    hardware: Hardware {
        counts_per_rev: 2000.0,
        ratios: [13.3, 11.2, 11.2],
        limits_rad: [[-1.5708, 1.5708], [-2.1642, 2.0769], [-0.5061, 3.7350]],
        peak_torque_nm: 0.129,
        continuous_torque_nm: 0.0286,
    },
    least_damping_nspm: 0.003_703,
    rest_rad: [0.0, 0.3, 1.2],
    // g (l1 m_a + l5 m_be + l1 m_c/2), g (l2 m_a/2 + l3 m_c - l6 m_df):
    // both counterweighted past balance.
    gravity: Gravity::SerialArm {
        upper_nm: -0.016_298,
        fore_nm: -0.073_755,
    },
};
/// A serial arm's two links (m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ArmLengths {
    /// The upper arm, `l1` (m).
    pub l1_m: f32,
    /// The forearm, `l2` (m).
    pub l2_m: f32,
}

/// Its arm.
pub const PHANTOM_ARM: ArmLengths = ArmLengths {
    l1_m: 0.215,
    l2_m: 0.170,
};

/// The Falcon-like delta (`falcon_like.toml`).
pub const FALCON: ImageSpec = ImageSpec {
    hardware: Hardware {
        counts_per_rev: 1280.0,
        ratios: [7.72, 7.72, 7.72],
        limits_rad: [[-0.3, 1.2], [-0.3, 1.2], [-0.3, 1.2]],
        peak_torque_nm: 0.1,
        continuous_torque_nm: 0.04,
    },
    least_damping_nspm: 0.087_77,
    rest_rad: [0.45, 0.45, 0.45],
    // The lumped handle's 60 g.
    gravity: Gravity::Handle { weight_n: 0.5886 },
};
/// A rotary delta's geometry (m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DeltaLengths {
    /// The base's radius to each motor's axis (m).
    pub base_m: f32,
    /// The effector's radius to each lower arm's joint (m).
    pub effector_m: f32,
    /// Each upper arm (m).
    pub upper_m: f32,
    /// Each lower arm (m).
    pub lower_m: f32,
}

/// Its geometry.
pub const FALCON_DELTA: DeltaLengths = DeltaLengths {
    base_m: 0.040,
    effector_m: 0.02309,
    upper_m: 0.060,
    lower_m: 0.1025,
};

/// The images' world: a wall on each Cartesian axis, only the floor (the
/// last axis) within reach.
pub type LinkageWorld<const N: usize = 3> = PerAxis<UnilateralWall, N>;

/// A linkage image's servo.
pub type LinkageImageServo<K, const N: usize = 3> = LinkageServo<K, LinkageWorld<N>, f32, N>;

/// A linkage image's board.
pub type LinkageBoard<K, const N: usize = 3> = Board<LinkageImageServo<K, N>, REGION_POINTS, N>;

/// The serial-arm image's board.
pub type SerialArmBoard = LinkageBoard<SerialArm>;

/// The delta image's board.
pub type DeltaBoard = LinkageBoard<Delta>;

/// The Cartesian limits every axis runs: 10 N peak, 4 N held, 2 m/s, the
/// link watchdog and the dead-man switch on.
pub fn safety() -> SafetyConfig {
    SafetyConfig {
        heartbeat_timeout_ticks: HEARTBEAT_TIMEOUT_TICKS,
        max_velocity_mps: 2.0,
        require_dead_man: true,
        ..SafetyConfig::new(PERIOD_S, 10.0, 4.0)
    }
}

/// The proven region of `spec`: at each coupling damping `b_c`, the
/// stiffest `k_c = 2 (λ_min + b_g - b_c)/((1 + 3α) T)` for a latency of
/// `α T` ([`LATENCY_S`], under a tick), for every grasp of at least
/// [`GRASP_NSPM`]: Colgate's bound with the rigid device's cost of a
/// latency, at or below the designer's workspace proof at each grid
/// point (a host test holds it there).
pub fn region<const N: usize>(
    spec: &ImageSpec<N>,
) -> Result<Region<REGION_POINTS>, crate::RegionError> {
    let total = spec.least_damping_nspm + GRASP_NSPM;
    let b: [f32; REGION_POINTS] = core::array::from_fn(|i| 0.01 + 0.24 * total * i as f32);
    let alpha = LATENCY_S / PERIOD_S;
    let k = b.map(|b| 2.0 * (total - b) / ((1.0 + 3.0 * alpha) * PERIOD_S));
    Region::new(Bound::MaxStiffness, b, k, None)?.with_latency(LATENCY_S)
}

/// Each motor's duty scale: full scale at its peak torque at the joint.
pub fn io<const N: usize>(spec: &ImageSpec<N>) -> [IoScale; N] {
    spec.hardware.ratios.map(|n| IoScale {
        force_full_scale_n: spec.hardware.peak_torque_nm * n,
        ..IoScale::EXCALIBUR
    })
}

/// The board for `spec` on `kinematics`, disarmed and uncalibrated, its
/// joints reading the rest pose until the host calibrates them: the
/// coupling and the region the board runs under, proven [`region`] at the
/// board's own latency.
pub fn board<K: Kinematics<f32, 3>>(
    spec: &ImageSpec,
    kinematics: K,
) -> Result<LinkageBoard<K>, BuildError> {
    let r = region(spec).map_err(BuildError::Region)?;
    board_with(spec, kinematics, COUPLING, r)
}

/// The board for `spec` on `kinematics` running `coupling` under
/// `region` on every axis: the world [`FLOOR`] under the rest pose along
/// the last axis, far walls along the others.
pub fn board_with<K: Kinematics<f32, N>, const N: usize>(
    spec: &ImageSpec<N>,
    kinematics: K,
    coupling: ImpedanceGains,
    region: Region<REGION_POINTS>,
) -> Result<LinkageBoard<K, N>, BuildError>
where
    LinkageWorld<N>: World<f32, N>,
{
    let servo = image_servo(spec, kinematics, coupling)?;
    Ok(Board::new(servo, [region; N], TELEMETRY_EVERY).with_io(io(spec)))
}

/// The servo of [`board_with`]'s board.
pub fn image_servo<K: Kinematics<f32, N>, const N: usize>(
    spec: &ImageSpec<N>,
    kinematics: K,
    coupling: ImpedanceGains,
) -> Result<LinkageImageServo<K, N>, BuildError>
where
    LinkageWorld<N>: World<f32, N>,
{
    let at = kinematics
        .forward(&spec.rest_rad)
        .map_err(|_| BuildError::RestPose)?
        .position_m;
    let p = |x: f32| Position::from_m(x).ok_or(BuildError::RestPose);
    // The other axes' walls: the floor's law, far above.
    let far = Wall {
        surface_m: 0.5,
        solid: Solid::Above,
        ..FLOOR
    };
    let last = N.checked_sub(1).ok_or(BuildError::RestPose)?;
    let floor = FLOOR.build(at[last], PERIOD_S, p(at[last])?)?;
    let mut walls = [floor; N];
    for (i, w) in walls.iter_mut().enumerate().take(last) {
        *w = far.build(0.0, PERIOD_S, p(at[i])?)?;
    }
    let world = PerAxis(walls);
    LinkageServo::on(
        kinematics,
        &spec.hardware,
        COUNTER_BITS,
        spec.rest_rad,
        [coupling.into(); N],
        [safety(); N],
        world,
    )
    .map_err(BuildError::Linkage)?
    .with_gravity(spec.gravity)
    .map_err(BuildError::Param)
}

/// The serial-arm image: the PHANToM Premium 1.5.
pub fn serial_arm_board() -> Result<SerialArmBoard, BuildError> {
    let arm = SerialArm::new(PHANTOM_ARM.l1_m, PHANTOM_ARM.l2_m).map_err(BuildError::Param)?;
    board(&PHANTOM, arm)
}

/// The Falcon-like delta's kinematics.
pub fn falcon_delta() -> Result<Delta, BuildError> {
    let DeltaLengths {
        base_m: r,
        effector_m: e,
        upper_m: a,
        lower_m: b,
    } = FALCON_DELTA;
    Delta::new(r, e, a, b).map_err(BuildError::Param)
}

/// The delta image: the Falcon-like delta.
pub fn delta_board() -> Result<DeltaBoard, BuildError> {
    board(&FALCON, falcon_delta()?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use twoport_control::servo::{Display, Gains};

    /// Both images build; their coupling is inside their region and 20 %
    /// past its stiffness is not.
    #[test]
    fn the_images_build_with_proven_gains() {
        assert!(serial_arm_board().is_ok());
        assert!(delta_board().is_ok());
        for spec in [PHANTOM, FALCON] {
            let r = region(&spec).unwrap();
            let g = Gains::from(COUPLING);
            assert!(r.check(Display::Impedance, &g).is_ok());
            let kmax = 2.0 * (spec.least_damping_nspm + GRASP_NSPM - COUPLING.b_nspm)
                / ((1.0 + 3.0 * LATENCY_S / PERIOD_S) * PERIOD_S);
            let past = Gains::from(ImpedanceGains::new(1.2 * kmax, COUPLING.b_nspm));
            assert!(r.check(Display::Impedance, &past).is_err());
        }
    }

    /// The PC images build; each coupling is inside its region, 20 %
    /// stiffer than its boundary is not, and the region states the PC's
    /// latency.
    #[test]
    fn the_pc_images_build_inside_their_regions() {
        assert!(haply::board().is_ok());
        assert!(falcon_pc::board().is_ok());
        let check = |r: Region<REGION_POINTS>, c: ImpedanceGains, at: f32| {
            assert_eq!(r.latency_s(), pc::LATENCY_S);
            assert!(r.check(Display::Impedance, &Gains::from(c)).is_ok());
            let past = ImpedanceGains::new(1.2 * at, c.b_nspm);
            assert!(r.check(Display::Impedance, &Gains::from(past)).is_err());
        };
        check(
            haply::IMAGE.region().unwrap(),
            haply::IMAGE.coupling,
            haply::IMAGE.limit_npm[2],
        );
        let f = falcon_pc::IMAGE;
        check(f.region().unwrap(), f.coupling, f.limit_npm[2]);
    }
}
