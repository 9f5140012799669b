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
//! [`Channel`] is the delay; [`FourChannel`] Lawrence's four-channel
//! architecture (each side a virtual coupling to the other side's delayed
//! motion, and each side's sensed force sent across and fed back), with
//! its two common cases as constructors: position-position
//! ([`FourChannel::position_position`]) and force reflection
//! ([`FourChannel::position_force`]: the slave tracks the master, the
//! master feels the slave's sensed force); [`WaveVariables`] a channel
//! passive whatever its delay; [`ChannelGuard`] the passivity layer on a
//! channel whose delay varies or that drops packets.

mod channel;
mod four_channel;
mod guard;
mod transfer;
mod wave;

pub use channel::Channel;
pub use four_channel::{FourChannel, FourChannelGains, Motion, TeleopStep};
pub use guard::ChannelGuard;
pub use transfer::{Delayed, Sparse, TeleopTransfer};
pub use wave::WaveVariables;

#[cfg(test)]
mod response_tests;
