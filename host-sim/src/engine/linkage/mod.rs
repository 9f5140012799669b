//! Linkage devices in simulation: their nonlinear joint-space dynamics
//! and the encoders on their joints, one arm that a scene's servo, a
//! board in the loop or a test closes the loop through.

mod arm;
mod kinematics;
mod plant;
#[cfg(test)]
mod tests;

pub use arm::LinkageArm;
pub use kinematics::{AnyKinematics, Shifted};
pub use plant::{CartesianHand, LinkagePlant};
