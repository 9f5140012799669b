//! Bilateral teleoperation: two devices, a master under the operator's
//! hand and a slave on the environment, joined through one two-port (the
//! laws on each side and the channel between them).
//!
//! A teleoperator's law takes each device's motion and gives each its
//! force; across a channel that delays what each side sends by `d` ticks.
//! Each law exposes its z-domain form ([`TeleopTransfer`]): forces (N) on
//! the master and the slave, positive resisting each device's positive
//! motion (the paper's actuator force), per the devices' velocities (m/s)
//! (the two-port's impedance matrix `F = Z(z) V`) and per the force the
//! slave's sensor reads.
//!
//! [`Channel`] is the delay; [`PositionPosition`] the symmetric
//! position-position architecture (each side a virtual coupling to the
//! other side's delayed motion); [`PositionForce`] force reflection (the
//! slave tracks the master, the master feels the slave's sensed force);
//! [`WaveVariables`] a channel passive whatever its delay.

mod channel;
mod force;
mod position;
mod transfer;
mod wave;

pub use channel::Channel;
pub use force::PositionForce;
pub use position::{Motion, PositionPosition, TeleopStep};
pub use transfer::{Delayed, TeleopTransfer};
pub use wave::WaveVariables;
