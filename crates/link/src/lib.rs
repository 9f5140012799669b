#![doc = include_str!("../README.md")]
#![no_std]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod crc;
mod frame;
mod message;

pub use crc::crc16;
pub use frame::{encode, Decoder, Envelope, FrameError, Stats, MAX_FRAME, MAX_PAYLOAD};
pub use message::{
    ActuatorFrame, ConfigFallback, ConfigSource, Gains, GainsReply, LinkStats, Message, Mode,
    ModeRefusal, ModeRequest, Refusal, Role, SensorFrame, Status, Telemetry, PROTOCOL_VERSION,
};
