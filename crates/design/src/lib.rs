#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

pub mod design;
pub mod device;
#[cfg(feature = "plot")]
pub mod figures;
pub mod linalg;
pub mod model;
pub mod plant;
#[cfg(feature = "plot")]
pub mod plot;
pub mod rational;
pub mod sampled;
pub mod twoport;
pub mod verify;

pub use device::{Device, DeviceAxis};
pub use model::{DeviceModel, ModelError};
pub use plant::{Plant, PlantPoint};
