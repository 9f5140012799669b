//! Scaling between the raw peripherals and SI units: the PWM duty that
//! commands the amplifier, the load-cell ADC counts. The same functions run
//! on the board and in the host's processor-in-the-loop reference, so both
//! quantise a force identically.

/// Full-scale signed PWM duty: ±`DUTY_FULL_SCALE` commands ± the
/// amplifier's full-scale force.
pub const DUTY_FULL_SCALE: i16 = i16::MAX;

/// How the board's peripherals map to SI units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IoScale {
    /// Actuator force at full-scale duty (N).
    pub force_full_scale_n: f32,
    /// Load-cell force per ADC count (N).
    pub load_cell_n_per_count: f32,
    /// The load cell's ADC reading at zero force (counts).
    pub load_cell_offset_counts: i32,
}

impl IoScale {
    /// The Excalibur's amplifier (200 N peak, the safety layer's limit) and
    /// a 1 mN-per-count load-cell front end.
    pub const EXCALIBUR: IoScale = IoScale {
        force_full_scale_n: 200.0,
        load_cell_n_per_count: 1.0e-3,
        load_cell_offset_counts: 0,
    };

    /// The signed duty for `force_n`, rounded to the nearest step and
    /// clamped to full scale; a non-finite force gives zero duty.
    pub fn duty(&self, force_n: f32) -> i16 {
        let d = force_n / self.force_full_scale_n * DUTY_FULL_SCALE as f32;
        if !d.is_finite() {
            return 0;
        }
        let full = DUTY_FULL_SCALE as f32;
        let r = d.clamp(-full, full);
        // Round half away from zero without libm.
        (r + 0.5f32.copysign(r)) as i16
    }

    /// The force a duty commands (N).
    pub fn force_n(&self, duty: i16) -> f32 {
        duty.max(-DUTY_FULL_SCALE) as f32 * (self.force_full_scale_n / DUTY_FULL_SCALE as f32)
    }

    /// The load-cell force for an ADC reading (N).
    pub fn load_cell_n(&self, counts: i32) -> f32 {
        counts.saturating_sub(self.load_cell_offset_counts) as f32 * self.load_cell_n_per_count
    }

    /// The ADC reading (counts, nearest, half away from zero; saturating,
    /// NaN gives 0) a load-cell force gives: what a processor-in-the-loop
    /// host sends for a simulated force.
    pub fn load_cell_counts(&self, force_n: f32) -> i32 {
        let c = force_n / self.load_cell_n_per_count;
        ((c + 0.5f32.copysign(c)) as i32).saturating_add(self.load_cell_offset_counts)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn duty_round_trips_within_half_a_step_and_clamps() {
        let s = IoScale::EXCALIBUR;
        let step = s.force_full_scale_n / DUTY_FULL_SCALE as f32;
        for i in -2000..=2000 {
            let f = i as f32 * 0.0937;
            let back = s.force_n(s.duty(f));
            // Half a step, plus f32 rounding of the product at 100 N.
            assert!((back - f).abs() <= 0.5 * step * 1.01, "{f} -> {back}");
        }
        assert_eq!(s.duty(1e9), DUTY_FULL_SCALE);
        assert_eq!(s.duty(-1e9), -DUTY_FULL_SCALE);
        assert_eq!(s.duty(f32::NAN), 0);
        assert_eq!(s.duty(f32::INFINITY), 0);
        assert_eq!(s.force_n(i16::MIN), -s.force_full_scale_n);
        assert_eq!(s.duty(0.0), 0);
        assert_eq!(s.duty(-0.5 * step * 0.99), 0);
    }

    #[test]
    fn load_cell_counts_invert_load_cell_n() {
        let s = IoScale::EXCALIBUR;
        for c in [-250_000, -1001, -1, 0, 1, 999, 250_000] {
            assert_eq!(s.load_cell_counts(s.load_cell_n(c)), c);
        }
        assert_eq!(s.load_cell_counts(0.0014), 1);
        assert_eq!(s.load_cell_counts(-0.0016), -2);
        assert_eq!(s.load_cell_counts(f32::NAN), 0);
        // A calibrated zero offset shifts the counts, not the forces.
        let o = IoScale {
            load_cell_offset_counts: 2048,
            ..s
        };
        assert_eq!(o.load_cell_counts(0.0), 2048);
        assert_eq!(o.load_cell_n(2048 + 1500), s.load_cell_n(1500));
        assert_eq!(o.load_cell_n(i32::MIN), i32::MIN as f32 * 1e-3);
    }
}

/// A linear encoder as an image reads it: its counter's width and its
/// resolution.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EncoderScale {
    /// The counter's width (bits).
    pub bits: u8,
    /// Picometres per count.
    pub pm_per_count: i64,
}
