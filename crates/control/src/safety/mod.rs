//! The safety layer between every law and the actuator. Whatever a law asks
//! for, the actuator gets at most this layer's answer; any fault gives zero
//! force in the same tick, latches, and is reported until explicitly cleared.

mod config;
mod error;
mod faults;
mod layer;
#[cfg(test)]
mod tests;

pub use config::SafetyConfig;
pub use error::AxisError;
pub use faults::Faults;
pub use layer::{AxesInputs, SafeForce, SafeForces, SafetyInputs, SafetyLayer};
