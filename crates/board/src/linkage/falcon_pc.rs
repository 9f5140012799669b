//! The Novint Falcon's image for the PC's loop: the delta's
//! [`LinkageServo`](twoport_control::linkage::LinkageServo) in the PC's
//! thread, the Falcon's firmware reading the encoders and driving the
//! motors over USB. The device is the delta image's ([`FALCON`]); a test
//! holds the region to the designer's workspace proof
//! (`twoport design impedance --device models/linkages/falcon_like.toml
//! --min-grasp 2 --latency 0.005 --b B`).

use super::pc::{PcImage, PcLinkageBoard};
use super::{falcon_delta, FALCON};
use crate::BuildError;
use twoport_control::kinematics::Delta;
use twoport_control::servo::ImpedanceGains;

/// The image: 400 N/m at 1 N s/m (18 % under its boundary).
pub const IMAGE: PcImage<3> = PcImage {
    spec: FALCON,
    coupling: ImpedanceGains::new(400.0, 1.0),
    damping_nspm: [0.01, 0.5, 1.0, 1.5, 1.9],
    port_mass_kg: 0.06,
    limit_npm: [133.36, 403.44, 486.24, 412.93, 213.92],
};

/// The image's board.
pub type FalconBoard = PcLinkageBoard<Delta, 3>;

/// The image's board.
pub fn board() -> Result<FalconBoard, BuildError> {
    IMAGE.board(falcon_delta()?)
}
