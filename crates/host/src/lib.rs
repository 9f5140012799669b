#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod attached;
mod device;
pub mod device_port;
mod error;
pub mod falcon;
pub mod haply;
mod in_process;
mod local;
mod packet;
mod pc_loop;
mod port;
mod session;
mod simulated;
pub mod touch;

pub use device::{AxisState, HostBoard, State, HEARTBEAT_PERIOD, HEARTBEAT_POLLS, STATE_BUFFER};
pub use error::LinkError;
pub use local::{LocalBoard, LocalDelta, LocalFast, LocalSerialArm};
pub use packet::PacketError;
pub use pc_loop::{
    accept_unproven_gains, DeviceIo, LoopThread, LoopTiming, PcBoard, Percentiles, Priority,
    SteppedPc, Ticker, LATE_PERIODS, STALL, TIMING_WINDOW,
};
pub use port::{BoardPort, SerialBoard};
pub use session::{LinkFaults, Session, ANSWER_TIMEOUT, HEARTBEAT_EVERY};
pub use simulated::{Pace, SimulatedBoard, SimulatedDevice};

/// The link's types an application meets in this crate's calls.
pub use twoport_link::{
    Axes, AxisSpec, BoardMode, Contact, Gains, ProvenRegion, Spec, Status, VeParam, VeSource,
};
