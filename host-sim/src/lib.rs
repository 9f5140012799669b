//! # host-sim
//!
//! The simulator: the device model from the designer's model files, the
//! human operator and the VE around the board's own control code
//! (`twoport-control`, f32), stepping at the control period behind a hold.
//! Only the effects a scene names are simulated; a linear scene runs the
//! exact discrete update with no sub-steps.
#![forbid(unsafe_code)]

pub mod accuracy;
pub mod app;
pub mod blocks;
pub mod human;
pub mod pil;
pub mod plant;
pub mod plot;
pub mod scene;
pub mod scope;
pub mod sim;
pub mod stability;
#[cfg(feature = "gui")]
pub mod ui;
pub mod ve;
#[cfg(feature = "gui")]
pub mod window;

pub use scene::Scene;
pub use sim::{Report, Sample, Simulation};
