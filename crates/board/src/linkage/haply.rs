//! The Haply 2DIY's image for the PC's loop: the pantograph's
//! [`LinkageServo`](twoport_control::linkage::LinkageServo) in the PC's
//! thread, the hAPI board reading the encoders and driving the motors over
//! USB. The numbers are `models/linkages/haply_2diy.toml`'s; a test holds
//! the region to the designer's workspace proof
//! (`twoport design impedance --device models/linkages/haply_2diy.toml
//! --min-grasp 2 --latency 0.005 --b B`).

use super::pc::{PcImage, PcLinkageBoard};
use super::ImageSpec;
use crate::BuildError;
use twoport_control::kinematics::Pantograph;
use twoport_control::linkage::{Gravity, Hardware};
use twoport_control::servo::ImpedanceGains;

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
// (The limits are the file's 3.142 rad, as written there, not π.)
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

/// The image: 400 N/m at 1 N s/m (14 % under its boundary, and as stiff
/// as the walls of Haply's own examples).
pub const IMAGE: PcImage<2> = PcImage {
    spec: HAPLY,
    coupling: ImpedanceGains::new(400.0, 1.0),
    damping_nspm: [0.01, 0.5, 1.0, 1.5, 1.9],
    port_mass_kg: 0.02,
    limit_npm: [128.66, 393.99, 466.56, 376.68, 139.71],
};

/// The image's board.
pub type HaplyBoard = PcLinkageBoard<Pantograph, 2>;

/// The image's board on the v3 geometry.
pub fn board() -> Result<HaplyBoard, BuildError> {
    let PantographLengths { l_m, big_l_m, d_m } = HAPLY_LINKS;
    IMAGE.board(Pantograph::new(l_m, big_l_m, d_m).map_err(BuildError::Param)?)
}
