//! The effects a scene may name: each absent unless named.

use serde::Deserialize;

/// The effects a scene may name. Absent means not simulated at all.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Effects {
    /// The flexible multi-mass model instead of the rigid reduction.
    #[serde(default)]
    pub flexibility: bool,
    /// The strain gauge and its analog filter (needed by an admittance display).
    #[serde(default)]
    pub load_cell: bool,
    /// Encoder quantisation.
    pub encoder: Option<EncoderEffect>,
    /// Load-cell ADC quantisation and noise.
    pub adc: Option<AdcEffect>,
    /// Amplifier saturation.
    pub saturation: Option<SaturationEffect>,
    /// Coulomb friction at the actuator.
    pub coulomb: Option<CoulombEffect>,
    /// Motor cogging.
    pub cogging: Option<CoggingEffect>,
    /// Slack in the cable between the actuator and the first link.
    pub cable_slack: Option<SlackEffect>,
    /// Sensor delay.
    pub delay: Option<DelayEffect>,
    /// The time from sampling the sensors to the force's change: the
    /// hold switches inside the tick (its whole ticks join `delay`).
    pub latency: Option<LatencyEffect>,
    /// A hard stop at the end of the actuator's travel (what homing finds).
    pub hard_stop: Option<HardStopEffect>,
    /// The coupling and VE see the device's position this many ticks late
    /// (a VE on a host behind a link), while the board's passivity layer
    /// reads it fresh.
    pub element_delay: Option<DelayEffect>,
}

/// Encoder quantisation.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EncoderEffect {
    /// Travel per count (m).
    pub resolution_m: f64,
    /// Counter width (bits).
    #[serde(default = "default_bits")]
    pub bits: u8,
    /// Where the encoder's index mark is (m), if it has one: passing it
    /// latches the count for a board that homes on the index.
    #[serde(default)]
    pub index_m: Option<f64>,
}
fn default_bits() -> u8 {
    16
}

/// ADC quantisation and seeded Gaussian noise on the load cell.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AdcEffect {
    /// Force per least significant bit (N).
    pub lsb_n: f64,
    /// Noise standard deviation (N).
    #[serde(default)]
    pub noise_rms_n: f64,
    /// Noise seed.
    #[serde(default)]
    pub seed: u64,
}

/// Amplifier force limit.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SaturationEffect {
    /// Largest force the amplifier delivers (N).
    pub limit_n: f64,
}

/// Coulomb friction at the actuator.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CoulombEffect {
    /// Friction force (N).
    pub force_n: f64,
    /// Velocity over which it is smoothed (m/s).
    #[serde(default = "default_smooth")]
    pub smoothing_mps: f64,
}
fn default_smooth() -> f64 {
    1e-3
}

/// Motor cogging: `A sin(2π x_a / period)`.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CoggingEffect {
    /// Amplitude (N).
    pub amplitude_n: f64,
    /// Spatial period at the actuator (m).
    pub period_m: f64,
}

/// A dead band in the cable between the actuator and the first link.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SlackEffect {
    /// Total free play (m).
    pub width_m: f64,
}

/// A hard stop: a stiff, damped spring that only pushes, where the
/// actuator (the end of travel) or the handle (a wall it touches) passes
/// `position_m`.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HardStopEffect {
    /// Where the stop's face is (m).
    pub position_m: f64,
    /// Which side of the face is solid.
    #[serde(default = "default_stop_side")]
    pub solid: StopSide,
    /// Its stiffness (N/m).
    #[serde(default = "default_stop_stiffness")]
    pub stiffness_npm: f64,
    /// Its damping while pressed (N s/m).
    #[serde(default = "default_stop_damping")]
    pub damping_nspm: f64,
    /// What it stops: `actuator` (the default) or `handle`.
    #[serde(default)]
    pub on: StopOn,
}

/// What a hard stop stops.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StopOn {
    /// The actuator: the end of the device's travel.
    #[default]
    Actuator,
    /// The handle: a wall in the environment.
    Handle,
}
fn default_stop_side() -> StopSide {
    StopSide::Below
}
fn default_stop_stiffness() -> f64 {
    2.0e5
}
fn default_stop_damping() -> f64 {
    50.0
}

/// The solid side of a hard stop.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StopSide {
    /// It stops travel toward negative positions.
    Below,
    /// It stops travel toward positive positions.
    Above,
}

/// Sensor delay.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DelayEffect {
    /// Ticks of delay.
    pub ticks: u32,
}

/// The time from sampling the sensors to the force's change: one of the
/// two, in seconds or in periods.
#[derive(Clone, Copy, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LatencyEffect {
    /// Seconds.
    #[serde(default)]
    pub seconds: Option<f64>,
    /// Sample periods.
    #[serde(default)]
    pub periods: Option<f64>,
}

impl LatencyEffect {
    /// The latency (s) at sample period `period_s`.
    pub fn seconds_at(&self, period_s: f64) -> f64 {
        self.seconds
            .or(self.periods.map(|p| p * period_s))
            .unwrap_or(0.0)
    }
}
