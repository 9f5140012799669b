//! A scene's identification experiment: what the board plays once armed,
//! in the link's terms.

use super::Scene;
use crate::Error;
use serde::Deserialize;

/// `[identify]`: a periodic multisine on one axis, every axis held by a
/// weak spring-damper that must lie in the board's proven region.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IdentifySpec {
    /// The axis excited (0 is x).
    #[serde(default)]
    pub axis: u8,
    /// When the experiment starts, after arming (s): past the arming ramp.
    #[serde(default = "default_start")]
    pub start_s: f64,
    /// The multisine's period (s): its frequency resolution is one over it.
    pub period_s: f64,
    /// The band played (Hz): every harmonic of the period from the first
    /// to the second, each below Nyquist.
    pub band_hz: [f64; 2],
    /// The multisine's peak (N).
    pub peak_n: f64,
    /// Periods played.
    pub periods: u32,
    /// The hold's stiffness (N/m).
    pub hold_k_npm: f64,
    /// The hold's damping (N s/m).
    pub hold_b_nspm: f64,
}

fn default_start() -> f64 {
    0.2
}

impl IdentifySpec {
    /// The experiment in the link's terms at the control period `tick_s`,
    /// or why it cannot be played (naming the field).
    pub fn experiment(&self, tick_s: f64) -> Result<twoport_link::ExperimentRequest, Error> {
        let period = self.period_s / tick_s;
        if !(period.is_finite() && period >= 4.0 && period <= u32::MAX as f64) {
            return Err(sim_err!(
                "identify.period_s = {} must be at least 4 ticks of {tick_s} s",
                self.period_s
            ));
        }
        let period_ticks = period.round() as u32;
        let [lo, hi] = self.band_hz.map(|f| (f * self.period_s).round());
        let nyquist = 0.5 / tick_s;
        if !(lo >= 1.0 && hi >= lo && 2.0 * hi < period_ticks as f64) {
            return Err(sim_err!(
                "identify.band_hz = {:?} must hold at least one harmonic of 1/{} Hz, from one \
                 harmonic up to below Nyquist ({nyquist} Hz)",
                self.band_hz,
                self.period_s
            ));
        }
        for (name, v) in [
            ("identify.peak_n", self.peak_n),
            ("identify.hold_k_npm", self.hold_k_npm),
            ("identify.hold_b_nspm", self.hold_b_nspm),
            ("identify.start_s", self.start_s),
        ] {
            twoport_design::field::non_negative(name, v).map_err(Error::Sim)?;
        }
        if self.periods < 2 {
            return Err(sim_err!(
                "identify.periods = {}: an estimate needs at least two periods",
                self.periods
            ));
        }
        let m = twoport_control::multisine::Multisine::new(
            period_ticks,
            lo as u32,
            hi as u32,
            self.peak_n as f32,
        )
        .map_err(|e| sim_err!("identify: {e}"))?;
        Ok(twoport_link::ExperimentRequest {
            axis: self.axis,
            period_ticks,
            first: lo as u32,
            last: hi as u32,
            amplitude_n: m.amplitude(),
            peak_n: self.peak_n as f32,
            periods: self.periods,
            hold_k_npm: self.hold_k_npm as f32,
            hold_b_nspm: self.hold_b_nspm as f32,
        })
    }
}

impl Scene {
    /// The scene's experiment, checked against its axes and period.
    pub(super) fn check_identify(&self) -> Result<(), Error> {
        let Some(x) = &self.identify else {
            return Ok(());
        };
        if x.axis >= self.axes {
            return Err(sim_err!(
                "identify.axis = {}: the device has {} axes",
                x.axis,
                self.axes
            ));
        }
        x.experiment(self.period()).map(|_| ())
    }
}
