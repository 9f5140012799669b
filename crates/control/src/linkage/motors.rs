//! Each motor's torque limits: a peak, and a continuous torque the I²t
//! budget folds back to.

use crate::param::positive;
use crate::safety::AxisError;
use crate::{ParamError, Real};

/// One motor's torque limits at its joint (after the transmission).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MotorConfig {
    /// Largest torque at any instant (N m).
    pub peak_torque_nm: f32,
    /// Largest torque that may be held indefinitely (N m).
    pub continuous_torque_nm: f32,
    /// Time at peak torque from cold before the limit folds back to the
    /// continuous torque (s).
    pub peak_duration_s: f32,
}

impl MotorConfig {
    /// `peak_torque_nm` (N m) for at most 2 s from cold,
    /// `continuous_torque_nm` (N m) indefinitely.
    pub fn new(peak_torque_nm: f32, continuous_torque_nm: f32) -> Self {
        MotorConfig {
            peak_torque_nm,
            continuous_torque_nm,
            peak_duration_s: 2.0,
        }
    }

    /// Refused, naming the field, where a limit is not finite and > 0 or
    /// the continuous torque exceeds the peak.
    pub fn validate(&self) -> Result<(), ParamError> {
        positive("motors.peak_torque_nm (N m)", self.peak_torque_nm)?;
        positive(
            "motors.continuous_torque_nm (N m)",
            self.continuous_torque_nm,
        )?;
        positive("motors.peak_duration_s (s)", self.peak_duration_s)?;
        if self.continuous_torque_nm > self.peak_torque_nm {
            return Err(ParamError {
                name: "motors.continuous_torque_nm (N m)",
                value: self.continuous_torque_nm,
                problem: "must be at most the peak torque",
            });
        }
        Ok(())
    }
}

/// The torques a tick's motors may hold, and whether the limits scaled
/// them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LimitedTorques<R, const N: usize> {
    /// Each motor's torque (N m).
    pub torque_nm: [R; N],
    /// Whether the vector was scaled down to fit the limits.
    pub limited: bool,
}

/// Every motor's limits and thermal state. A torque vector past any
/// motor's limit is scaled down as a whole, so the force at the handle
/// keeps its direction (clipping each motor alone would turn it, and a
/// turned force can push the hand along a direction the coupling never
/// asked for).
#[derive(Clone, Copy, Debug)]
pub struct MotorLimits<R, const N: usize> {
    peak: [R; N],
    continuous: [R; N],
    continuous_sq: [R; N],
    /// The I²t budget in N² m² ticks.
    budget: [R; N],
    heat: [R; N],
}

impl<R: Real, const N: usize> MotorLimits<R, N> {
    /// Each motor's limits at period `period_s` (s); the error names the
    /// motor and the field.
    pub fn new(cfg: [MotorConfig; N], period_s: f32) -> Result<Self, AxisError> {
        let period_s = positive("period_s (s)", period_s).map_err(|e| AxisError::new(0, e))?;
        for (i, c) in cfg.iter().enumerate() {
            c.validate().map_err(|e| AxisError::new(i, e))?;
        }
        let sq = |x: f32| x * x;
        Ok(MotorLimits {
            peak: cfg.map(|c| R::of(c.peak_torque_nm)),
            continuous: cfg.map(|c| R::of(c.continuous_torque_nm)),
            continuous_sq: cfg.map(|c| R::of(sq(c.continuous_torque_nm))),
            budget: cfg.map(|c| {
                R::of(
                    (sq(c.peak_torque_nm) - sq(c.continuous_torque_nm)) * c.peak_duration_s
                        / period_s,
                )
            }),
            heat: [R::ZERO; N],
        })
    }

    /// The finite `torque_nm` (N m) scaled to every motor's limit, and the
    /// motors' heat booked. Call once per tick.
    #[inline(always)]
    pub fn step(&mut self, torque_nm: [R; N]) -> LimitedTorques<R, N> {
        let mut scale = R::ONE;
        for ((t, h), (b, (c, p))) in torque_nm.iter().zip(&self.heat).zip(
            self.budget
                .iter()
                .zip(self.continuous.iter().zip(&self.peak)),
        ) {
            let limit = if *h >= *b { *c } else { *p };
            let t = t.abs();
            if t * scale > limit {
                scale = limit / t;
            }
        }
        let limited = scale < R::ONE;
        let out = torque_nm.map(|t| t * scale);
        for ((heat, o), shed) in self.heat.iter_mut().zip(&out).zip(&self.continuous_sq) {
            let h = *heat + (*o * *o - *shed);
            *heat = if h > R::ZERO { h } else { R::ZERO };
        }
        LimitedTorques {
            torque_nm: out,
            limited,
        }
    }

    /// Motor `i`'s spent share of its I²t budget (0 cold, 1 folded back).
    pub fn thermal_load(&self, i: usize) -> f32 {
        match (self.heat.get(i), self.budget.get(i)) {
            (Some(h), Some(b)) if b.to_f32() > 0.0 => (h.to_f32() / b.to_f32()).min(1.0),
            _ => 0.0,
        }
    }
}
