//! The handshake that opens a session: the host's `Hello`, the board's
//! `HelloAck`, and what each side makes of the other's.

use crate::message::{Message, Role, NO_SESSION, PROTOCOL_VERSION};

impl Message {
    /// This side's handshake opener, for a sender that drives `axes` axes
    /// and opens `session` (not [`NO_SESSION`]).
    pub const fn hello(role: Role, axes: u8, session: u16) -> Message {
        Message::Hello {
            version: PROTOCOL_VERSION,
            role,
            axes,
            session,
        }
    }

    /// The answer of a board with `axes` axes, now in session `current`,
    /// to a `Hello`: accepted when the versions and the axis counts match
    /// and the session is one, and then in the `Hello`'s session; `None`
    /// for any other message.
    pub fn answer(&self, axes: u8, current: u16) -> Option<Message> {
        match *self {
            Message::Hello {
                version,
                axes: a,
                session,
                ..
            } => {
                let accepted = version == PROTOCOL_VERSION && a == axes && session != NO_SESSION;
                Some(Message::HelloAck {
                    version: PROTOCOL_VERSION,
                    accepted,
                    axes,
                    session: if accepted { session } else { current },
                })
            }
            _ => None,
        }
    }

    /// The session a board's answer is stamped with, for the messages that
    /// carry one.
    pub fn session(&self) -> Option<u16> {
        match self {
            Message::Actuator(a) => Some(a.session),
            Message::Telemetry(t) => Some(t.session),
            Message::Status(s) => Some(s.session),
            Message::HelloAck { session, .. } => Some(*session),
            _ => None,
        }
    }

    /// What a host that drives `axes` axes and opened `session` makes of
    /// the board's answer to its `Hello`: `Ok` when both sides agree,
    /// otherwise why not, in words for the user.
    pub fn accept_ack(&self, axes: u8, session: u16) -> Result<(), HandshakeError> {
        match *self {
            Message::HelloAck { version, .. } if version != PROTOCOL_VERSION => {
                Err(HandshakeError::Version { board: version })
            }
            Message::HelloAck { axes: board, .. } if board != axes => {
                Err(HandshakeError::Axes { board, host: axes })
            }
            Message::HelloAck {
                accepted: true,
                session: s,
                ..
            } if s == session => Ok(()),
            _ => Err(HandshakeError::NotAnAnswer),
        }
    }
}

/// Why a host will not drive a board.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum HandshakeError {
    /// The board speaks another protocol version.
    Version {
        /// The board's version.
        board: u16,
    },
    /// The board has another number of axes than this host drives.
    Axes {
        /// The board's axes.
        board: u8,
        /// This host's.
        host: u8,
    },
    /// The message is no accepting answer to a `Hello`.
    NotAnAnswer,
}

impl core::fmt::Display for HandshakeError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            HandshakeError::Version { board } => write!(
                f,
                "the board speaks protocol {board} and this host {PROTOCOL_VERSION}: \
                 flash a matching image"
            ),
            HandshakeError::Axes { board, host } => write!(
                f,
                "the board has {board} axes and this host drives {host}: \
                 use a scene (or a host) built for {board}"
            ),
            HandshakeError::NotAnAnswer => f.write_str("the board did not accept the handshake"),
        }
    }
}
