//! The VE on the host (protocol 8): the board runs the coupling at its
//! servo's rate against points the host's VE sends at its own rate, held
//! between updates, and faults to zero force when they stop coming.

use crate::Axes;
use serde::{Deserialize, Serialize};

/// Where the VE the coupling holds runs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum VeSource {
    /// The board's own VE, in its image (the default at boot).
    #[default]
    Board,
    /// The host's: each [`VeUpdate`] moves each axis's surface in a
    /// straight line over `ramp_ticks` ticks, and it is held there until
    /// the next. An armed board that runs more than
    /// `deadline_ticks` ticks on one update faults to zero force.
    Host {
        /// Ticks a move takes: the host's period, in the board's ticks,
        /// spreads each update over the period (0 counts as 1).
        ramp_ticks: u32,
        /// Ticks one update may serve (at least 1).
        deadline_ticks: u32,
    },
}

/// One parameter of the board's own VE on one axis (protocol 9; its
/// surface in nanometres, as the VE holds it, since protocol 10): the VE
/// law's own type, on the wire as it is. A disarmed board takes it
/// ([`Message::SetVeParam`](crate::Message::SetVeParam)); any value in
/// range keeps the VE passive, so the proven coupling holds.
pub use twoport_control::ve::VeParam;

/// What an axis's surface in a [`VeUpdate`] is to the VE point the
/// coupling holds: the held world's own type, on the wire as it is.
pub use twoport_control::world::Contact;

/// One update of the host's VE: each axis's surface and what it is. The
/// board solves the VE point against it at its servo's rate, so a surface
/// under the handle, sent at the host's rate, renders a wall with no lag
/// in free space. The board takes an update whose `seq` is newer (by
/// wrapping order) than the last it took, and ignores any other.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct VeUpdate {
    /// The host's count of its updates.
    pub seq: u32,
    /// Each axis's surface (pm).
    pub position_pm: Axes<i64>,
    /// What each axis's surface is.
    pub contact: Axes<Contact>,
}
