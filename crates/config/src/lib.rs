#![doc = include_str!("../README.md")]
#![no_std]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod crc32;
mod ram;
pub mod record;
mod store;

pub use crc32::crc32;
pub use ram::{RamFlash, RamFlashError};
pub use record::{Config, HomingSetup, Limits, LoadCell, RecordError};
pub use store::{SaveError, Store};
