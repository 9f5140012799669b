#![doc = include_str!("../README.md")]
#![no_std]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

#[cfg(test)]
extern crate std;

pub mod coupling;
pub mod drive;
mod encoder;
mod estimator;
pub mod experiment;
pub mod homing;
pub mod kinematics;
pub mod linkage;
pub mod multisine;
mod param;
pub mod passivity;
mod position;
mod probe;
mod real;
mod regulator;
mod root;
pub mod safety;
pub mod servo;
pub mod teleop;
mod tf;
mod trig;
pub mod ve;
pub mod world;

#[cfg(test)]
mod response_tests;

pub use coupling::{AdmittanceCoupling, ImpedanceCoupling};
pub use encoder::{Encoder, EncoderError};
pub use estimator::FirstDifference;
pub use num_complex::Complex64;
pub use param::ParamError;
pub use position::{Integrator, Position, NM_PER_M};
pub use probe::SineProbe;
pub use real::Real;
pub use regulator::PositionRegulator;
pub use safety::{AxisError, Faults, SafetyConfig, SafetyLayer};
// (`servo::Display` stays in its module: at the root it would shadow
// `core::fmt::Display` for anyone who imports the crate whole.)
pub use servo::{
    AdmittanceGains, Gains, GainsError, ImpedanceGains, SensorFrame, Servo, ServoOutput,
};
pub use tf::ZTransfer;
