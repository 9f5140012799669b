//! What can go wrong on the host's side of a link.

use thiserror::Error;
use twoport_link::{AxisRefusal, ModeRefusal, ModeRequest};

/// Why a call to a board failed.
#[derive(Clone, Debug, PartialEq, Error)]
#[non_exhaustive]
pub enum LinkError {
    /// The serial port would not open.
    #[error("serial port {path}: {why}")]
    Open {
        /// Its path.
        path: String,
        /// What the system said.
        why: String,
    },
    /// Reading or writing the transport failed.
    #[error("serial {0}")]
    Transport(String),
    /// A message would not encode into a frame.
    #[error("encode: {0}")]
    Encode(String),
    /// No board image to run in-process.
    #[error("{0}")]
    Image(String),
    /// The device a loop on the PC drives failed (it stopped answering,
    /// or answered nonsense): the loop has stopped with zero force.
    #[error("device: {0}")]
    Device(String),
    /// No answer to the handshake.
    #[error("no handshake answer from the board (this host speaks protocol {0})")]
    NoHandshake(u16),
    /// The board's handshake answer does not fit this host (another
    /// protocol, another axis count).
    #[error("{0}")]
    Handshake(String),
    /// No answer in time.
    #[error("the board did not answer {what} within {seconds} s")]
    Timeout {
        /// What was asked.
        what: String,
        /// How long the host waited (s).
        seconds: u64,
    },
    /// The board refused a mode change or a request, and why.
    #[error("the board refused {asked:?}: {}", refusal(why))]
    Refused {
        /// What was asked.
        asked: ModeRequest,
        /// The board's reason.
        why: ModeRefusal,
    },
    /// The board answers with no session: it has reset since the
    /// handshake.
    #[error(
        "the board has reset since the handshake: it answers with no session, not this host's {0}"
    )]
    Reset(u16),
    /// The board answers in another host's session.
    #[error("another host has opened session {found} with the board since this host's {ours}")]
    Foreign {
        /// The session the board answers in.
        found: u16,
        /// This host's.
        ours: u16,
    },
    /// The board refused gains, naming the first axis it refused and why.
    #[error("the board refused the gains of axis {}: {:?}", .0.axis, .0.why)]
    GainsRefused(AxisRefusal),
    /// A call gave another number of values than the board has axes.
    #[error("{what}: {given} values for a board of {board} axes")]
    Axes {
        /// The call.
        what: String,
        /// Values given.
        given: usize,
        /// The board's axes.
        board: usize,
    },
    /// A position outside the board's range (±2.147 m), or not a number.
    #[error("{what}: axis {axis} at {value_m} m is outside the board's range (±2.147 m)")]
    OutOfRange {
        /// The call.
        what: String,
        /// The axis.
        axis: usize,
        /// The value given (m).
        value_m: f64,
    },
    /// A value the board would not take, named before it is sent.
    #[error("{what} {why}")]
    BadValue {
        /// The call and the value.
        what: String,
        /// What is wrong with it.
        why: String,
    },
    /// The board latched faults (their bits) while the host waited.
    #[error("the board faulted: {}", twoport_control::Faults(*.0))]
    Faulted(u16),
}

/// A refusal in words, with latched faults named.
fn refusal(why: &ModeRefusal) -> String {
    match why {
        ModeRefusal::Faulted { faults } => {
            format!("faults latched: {}", twoport_control::Faults(*faults))
        }
        other => format!("{other:?}"),
    }
}
