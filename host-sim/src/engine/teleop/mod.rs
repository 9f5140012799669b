//! Teleoperation: two devices, a master under the operator's hand and a
//! slave on the environment, each simulated as a one-axis scene's device
//! is (its plant, hand and effects), joined by the control crate's
//! teleoperator across a channel with a delay, and optionally a jitter,
//! lost packets and a passivity guard at each port.

mod link;
mod run;
mod scene;

pub use link::Link;
pub use run::{TeleopReport, TeleopSample, Teleoperation};
pub use scene::{ChannelSpec, GuardSpec, SideSpec, TeleopScene};
