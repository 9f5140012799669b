//! The Excalibur board image: what the firmware ships with and what the
//! host's processor-in-the-loop reference builds, from one place. The
//! impedance display at 90 N s/m, the paper's coupling damping, holding
//! the stiff wall of the default scene (`scenes/stiff_wall.toml`), and the
//! region of gains the designer proved absolutely stable for a latency of
//! up to 50 µs from sampling to the force.

use crate::io::{EncoderScale, IoScale};
use crate::region::Region;
use crate::Board;
use crate::{BuildError, Wall};
use twoport_control::homing::HomingConfig;
use twoport_control::passivity::{PassivityLimits, SeriesDamper};
use twoport_control::servo::PortLayer;
use twoport_control::ve::{Solid, UnilateralWall};
use twoport_control::{Encoder, ImpedanceGains, Position, SafetyConfig, Servo};

pub mod fast;
pub mod pc;
pub mod xyz;

crate::region::shipped_region!(
    /// The proven region (impedance display, paper human bound, T = 1 ms,
    /// latency 50 µs).
    "excalibur_region.rs"
);

/// Control period (s).
pub const PERIOD_S: f32 = 1.0e-3;
/// The encoder: a 16-bit counter of 1 um counts.
pub const ENCODER: EncoderScale = EncoderScale {
    bits: 16,
    pm_per_count: 1_000_000,
};
/// The coupling: 95% of the stiffest the region proves at the paper's
/// damping (45,770 N/m at 90 N s/m). The paper's 51,000 N/m sits on the
/// boundary proven with no latency, and any latency leaves it outside.
pub const COUPLING: ImpedanceGains = ImpedanceGains::new(43_500.0, 90.0);
/// The wall: 1 cm up, solid above, 5 MN/m and 200 N s/m.
pub const WALL: Wall = Wall {
    surface_m: 0.010,
    solid: Solid::Above,
    stiffness_npm: 5.0e6,
    damping_nspm: 200.0,
};
/// Ticks without a host heartbeat before the board forces zero (50 ms).
pub const HEARTBEAT_TIMEOUT_TICKS: u32 = 50;
/// Homing: the hard stop is 20 mm below the origin (the wall's surface is
/// at +10 mm), and the axis homes onto it gently
/// ([`HomingConfig::gentle`]: 20 mm/s, at most 5 N).
pub const HOMING: HomingConfig = HomingConfig::gentle(Position::from_nm(-20_000_000), PERIOD_S);
/// Telemetry every this many ticks (100 Hz).
pub const TELEMETRY_EVERY: u32 = 10;

/// The axis limits: Excalibur's, with the link watchdog and the dead-man
/// switch on.
pub const fn safety() -> SafetyConfig {
    safety_at(PERIOD_S, HEARTBEAT_TIMEOUT_TICKS)
}

/// [`safety`] for a servo of period `period_s` (s) whose watchdog waits
/// `heartbeat_ticks`.
pub(crate) const fn safety_at(period_s: f32, heartbeat_ticks: u32) -> SafetyConfig {
    SafetyConfig {
        period_s,
        heartbeat_timeout_ticks: heartbeat_ticks,
        require_dead_man: true,
        ..SafetyConfig::excalibur()
    }
}

/// The board's servo: the impedance display on the wall, disabled until the
/// host enables it.
pub fn stiff_wall_servo() -> Result<Servo<UnilateralWall>, BuildError> {
    wall_servo(COUPLING, safety())
}

/// The impedance display with `coupling` on the wall, under `safety` (its
/// period the servo's).
pub(crate) fn wall_servo(
    coupling: ImpedanceGains,
    safety: SafetyConfig,
) -> Result<Servo<UnilateralWall>, BuildError> {
    let enc = Encoder::new(ENCODER.bits, ENCODER.pm_per_count, 0, Position::ZERO)?;
    let ve = WALL.build(0.0, safety.period_s, Position::ZERO)?;
    Ok(Servo::new([coupling.into()], [enc], [safety], ve)?)
}

/// A device's port as the passivity layer sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ActuatorPort {
    /// The moving mass at the encoder (kg).
    pub mass_kg: f32,
    /// A lower bound of its own viscous damping (N s/m).
    pub damping_nspm: f32,
}

/// The actuator's port: the model's actuator inertia, and 4 N s/m of its
/// damping.
pub const ACTUATOR_PORT: ActuatorPort = ActuatorPort {
    mass_kg: 0.93,
    damping_nspm: 4.0,
};

/// The stiff wall's servo with the passivity layer (the series damper) at
/// the actuator's port: the passivity image's.
pub fn stiff_wall_servo_with_passivity(
) -> Result<Servo<UnilateralWall, f32, 1, SeriesDamper>, BuildError> {
    let port = ACTUATOR_PORT;
    let mut limits = PassivityLimits::for_device(port.mass_kg, PERIOD_S, safety().peak_force_n)?;
    limits.device_damping_nspm = port.damping_nspm;
    let layer = SeriesDamper::new(limits)?;
    Ok(stiff_wall_servo()?.with_layers([layer])?)
}

/// The passivity image's board: [`stiff_wall_board`] with the series
/// damper between the actuator's port and the coupling.
pub fn stiff_wall_board_with_passivity(
) -> Result<Board<Servo<UnilateralWall, f32, 1, SeriesDamper>, REGION_POINTS>, BuildError> {
    Ok(wall_board(
        stiff_wall_servo_with_passivity()?,
        proven_region()?,
        TELEMETRY_EVERY,
        HOMING,
    ))
}

/// The whole board: servo, region, telemetry rate, I/O scaling. It reads its
/// own sensors; the processor-in-the-loop images add `.with_pil(true)`.
pub fn stiff_wall_board() -> Result<Board<Servo<UnilateralWall>, REGION_POINTS>, BuildError> {
    Ok(wall_board(
        stiff_wall_servo()?,
        proven_region()?,
        TELEMETRY_EVERY,
        HOMING,
    ))
}

/// A one-axis Excalibur board: `servo` on the wall, accepting gains inside
/// `region`, telemetry every `telemetry_every` ticks, the Excalibur's I/O
/// scaling, homing with `homing`.
pub(crate) fn wall_board<L: PortLayer, const R: usize>(
    servo: Servo<UnilateralWall, f32, 1, L>,
    region: Region<R>,
    telemetry_every: u32,
    homing: HomingConfig,
) -> Board<Servo<UnilateralWall, f32, 1, L>, R> {
    Board::new(servo, [region], telemetry_every)
        .with_io([IoScale::EXCALIBUR])
        .with_homing([homing])
}
