//! The Excalibur at 4 kHz: the same device, wall, encoder and limits as
//! the shipped image, its servo four times as fast with the coupling and
//! region the designer proves there. A host VE at 1 kHz runs beside it:
//! the processor-in-the-loop scene that drives it is
//! `scenes/pil/fast_host_ve.toml`, its surfaces sent every 4 ticks.

use super::{safety_at, wall_servo, BuildError};
use crate::Board;
use twoport_control::homing::HomingConfig;
use twoport_control::ve::UnilateralWall;
use twoport_control::{ImpedanceGains, Position, SafetyConfig, Servo};

crate::region::shipped_region!(
    /// The proven region (impedance display, paper human bound,
    /// T = 0.25 ms, latency 25 µs).
    "../excalibur_fast_region.rs"
);

/// Control period (s): 4 kHz.
pub const PERIOD_S: f32 = 2.5e-4;
/// The coupling: 90% of the stiffest proven at 810 N s/m, the region's
/// point nearest the best pair (529,763 N/m at 863 N s/m).
pub const COUPLING: ImpedanceGains = ImpedanceGains::new(476_000.0, 810.0);
/// Ticks without a host heartbeat before the board forces zero (50 ms, as
/// the 1 kHz image).
pub const HEARTBEAT_TIMEOUT_TICKS: u32 = 200;
/// Telemetry every this many ticks (100 Hz).
pub const TELEMETRY_EVERY: u32 = 40;
/// Homing onto the stop 20 mm below the origin, as the 1 kHz image.
pub const HOMING: HomingConfig = HomingConfig::gentle(Position::from_nm(-20_000_000), PERIOD_S);

/// The axis limits at 4 kHz.
pub const fn safety() -> SafetyConfig {
    safety_at(PERIOD_S, HEARTBEAT_TIMEOUT_TICKS)
}

/// The whole 4 kHz board.
pub fn board() -> Result<Board<Servo<UnilateralWall>, REGION_POINTS>, BuildError> {
    Ok(super::wall_board(
        wall_servo(COUPLING, safety())?,
        proven_region()?,
        TELEMETRY_EVERY,
        HOMING,
    ))
}
