//! The fault bits: what latched, by name.

use core::fmt;

/// A set of fault reasons (bit flags).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Faults(pub u16);

impl Faults {
    /// No fault.
    pub const NONE: Faults = Faults(0);
    /// A sensor gave NaN or infinity.
    pub const SENSOR_NOT_FINITE: Faults = Faults(1 << 0);
    /// A sensor reading is beyond its range or at its rail.
    pub const SENSOR_OUT_OF_RANGE: Faults = Faults(1 << 1);
    /// The encoder gave a raw value its counter cannot hold.
    pub const ENCODER_INVALID: Faults = Faults(1 << 2);
    /// The handle moved faster than the velocity limit.
    pub const VELOCITY_LIMIT: Faults = Faults(1 << 3);
    /// The dead-man switch opened while enabled.
    pub const DEAD_MAN: Faults = Faults(1 << 4);
    /// A control tick was missed (the tick counter skipped).
    pub const MISSED_TICK: Faults = Faults(1 << 5);
    /// No link heartbeat within the timeout while enabled.
    pub const HEARTBEAT_LOST: Faults = Faults(1 << 6);
    /// A law produced a non-finite force.
    pub const COMMAND_NOT_FINITE: Faults = Faults(1 << 7);
    /// Homing found no hard stop: it timed out, or its own checks failed.
    pub const HOMING_FAILED: Faults = Faults(1 << 8);
    /// The board restarted from its watchdog: the loop had hung.
    pub const WATCHDOG_RESET: Faults = Faults(1 << 9);
    /// A linkage's pose is singular, out of reach or outside the joint
    /// limits its gains were proven for.
    pub const KINEMATICS: Faults = Faults(1 << 10);
    /// The host's VE sent no update within its deadline.
    pub const VE_STALE: Faults = Faults(1 << 11);
    /// A force reached the device later after its sample than the proven
    /// gains allow.
    pub const LATE_FORCE: Faults = Faults(1 << 12);

    const NAMES: [(Faults, &'static str); 13] = [
        (Faults::SENSOR_NOT_FINITE, "sensor reading not finite"),
        (Faults::SENSOR_OUT_OF_RANGE, "sensor reading out of range"),
        (Faults::ENCODER_INVALID, "encoder value invalid"),
        (Faults::VELOCITY_LIMIT, "velocity limit exceeded"),
        (Faults::DEAD_MAN, "dead-man switch released"),
        (Faults::MISSED_TICK, "control tick missed"),
        (Faults::HEARTBEAT_LOST, "link heartbeat lost"),
        (Faults::COMMAND_NOT_FINITE, "force command not finite"),
        (Faults::HOMING_FAILED, "homing found no hard stop"),
        (Faults::WATCHDOG_RESET, "watchdog reset: the loop hung"),
        (
            Faults::KINEMATICS,
            "pose singular, out of reach or outside the proven joints",
        ),
        (
            Faults::VE_STALE,
            "host VE late: no update within its deadline",
        ),
        (
            Faults::LATE_FORCE,
            "force late: the latency passed what the gains are proven for",
        ),
    ];

    /// Whether no fault is set.
    pub const fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// Whether every fault of `other` is set.
    pub const fn contains(self, other: Faults) -> bool {
        self.0 & other.0 == other.0
    }

    /// The union.
    pub const fn with(self, other: Faults) -> Faults {
        Faults(self.0 | other.0)
    }

    /// The lowest-numbered fault set, alone.
    pub const fn lowest(self) -> Faults {
        Faults(self.0 & self.0.wrapping_neg())
    }

    /// Each set fault's description.
    pub fn names(self) -> impl Iterator<Item = &'static str> {
        Self::NAMES
            .into_iter()
            .filter(move |(f, _)| self.contains(*f))
            .map(|(_, n)| n)
    }
}

impl fmt::Display for Faults {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.is_empty() {
            return f.write_str("no fault");
        }
        for (i, n) in self.names().enumerate() {
            if i > 0 {
                f.write_str(", ")?;
            }
            f.write_str(n)?;
        }
        Ok(())
    }
}
