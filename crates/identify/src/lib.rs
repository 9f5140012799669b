#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod error;
#[cfg(feature = "plot")]
pub mod figures;
pub mod fit;
pub mod frf;
pub mod log;
pub mod pose;
pub mod stepped;

pub use error::IdentifyError;
