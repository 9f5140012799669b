#![doc = include_str!("../README.md")]
#![no_std]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod axes;
mod crc;
mod frame;
mod handshake;
mod message;
mod spec;
mod ve;

pub use axes::{Axes, MAX_AXES};
pub use crc::crc16;
pub use frame::{encode, Decoder, Envelope, FrameError, Stats, MAX_FRAME, MAX_PAYLOAD};
pub use handshake::HandshakeError;
pub use message::{
    ActuatorFrame, AxisRefusal, AxisTelemetry, BoardMode, ConfigFallback, ConfigSource,
    ExperimentRequest, Gains, GainsReply, LinkStats, Message, ModeRefusal, ModeRequest, PilSensors,
    Refusal, Role, Status, Telemetry, NO_SESSION, PROTOCOL_VERSION,
};
pub use spec::{AxisSpec, ProvenRegion, Spec};
pub use ve::{Contact, VeParam, VeSource, VeUpdate};
