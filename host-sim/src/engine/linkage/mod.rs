//! Linkage devices in simulation: their nonlinear joint-space dynamics,
//! and runs that close the loop through the board's linkage servo.

mod kinematics;
mod plant;
mod run;
#[cfg(test)]
mod tests;

pub use kinematics::{AnyKinematics, Shifted};
pub use plant::{CartesianHand, LinkagePlant, PlantError};
pub use run::{run_linkage, LinkageScene, LinkageTrace, RunError};
