//! The 3D Systems Touch's image for the PC's loop: the serial arm's
//! [`LinkageServo`](twoport_control::linkage::LinkageServo) in the loop
//! OpenHaptics' scheduler runs, the HD library reading the joints' angles
//! and taking their torques. The numbers are
//! `models/linkages/touch.toml`'s; a test holds the region to the
//! designer's workspace proof (`twoport design impedance --device
//! models/linkages/touch.toml --min-grasp 2 --latency 0.005 --b B`).

use super::pc::{PcImage, PcLinkageBoard};
use super::{ArmLengths, ImageSpec};
use crate::BuildError;
use twoport_control::kinematics::SerialArm;
use twoport_control::linkage::{Gravity, Hardware};
use twoport_control::servo::ImpedanceGains;

/// The Touch's links (m).
pub const TOUCH_ARM: ArmLengths = ArmLengths {
    l1_m: 0.133_35,
    l2_m: 0.133_35,
};

/// The Touch (`touch.toml`): its joints driven directly as the HD library
/// drives them, its counts the quantum the driver reads the library's
/// angles at.
pub const TOUCH: ImageSpec = ImageSpec {
    hardware: Hardware {
        counts_per_rev: 15_000.0,
        ratios: [1.0, 1.0, 1.0],
        limits_rad: [[-0.98, 0.98], [-0.2, 1.75], [-0.35, 2.1]],
        peak_torque_nm: 0.44,
        continuous_torque_nm: 0.117,
    },
    least_damping_nspm: 0.007_433,
    rest_rad: [0.0, 0.3, 1.2],
    // The lumped handle's 45 g.
    gravity: Gravity::Handle { weight_n: 0.441_45 },
};

/// The image: 400 N/m at 1 N s/m (14 % under its boundary, and CHAI3D's
/// hand-set stiffness for the Touch).
pub const IMAGE: PcImage<3> = PcImage {
    spec: TOUCH,
    coupling: ImpedanceGains::new(400.0, 1.0),
    damping_nspm: [0.01, 0.5, 1.0, 1.5, 1.9],
    port_mass_kg: 0.045,
    limit_npm: [128.82, 394.31, 467.24, 377.95, 142.52],
};

/// The image's board.
pub type TouchBoard = PcLinkageBoard<SerialArm, 3>;

/// The image's board.
pub fn board() -> Result<TouchBoard, BuildError> {
    let ArmLengths { l1_m, l2_m } = TOUCH_ARM;
    IMAGE.board(SerialArm::new(l1_m, l2_m).map_err(BuildError::Param)?)
}
