//! # twoport-link
//!
//! The board-host protocol, `no_std` and allocation-free: serde messages
//! encoded with postcard, a sequence number and a CRC-16 on every frame, COBS
//! framing with a zero delimiter, and a protocol-version handshake. A
//! corrupted, truncated or garbage frame is dropped and counted; the decoder
//! resynchronises at the next delimiter and never panics.
//!
//! ```text
//! frame = COBS( postcard(Envelope { seq: u16, msg: Message }) ++ crc16_le ) 0x00
//! ```
#![no_std]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod crc;
mod frame;
mod message;

pub use crc::crc16;
pub use frame::{encode, Decoder, Envelope, FrameError, Stats, MAX_FRAME, MAX_PAYLOAD};
pub use message::{
    ActuatorFrame, Gains, GainsReply, LinkStats, Message, Refusal, Role, SensorFrame, Telemetry,
    PROTOCOL_VERSION,
};
