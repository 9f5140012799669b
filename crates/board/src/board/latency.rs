//! The loop's timing and its latency gate: how long each tick took, and
//! a force later than the regions are proven for faulted, or guarded by
//! the passivity layer.

use super::Board;
use twoport_control::drive::Drive;
use twoport_control::servo::PortLayer;
use twoport_control::Faults;
use twoport_link::BoardMode;

/// Ticks on time after its last late one that a board's passivity layer
/// stays engaged for: a second at 1 kHz, so that a run of late ticks with
/// a few on time between them is guarded throughout.
pub const GUARD_TICKS: u32 = 1000;

/// The loop's timing, in the support's count.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Timing {
    pub(super) stages: [u32; 3],
    last_start: Option<u32>,
    pub(super) deadline_misses: u32,
    pub(super) worst_jitter: u32,
    /// The longest from the sample to the amplifiers' command since boot.
    pub(super) worst_latency: u32,
    /// The rate of the count `cycles` gives (Hz), where the image knows it.
    pub(super) count_hz: Option<u32>,
    /// The greatest latency, in that count, the regions are proven for.
    late_after: Option<u32>,
    /// Armed ticks whose force came later than the regions allow, run on
    /// under the passivity layer.
    late_guarded: u32,
    /// Ticks the passivity layer stays engaged for (none: idle).
    guarding: u32,
}

impl Timing {
    /// A tick that started (sampled) at `start`, ran its stages through
    /// the instants `t` and whose force reached the device `latency` after
    /// its sample, against a period of `period` (0: unchecked).
    pub(super) fn record(&mut self, start: u32, t: [u32; 3], latency: u32, period: u32) {
        self.stages = [
            t[0].wrapping_sub(start),
            t[1].wrapping_sub(t[0]),
            t[2].wrapping_sub(t[1]),
        ];
        self.worst_latency = self.worst_latency.max(latency);
        if period > 0 {
            let took = t[2].wrapping_sub(start);
            let late = self.last_start.is_some_and(|s0| {
                let dt = start.wrapping_sub(s0);
                self.worst_jitter = self.worst_jitter.max(dt.abs_diff(period));
                dt > period + period / 2
            });
            if took > period || late {
                self.deadline_misses = self.deadline_misses.saturating_add(1);
            }
        }
        self.last_start = Some(start);
    }
}

impl<D: Drive<N>, const R: usize, const N: usize> Board<D, R, N> {
    /// The same board stating the rate of its support's
    /// [`cycles`](crate::BoardSupport::cycles) count (Hz: its core clock; in an
    /// emulator that counts instructions, the core clock at one cycle per
    /// instruction), so that its spec gives its latency in seconds.
    ///
    /// Knowing it, the board holds its latency to what its regions are
    /// proven for: armed, a force that reaches the device later latches
    /// [`Faults::LATE_FORCE`], and from the next tick on the force is zero;
    /// unless a passivity layer guards the port
    /// ([`PortLayer::GUARDS_LATENCY`]): then the board engages it, runs on,
    /// and lets it go idle again [`GUARD_TICKS`] ticks after the last late
    /// one ([`late_guarded`](Self::late_guarded) counts them).
    pub fn with_count_rate(mut self, hz: u32) -> Self {
        self.timing.count_hz = Some(hz);
        // (f64: a budget of microseconds at a GHz count is exact.)
        let counts = f64::from(self.latency_budget_s()) * f64::from(hz);
        self.timing.late_after = Some(if counts < f64::from(u32::MAX) {
            counts as u32
        } else {
            u32::MAX
        });
        self
    }

    /// Whether the passivity layer is engaged after a late force.
    pub fn guarding(&self) -> bool {
        self.timing.guarding > 0
    }

    /// Armed ticks whose force came later than the regions allow, run on
    /// with the passivity layer engaged.
    pub fn late_guarded(&self) -> u32 {
        self.timing.late_guarded
    }

    /// The latency from sampling to the force (s) every axis's region is
    /// proven for.
    pub fn latency_budget_s(&self) -> f32 {
        self.regions
            .iter()
            .map(|r| r.latency_s())
            .fold(f32::INFINITY, f32::min)
    }

    /// Hold this tick's `latency` (counts from its sample to its force)
    /// to the regions' budget.
    #[inline(always)]
    pub(super) fn hold_latency(&mut self, latency: u32) {
        // The regions prove the coupling: its force is what must not come
        // late (homing's and an experiment's laws are not the coupling,
        // and a tick that ends them may run long).
        let coupled = self.mode == BoardMode::Armed && self.outputs_on;
        if coupled
            && self
                .timing
                .late_after
                .is_some_and(|budget| latency > budget)
        {
            if <D::Layer as PortLayer>::GUARDS_LATENCY {
                // Past the proof, the passivity layer keeps the port
                // passive: the loop runs on with it engaged, until it has
                // been on time for a while.
                self.timing.late_guarded = self.timing.late_guarded.saturating_add(1);
                if self.timing.guarding == 0 {
                    self.servo.servo_mut().engage_layers();
                }
                self.timing.guarding = GUARD_TICKS;
            } else {
                self.servo.servo_mut().trip(Faults::LATE_FORCE);
            }
        } else if self.timing.guarding > 0 {
            self.timing.guarding -= 1;
            if self.timing.guarding == 0 {
                self.servo.servo_mut().disengage_layers();
            }
        }
    }
}
