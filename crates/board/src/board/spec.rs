//! What the board tells a host it can do (protocol 8; its travel and its
//! link's rate, protocol 9), and the telemetry rate the host asks for.

use super::Board;
use twoport_control::drive::Drive;
use twoport_link::{AxisSpec, Message, Spec};

impl<D: Drive<N>, const R: usize, const N: usize> Board<D, R, N> {
    /// The board's specification: its period, each axis's safety limits and
    /// proven region, and the telemetry rate in force.
    pub fn spec(&self) -> Spec {
        let limits = self.servo.servo().safety().configs();
        let axes = core::array::from_fn(|i| AxisSpec {
            peak_force_n: limits[i].peak_force_n,
            continuous_force_n: limits[i].continuous_force_n,
            max_velocity_mps: limits[i].max_velocity_mps,
            region: self.regions[i].envelope(),
            workspace_nm: self.workspace[i].map(|(lo, hi)| (lo.nm(), hi.nm())),
        });
        Spec {
            // (A period past 4.29 s is no servo's: the cast saturates.)
            period_ns: (f64::from(limits[0].period_s) * 1e9 + 0.5) as u32,
            stream_every: self.telemetry_every,
            linkage: !D::HOMES,
            ve: self.ve_source(),
            link_bytes_per_s: self.link_bytes_per_s,
            count_hz: self.timing.count_hz,
            worst_latency_cycles: self.timing.worst_latency,
            latency_budget_s: self.latency_budget_s(),
            axes: Self::axes(axes),
        }
    }

    /// Send telemetry every `every_ticks` ticks from the next one (0: none
    /// outside an experiment, which streams every tick regardless).
    pub fn set_stream(&mut self, every_ticks: u32) {
        self.telemetry_every = every_ticks;
        self.since_telemetry = 0;
    }

    pub(super) fn answer_spec(&mut self) {
        let spec = self.spec();
        self.queue(Message::Spec(spec));
    }

    pub(super) fn answer_stream(&mut self, every_ticks: u32) {
        self.set_stream(every_ticks);
        self.queue(Message::Stream { every_ticks });
    }
}
