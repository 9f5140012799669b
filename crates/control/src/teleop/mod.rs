//! Bilateral teleoperation: two devices, a master under the operator's
//! hand and a slave on the environment, joined through one two-port (the
//! laws on each side and the channel between them).
//!
//! A teleoperator's law takes each device's motion and gives each its
//! force; across a channel that delays what each side sends by `d` ticks.
//! Each law exposes its z-domain form as the two-port's impedance matrix
//! `F = Z(z) V` ([`TeleopTransfer`]): forces (N) on the master and the
//! slave, positive resisting each device's positive motion (the paper's
//! actuator force), per the devices' velocities (m/s).
//!
//! [`Channel`] is the delay; [`PositionPosition`] the symmetric
//! position-position architecture (each side a virtual coupling to the
//! other side's delayed motion).

mod channel;
mod position;
mod transfer;

pub use channel::Channel;
pub use position::{PositionPosition, TeleopStep};
pub use transfer::{Delayed, TeleopTransfer};
