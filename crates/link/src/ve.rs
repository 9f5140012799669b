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
    /// The host's: each [`VeUpdate`] moves the coupling's VE point per
    /// axis, in a straight line over `ramp_ticks` ticks, and it is held
    /// there until the next. An armed board that runs more than
    /// `deadline_ticks` ticks on one update faults to zero force.
    Host {
        /// Ticks a move takes: the host's period, in the board's ticks,
        /// spreads each update over the period (0 counts as 1).
        ramp_ticks: u32,
        /// Ticks one update may serve (at least 1).
        deadline_ticks: u32,
    },
}

/// One update of the host's VE: where each axis's VE point is now. The
/// board takes an update whose `seq` is newer (by wrapping order) than the
/// last it took, and ignores any other.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct VeUpdate {
    /// The host's count of its updates.
    pub seq: u32,
    /// Each axis's VE point (pm).
    pub position_pm: Axes<i64>,
}
