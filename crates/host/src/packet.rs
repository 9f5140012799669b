//! What is wrong with a device's packet, whichever protocol carries it
//! (the Haply board's, the Falcon's).

use std::fmt;

/// What is wrong with a packet.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum PacketError {
    /// Fewer bytes than the packet needs.
    Short {
        /// Bytes there.
        got: usize,
        /// Bytes needed.
        need: usize,
    },
    /// A reply or packet for another device.
    DeviceId {
        /// The id it carries.
        got: u8,
        /// The id set up.
        expected: u8,
    },
    /// A type byte the protocol does not have.
    Type(u8),
    /// A setup the protocol cannot carry (ports, directions, pins), named.
    Setup(String),
    /// A value that is not a finite number, at its position in the reply.
    NotFinite {
        /// Which value (sensors first, then encoders).
        index: usize,
    },
    /// Not framed by `<` and `>`.
    Frame,
    /// A byte that is not a nibble offset by `0x41`, at its position.
    Nibble(usize),
}

impl fmt::Display for PacketError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PacketError::Short { got, need } => {
                write!(f, "a short packet: {got} of its {need} bytes")
            }
            PacketError::DeviceId { got, expected } => write!(
                f,
                "a packet for device id {got} where device {expected} is set up \
                 (another program on the port, or a garbled byte)"
            ),
            PacketError::Type(t) => write!(f, "packet type {t}: the protocol has 0, 1 and 2"),
            PacketError::Setup(why) => write!(f, "a setup the protocol cannot carry: {why}"),
            PacketError::NotFinite { index } => {
                write!(f, "value {index} of the reply is not a finite number")
            }
            PacketError::Frame => write!(f, "a packet not framed by '<' and '>'"),
            PacketError::Nibble(at) => {
                write!(f, "byte {at} of a packet is not a nibble offset by 0x41")
            }
        }
    }
}

impl std::error::Error for PacketError {}
