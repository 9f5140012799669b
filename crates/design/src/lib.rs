#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod analysis;
pub mod designer;
pub mod device;
mod error;
pub mod field;
#[cfg(feature = "plot")]
pub mod figures;
pub mod host_ve;
pub mod limit_cycle;
pub mod linalg;
pub mod linkage;
pub mod model;
pub mod network;
mod par;
pub mod plant;
#[cfg(feature = "plot")]
pub mod plot;
pub mod rational;
pub mod sampled;
#[cfg(test)]
mod test_rng;
pub mod verify;

pub use designer::Designer;
pub use device::{Device, DeviceAxis};
pub use error::Error;
pub use model::{DeviceModel, Lag, ModelError};
pub use plant::{Plant, PlantPoint};
