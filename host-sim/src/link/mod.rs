//! The host's side of the link to a board, written once for every host
//! tool (the processor-in-the-loop runs and the scope's board mode): the
//! transport ([`BoardPort`]: a serial port, or the board loop in this
//! process), and a [`Session`] over it: the handshake, heartbeats, the
//! request and answer calls, the lockstep exchange of sensor and actuator
//! frames, and the faults a test injects into the link.
//!
//! A session knows its board by the session number it opened: the board
//! stamps it on every answer, so a board that has reset since the
//! handshake (it answers with [`twoport_link::NO_SESSION`]) is seen by
//! protocol, whatever the timing, and every call after it fails saying so.

mod error;
mod local;
mod port;
mod session;

pub use error::LinkError;
pub use local::{LocalBoard, LocalDelta, LocalSerialArm};
pub use port::{BoardPort, SerialBoard};
pub use session::{LinkFaults, Session, ANSWER_TIMEOUT, HEARTBEAT_EVERY};
