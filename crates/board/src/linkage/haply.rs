//! The Haply 2DIY's image for the PC's loop: the pantograph's
//! [`LinkageServo`](twoport_control::linkage::LinkageServo) in the PC's
//! thread, the hAPI board reading the encoders and driving the motors over
//! USB. The numbers are `models/linkages/haply_2diy.toml`'s; a test holds
//! the region to the designer's workspace proof.

use super::{board_with, ImageSpec, LinkageBoard, REGION_POINTS};
use crate::region::{Bound, Region};
use crate::BuildError;
use twoport_control::kinematics::Pantograph;
use twoport_control::linkage::{Gravity, Hardware};
use twoport_control::servo::ImpedanceGains;

/// The latency from a sample to its force (s) the region is proven for:
/// the protocol's two ticks (the PC hands a tick's torques to the next
/// exchange, and the board answers within the next 1 ms USB frame) and
/// three more for a desktop system's scheduling, as the Excalibur's PC
/// image allows. A later force faults the board to zero.
pub const LATENCY_S: f32 = 5.0e-3;

/// The coupling the image runs: inside its region for every grasp of at
/// least [`GRASP_NSPM`](super::GRASP_NSPM), 14 % under its boundary (and
/// as stiff as the walls of Haply's own examples).
pub const COUPLING: ImpedanceGains = ImpedanceGains::new(400.0, 1.0);

/// The coupling dampings of the region's grid (N s/m).
pub const DAMPING_NSPM: [f32; REGION_POINTS] = [0.01, 0.5, 1.0, 1.5, 1.9];

/// The stiffest coupling proven at each damping (N/m): the designer's
/// branch and bound over the workspace, for a grasp of at least 2 N s/m,
/// at 1 kHz and [`LATENCY_S`], rounded down
/// (`twoport design impedance --device models/linkages/haply_2diy.toml
/// --min-grasp 2 --latency 0.005 --b B`).
pub const LIMIT_NPM: [f32; REGION_POINTS] = [128.66, 393.99, 466.56, 376.68, 139.71];

/// The five-bar's links (m): proximal `l`, distal `L`, motors `d` apart.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PantographLengths {
    /// Each proximal link (m).
    pub l_m: f32,
    /// Each distal link (m).
    pub big_l_m: f32,
    /// Between the motors (m).
    pub d_m: f32,
}

/// The hardware v3 geometry.
pub const HAPLY_LINKS: PantographLengths = PantographLengths {
    l_m: 0.07,
    big_l_m: 0.09,
    d_m: 0.038,
};

/// The 2DIY (`haply_2diy.toml`): direct drive, lying on the table (no
/// gravity on its joints).
#[allow(clippy::approx_constant)]
pub const HAPLY: ImageSpec<2> = ImageSpec {
    hardware: Hardware {
        counts_per_rev: 13_824.0,
        ratios: [1.0, 1.0],
        limits_rad: [[1.047, 3.142], [0.0, 2.094]],
        peak_torque_nm: 0.3,
        continuous_torque_nm: 0.1,
    },
    least_damping_nspm: 0.004_638,
    // 120.3 and 59.6 degrees: the handle 132 mm out, near the midline.
    rest_rad: [2.1, 1.04],
    gravity: Gravity::Off,
};

/// The image's board.
pub type HaplyBoard = LinkageBoard<Pantograph, 2>;

/// The region the image runs under, stating its latency.
pub fn region() -> Result<Region<REGION_POINTS>, crate::RegionError> {
    Region::new(Bound::MaxStiffness, DAMPING_NSPM, LIMIT_NPM, None)?.with_latency(LATENCY_S)
}

/// The image: disarmed and uncalibrated (the host puts the handle at
/// [`HAPLY`]'s rest pose and calibrates), a wall 5 mm under the rest pose
/// along `y`.
pub fn board() -> Result<HaplyBoard, BuildError> {
    let PantographLengths { l_m, big_l_m, d_m } = HAPLY_LINKS;
    let k = Pantograph::new(l_m, big_l_m, d_m).map_err(BuildError::Param)?;
    board_with(&HAPLY, k, COUPLING, region().map_err(BuildError::Region)?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use twoport_control::servo::{Display, Gains};

    /// The image builds; its coupling is inside its region, 20 % stiffer is
    /// not, and the region states the latency it is proven for.
    #[test]
    fn the_image_builds_inside_its_region() {
        assert!(board().is_ok());
        let r = region().unwrap();
        assert_eq!(r.latency_s(), LATENCY_S);
        assert!(r.check(Display::Impedance, &Gains::from(COUPLING)).is_ok());
        let past = ImpedanceGains::new(1.2 * LIMIT_NPM[2], COUPLING.b_nspm);
        assert!(r.check(Display::Impedance, &Gains::from(past)).is_err());
    }
}
