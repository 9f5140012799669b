//! The Excalibur driven from the PC: the same device, wall, encoder and
//! limits as the shipped image, its loop run by `twoport-host`'s PC servo
//! loop against the device over a bus. The force a tick computes reaches
//! the device at the next tick's exchange, a period and more after its
//! sample, so the region is the designer's for a latency of up to 5 ms,
//! and the coupling is far softer than a board's. A force later still
//! engages the passivity layer (the series damper at the actuator's
//! port), as on every image for the PC's loop.

use super::{safety, wall_servo, BuildError, ACTUATOR_PORT, HOMING, PERIOD_S, TELEMETRY_EVERY};
use crate::Board;
use twoport_control::passivity::{PassivityLimits, SeriesDamper};
use twoport_control::servo::OnDemand;
use twoport_control::ve::UnilateralWall;
use twoport_control::{ImpedanceGains, Servo};

crate::region::shipped_region!(
    /// The proven region (impedance display, paper human bound, T = 1 ms,
    /// latency 5 ms).
    "../excalibur_pc_region.rs"
);

/// The coupling: 88% of the stiffest proven at 4 N s/m, the region's
/// point nearest the best pair.
pub const COUPLING: ImpedanceGains = ImpedanceGains::new(3_000.0, 4.0);

/// The whole board, for the PC's loop.
pub fn board(
) -> Result<Board<Servo<UnilateralWall, f32, 1, OnDemand<SeriesDamper>>, REGION_POINTS>, BuildError>
{
    let port = ACTUATOR_PORT;
    let mut limits = PassivityLimits::for_device(port.mass_kg, PERIOD_S, safety().peak_force_n)?;
    limits.device_damping_nspm = port.damping_nspm;
    let layer = OnDemand::new(SeriesDamper::new(limits)?);
    Ok(super::wall_board(
        wall_servo(COUPLING, safety())?.with_layers([layer])?,
        proven_region()?,
        TELEMETRY_EVERY,
        HOMING,
    ))
}
