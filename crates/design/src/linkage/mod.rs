//! Linkage devices for the designer: their files (kind, geometry, motors,
//! joints), and their dynamics at a pose through the control crate's
//! kinematics (the same Jacobian the board will run).

mod dynamics;
mod file;

pub use dynamics::SerialArmDynamics;
pub use file::{Geometry, Joints, LinkageFile, Motors};
