//! One axis's limits, and the Excalibur's.

use crate::{param, ParamError};

/// Limits of one actuator axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SafetyConfig {
    /// Sample period `T` (s).
    pub period_s: f32,
    /// Largest force at any instant (N).
    pub peak_force_n: f32,
    /// Largest force that may be held indefinitely (N).
    pub continuous_force_n: f32,
    /// Time at peak force from cold before the thermal budget folds the limit
    /// back to the continuous force (s). Sets the I^2 t budget
    /// `(peak^2 - continuous^2) * peak_duration`.
    pub peak_duration_s: f32,
    /// Largest handle speed (m/s).
    pub max_velocity_mps: f32,
    /// Load-cell range (N): a reading beyond it is a fault.
    pub max_sensor_force_n: f32,
    /// Ticks without a link heartbeat before a fault; 0 disables the check.
    pub heartbeat_timeout_ticks: u32,
    /// Ticks over which force ramps in after enable or clear (>= 1).
    pub ramp_ticks: u32,
    /// Whether an open dead-man switch is a fault.
    pub require_dead_man: bool,
}

impl SafetyConfig {
    /// A cautious configuration for any actuator: `peak_force_n` (N) for
    /// at most 2 s from cold, `continuous_force_n` (N) indefinitely, at
    /// period `period_s` (s); 1 m/s at most, a load-cell range of 1.25 times
    /// the peak, a 100 ms ramp-in, the dead-man switch required and no link
    /// heartbeat. Adjust the fields for the device; [`validate`](Self::validate)
    /// names a bad one.
    ///
    /// # Examples
    ///
    /// ```
    /// use twoport_control::SafetyConfig;
    /// let cfg = SafetyConfig::new(1e-3, 10.0, 4.0);
    /// assert!(cfg.validate().is_ok());
    /// assert!(cfg.require_dead_man);
    /// assert!(SafetyConfig::new(1e-3, 4.0, 10.0).validate().is_err());
    /// ```
    pub fn new(period_s: f32, peak_force_n: f32, continuous_force_n: f32) -> Self {
        SafetyConfig {
            period_s,
            peak_force_n,
            continuous_force_n,
            peak_duration_s: 2.0,
            max_velocity_mps: 1.0,
            max_sensor_force_n: 1.25 * peak_force_n,
            heartbeat_timeout_ticks: 0,
            ramp_ticks: ((0.1 / period_s) as u32).max(1),
            require_dead_man: true,
        }
    }

    /// Excalibur's axis: 200 N peak, 100 N continuous (paper section III),
    /// 2 s at peak, 1 m/s, a 250 N load cell, 100 ms ramp, 1 kHz.
    pub const fn excalibur() -> Self {
        SafetyConfig {
            period_s: 1.0e-3,
            peak_force_n: 200.0,
            continuous_force_n: 100.0,
            peak_duration_s: 2.0,
            max_velocity_mps: 1.0,
            max_sensor_force_n: 250.0,
            heartbeat_timeout_ticks: 0,
            ramp_ticks: 100,
            require_dead_man: false,
        }
    }

    /// Check every field; the error names the field.
    pub fn validate(&self) -> Result<(), ParamError> {
        param::positive("safety.period_s (s)", self.period_s)?;
        param::positive("safety.peak_force_n (N)", self.peak_force_n)?;
        param::positive("safety.continuous_force_n (N)", self.continuous_force_n)?;
        if self.continuous_force_n > self.peak_force_n {
            return Err(ParamError {
                name: "safety.continuous_force_n (N)",
                value: self.continuous_force_n,
                problem: "must not exceed safety.peak_force_n",
            });
        }
        param::non_negative("safety.peak_duration_s (s)", self.peak_duration_s)?;
        param::positive("safety.max_velocity_mps (m/s)", self.max_velocity_mps)?;
        param::positive("safety.max_sensor_force_n (N)", self.max_sensor_force_n)?;
        if self.ramp_ticks == 0 {
            return Err(ParamError {
                name: "safety.ramp_ticks",
                value: 0.0,
                problem: "must be >= 1",
            });
        }
        Ok(())
    }

    pub(super) fn thermal_budget(&self) -> f32 {
        let (p, c) = (self.peak_force_n, self.continuous_force_n);
        (p * p - c * c) * self.peak_duration_s
    }
}
