//! # twoport-design
//!
//! Two-port analysis and virtual-coupling synthesis for haptic displays
//! (Adams & Hannaford 2002), in f64. The couplings and regulator analysed
//! here are the control crate's own laws, through their z-domain forms.
#![forbid(unsafe_code)]

pub mod design;
pub mod figures;
pub mod linalg;
pub mod model;
pub mod plant;
pub mod plot;
pub mod rational;
pub mod sampled;
pub mod twoport;
pub mod verify;

pub use model::{DeviceModel, ModelError};
pub use plant::{Plant, PlantPoint};
