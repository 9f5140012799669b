#![doc = include_str!("../README.md")]
#![no_std]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod board;
mod build_error;
pub mod excalibur;
mod io;
pub mod linkage;
mod region;
mod simulated;
mod support;
mod wall;

pub use board::{Board, Frame, GUARD_TICKS, TX_FRAMES};
pub use build_error::BuildError;
pub use io::{EncoderScale, IoScale, DUTY_FULL_SCALE};
pub use region::{check_axes, Bound, Region, RegionError};
pub use simulated::{SimAxis, Simulated};
pub use support::{BoardSupport, RawSensors};
pub use wall::Wall;
