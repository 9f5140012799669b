#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod error;
mod port;
mod session;

pub use error::LinkError;
pub use port::{BoardPort, SerialBoard};
pub use session::{LinkFaults, Session, ANSWER_TIMEOUT, HEARTBEAT_EVERY};
