//! Linkage devices in simulation: their nonlinear joint-space dynamics,
//! and runs that close the loop through the board's linkage servo.

mod plant;
mod run;
#[cfg(test)]
mod tests;

pub use plant::{CartesianHand, LinkagePlant, PlantError};
pub use run::{run_linkage, LinkageScene, LinkageTrace, RunError};
