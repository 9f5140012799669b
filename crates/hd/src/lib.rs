#![doc = include_str!("../README.md")]
#![warn(missing_docs)]

mod consts;
mod device;
mod error;
mod library;

pub use consts::*;
pub use device::{HdDevice, HdFrame, Scheduled};
pub use error::HdError;
pub use library::{HdLibrary, DEFAULT_NAME};
