//! # twoport-board
//!
//! The motor-controller firmware's portable loop, `no_std` and
//! allocation-free so that it runs on the board and in host tests alike:
//! one servo tick per timer interrupt, the board-host link (handshake,
//! heartbeat, enable/disable/clear, gain get/set, telemetry, fault reports),
//! and a gate on gain changes: only gains inside the region the designer
//! proved absolutely stable are accepted; anything else is refused with the
//! reason and the proven limit. Board support (timers, PWM, ADC, UART) is
//! thin and lives with each board.
#![no_std]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod board;
pub mod excalibur;
mod io;
mod region;

pub use board::{Board, Frame, Law, TX_FRAMES};
pub use io::{IoScale, DUTY_FULL_SCALE};
pub use region::{Bound, Region, RegionError};
