//! What a board says it can do (protocol 8): its servo's period, each
//! axis's force and speed limits, and the region of couplings its designer
//! proved absolutely stable, so that a host application picks its gains
//! from a proof instead of a hand-set "max stiffness".

use crate::{Axes, VeSource};
use serde::{Deserialize, Serialize};

/// The board's specification, sent in answer to [`GetSpec`].
///
/// [`GetSpec`]: crate::Message::GetSpec
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Spec {
    /// The servo's period (ns).
    pub period_ns: u32,
    /// Telemetry goes out every this many ticks (0: none outside an
    /// experiment); [`SetStream`](crate::Message::SetStream) changes it.
    pub stream_every: u32,
    /// Whether the motors turn a linkage's joints: such a board is
    /// calibrated at a known pose and has no homing run.
    pub linkage: bool,
    /// Where the VE the coupling holds runs now.
    pub ve: VeSource,
    /// What the link carries (bytes/s), where the board knows it (a UART's
    /// baud rate over ten): a stream faster than that loses frames
    /// (protocol 9).
    pub link_bytes_per_s: Option<u32>,
    /// The rate of the count the board times its loop in (Hz: core cycles
    /// on hardware; in an emulator that counts instructions, the core
    /// clock at one cycle per instruction), where it knows it (protocol 11).
    pub count_hz: Option<u32>,
    /// The longest time since boot from sampling the sensors to writing
    /// the amplifiers' command, in that count (protocol 11).
    pub worst_latency_cycles: u32,
    /// The latency from sampling to the force (s) the proven regions
    /// allow: a board that knows its count's rate faults past it, to zero
    /// force (protocol 12).
    pub latency_budget_s: f32,
    /// Each Cartesian axis's.
    pub axes: Axes<AxisSpec>,
}

impl Spec {
    /// [`worst_latency_cycles`](Self::worst_latency_cycles) in seconds,
    /// where the board gives its count's rate.
    pub fn worst_latency_s(&self) -> Option<f64> {
        self.count_hz
            .filter(|hz| *hz > 0)
            .map(|hz| f64::from(self.worst_latency_cycles) / f64::from(hz))
    }
}

/// One Cartesian axis's limits and proven region.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct AxisSpec {
    /// The force the safety layer allows for a short time (N).
    pub peak_force_n: f32,
    /// The force it allows indefinitely (N).
    pub continuous_force_n: f32,
    /// The speed past which it faults to zero force (m/s).
    pub max_velocity_mps: f32,
    /// The couplings the board accepts on this axis.
    pub region: ProvenRegion,
    /// The axis's travel, lowest and highest position (nm, the board's
    /// positions: within ±2.147 m), where the board knows it (protocol 9).
    pub workspace_nm: Option<(i32, i32)>,
}

/// The envelope of a proven region: the range of coupling damping it
/// covers and its extreme coupling. Inside the range the board accepts a
/// coupling up to its proven limit at that damping, which
/// [`Refusal::NotProvenStable`](crate::Refusal::NotProvenStable) names
/// when a request goes past it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum ProvenRegion {
    /// Impedance display: a spring-damper coupling.
    MaxStiffness {
        /// Least coupling damping proven (N s/m).
        b_min_nspm: f32,
        /// Greatest (N s/m).
        b_max_nspm: f32,
        /// The stiffest coupling proven (N/m) ...
        k_max_npm: f32,
        /// ... at this damping (N s/m).
        b_at_k_max_nspm: f32,
    },
    /// Admittance display: a mass-damper coupling, for one regulator.
    MinMass {
        /// The regulator's stiffness (N/m) ...
        kp_npm: f32,
        /// ... and damping (N s/m) the region was proven for.
        bp_nspm: f32,
        /// Least coupling damping proven (N s/m).
        b_min_nspm: f32,
        /// Greatest (N s/m).
        b_max_nspm: f32,
        /// The lightest coupling mass proven (kg) ...
        m_min_kg: f32,
        /// ... at this damping (N s/m).
        b_at_m_min_nspm: f32,
    },
}

impl ProvenRegion {
    /// Whether it bounds the impedance display's spring-damper (else the
    /// admittance display's mass-damper).
    pub fn is_impedance(&self) -> bool {
        matches!(self, ProvenRegion::MaxStiffness { .. })
    }

    /// The coupling damping it covers, least and greatest (N s/m).
    pub fn b_range_nspm(&self) -> (f32, f32) {
        match *self {
            ProvenRegion::MaxStiffness {
                b_min_nspm,
                b_max_nspm,
                ..
            }
            | ProvenRegion::MinMass {
                b_min_nspm,
                b_max_nspm,
                ..
            } => (b_min_nspm, b_max_nspm),
        }
    }

    /// Its extreme coupling, the stiffest spring (N/m) or the lightest
    /// mass (kg), and the damping it is proven at (N s/m).
    pub fn limit(&self) -> (f32, f32) {
        match *self {
            ProvenRegion::MaxStiffness {
                k_max_npm,
                b_at_k_max_nspm,
                ..
            } => (k_max_npm, b_at_k_max_nspm),
            ProvenRegion::MinMass {
                m_min_kg,
                b_at_m_min_nspm,
                ..
            } => (m_min_kg, b_at_m_min_nspm),
        }
    }

    /// The regulator `(k_p N/m, b_p N s/m)` an admittance region holds
    /// for.
    pub fn regulator(&self) -> Option<(f32, f32)> {
        match *self {
            ProvenRegion::MinMass {
                kp_npm, bp_nspm, ..
            } => Some((kp_npm, bp_nspm)),
            ProvenRegion::MaxStiffness { .. } => None,
        }
    }
}

impl Spec {
    /// The servo's period (s).
    pub fn period_s(&self) -> f64 {
        f64::from(self.period_ns) * 1e-9
    }
}
