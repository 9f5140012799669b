//! A periodic multisine: the excitation an identification experiment
//! plays, tick by tick, on the board.
//!
//! Harmonics `first..=last` of the period `P` ticks, each of the same
//! amplitude, with Schroeder's phases `φ_i = -π i (i - 1)/K` (`i` from 1
//! to `K`, the harmonics' count), which keep the peak near `sqrt(2 K)`
//! times each harmonic's amplitude rather than `K` times. The sum is
//! scaled so that its largest magnitude over a period is the asked peak.
//! Every period repeats to the bit: each tick's angle is found from the
//! tick's index modulo `P` in integers, never accumulated.

use crate::{ParamError, Real};
use core::f32::consts::{PI, TAU};

/// A periodic multisine of bounded peak (N, or whatever the caller plays).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Multisine {
    period_ticks: u32,
    first: u32,
    last: u32,
    /// Each harmonic's amplitude, so that the peak is as asked.
    amplitude: f32,
}

impl Multisine {
    /// Harmonics `first..=last` of a period of `period_ticks` ticks (so
    /// the band is `first/(P T)` to `last/(P T)` Hz), peaking at `peak`.
    /// Refused: a period under 4 ticks, a band empty or past Nyquist
    /// (`last < P/2`), a peak not finite and positive.
    pub fn new(period_ticks: u32, first: u32, last: u32, peak: f32) -> Result<Self, ParamError> {
        if !(peak.is_finite() && peak > 0.0) {
            return Err(ParamError {
                name: "multisine peak",
                value: peak,
                problem: "must be finite and > 0",
            });
        }
        let unit = Multisine::with_amplitude(period_ticks, first, last, 1.0)?;
        // (A scan of the whole period: `period × harmonics` terms, which a
        // host does, not a board's link handler.)
        let mut most = 0.0f32;
        for n in 0..period_ticks {
            most = most.max(unit.at(n).abs());
        }
        Ok(Multisine {
            amplitude: peak / most,
            ..unit
        })
    }

    /// Harmonics `first..=last` of a period of `period_ticks` ticks, each
    /// of amplitude `amplitude` (its peak then follows from the phases:
    /// [`new`](Self::new) finds the amplitude for a peak). Refused as in
    /// `new`, and an amplitude not finite and positive.
    pub fn with_amplitude(
        period_ticks: u32,
        first: u32,
        last: u32,
        amplitude: f32,
    ) -> Result<Self, ParamError> {
        if period_ticks < 4 {
            return Err(ParamError {
                name: "multisine period (ticks)",
                value: period_ticks as f32,
                problem: "must be at least 4",
            });
        }
        if first == 0 || last < first || 2 * last >= period_ticks {
            return Err(ParamError {
                name: "multisine harmonics",
                value: last as f32,
                problem: "must satisfy 1 <= first <= last < period/2",
            });
        }
        if !(amplitude.is_finite() && amplitude > 0.0) {
            return Err(ParamError {
                name: "multisine amplitude",
                value: amplitude,
                problem: "must be finite and > 0",
            });
        }
        Ok(Multisine {
            period_ticks,
            first,
            last,
            amplitude,
        })
    }

    /// Its root mean square over a period: `A √(K/2)` for `K` harmonics.
    /// No peak is below it.
    pub fn rms(&self) -> f32 {
        let k = (self.last - self.first + 1) as f32;
        self.amplitude * Real::sqrt(k / 2.0)
    }

    /// The period (ticks).
    pub fn period_ticks(&self) -> u32 {
        self.period_ticks
    }

    /// The harmonics played, `first..=last`.
    pub fn harmonics(&self) -> core::ops::RangeInclusive<u32> {
        self.first..=self.last
    }

    /// Each harmonic's amplitude.
    pub fn amplitude(&self) -> f32 {
        self.amplitude
    }

    /// Harmonic `h`'s phase (rad), Schroeder's.
    pub fn phase_rad(&self, h: u32) -> f32 {
        let i = (h - self.first + 1) as f32;
        let k = (self.last - self.first + 1) as f32;
        -PI * i * (i - 1.0) / k
    }

    /// The value at tick `tick`: `Σ A cos(2π h n/P + φ_h)`.
    pub fn at(&self, tick: u32) -> f32 {
        let p = self.period_ticks as u64;
        let n = tick as u64 % p;
        let mut sum = 0.0f32;
        for h in self.first..=self.last {
            // (h n mod P in integers: the angle never loses the period.)
            let m = (h as u64 * n % p) as f32;
            let angle = TAU * m / self.period_ticks as f32 + self.phase_rad(h);
            sum += Real::sin_cos(angle).1;
        }
        self.amplitude * sum
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    extern crate std;
    use std::vec::Vec;

    /// Its spectrum over a period is the harmonics asked, each of the
    /// amplitude and phase it reports, and nothing else (to f32's
    /// rounding); its peak is as asked; every period is the first, bit
    /// for bit.
    #[test]
    fn the_spectrum_is_the_band_and_the_peak_is_bounded() {
        let m = Multisine::new(1000, 3, 120, 2.5).unwrap();
        let x: Vec<f64> = (0..1000).map(|n| m.at(n) as f64).collect();
        let peak = x.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        assert!((peak - 2.5).abs() < 1e-5, "{peak}");
        for h in 0..500u32 {
            let (mut re, mut im) = (0.0, 0.0);
            for (n, v) in x.iter().enumerate() {
                let a = std::f64::consts::TAU * (h as f64) * n as f64 / 1000.0;
                re += v * a.cos();
                im -= v * a.sin();
            }
            let (mag, ph) = (2.0 * (re * re + im * im).sqrt() / 1000.0, im.atan2(re));
            if m.harmonics().contains(&h) {
                assert!((mag - m.amplitude() as f64).abs() < 1e-4, "h {h}: {mag}");
                let d = (ph - m.phase_rad(h) as f64).rem_euclid(std::f64::consts::TAU);
                assert!(d.min(std::f64::consts::TAU - d) < 1e-3, "h {h}: {ph}");
            } else {
                assert!(mag < 1e-4, "h {h} is not played: {mag}");
            }
        }
        for n in [0u32, 17, 999] {
            assert_eq!(m.at(n).to_bits(), m.at(n + 7 * 1000).to_bits());
        }
        // Schroeder's phases keep the crest factor (peak over rms, the rms
        // `A sqrt(K/2)`) low: K = 118 in-phase cosines would give 15.
        let crest = 2.5 / (m.amplitude() * (118.0f32 / 2.0).sqrt());
        assert!(crest < 2.0, "{crest}");
    }

    #[test]
    fn bad_settings_are_refused_by_name() {
        assert!(Multisine::new(3, 1, 1, 1.0).is_err());
        assert!(Multisine::new(100, 0, 10, 1.0).is_err());
        assert!(Multisine::new(100, 10, 50, 1.0).is_err());
        let e = Multisine::new(100, 1, 10, f32::NAN).unwrap_err();
        assert_eq!(e.name, "multisine peak");
    }

    /// A multisine made from its amplitude is the one made from its peak,
    /// bit for bit; its rms is the period's, and below its peak.
    #[test]
    fn the_amplitude_makes_the_same_multisine_and_its_rms_is_the_periods() {
        let m = Multisine::new(400, 2, 90, 7.0).unwrap();
        let a = Multisine::with_amplitude(400, 2, 90, m.amplitude()).unwrap();
        assert_eq!(a, m);
        let ms = (0..400).map(|n| (m.at(n) as f64).powi(2)).sum::<f64>() / 400.0;
        assert!(
            (ms.sqrt() - m.rms() as f64).abs() < 1e-4 * ms.sqrt(),
            "{ms}"
        );
        assert!(m.rms() < 7.0);
        for bad in [0.0, -1.0, f32::NAN, f32::INFINITY] {
            assert!(Multisine::with_amplitude(400, 2, 90, bad).is_err());
        }
    }
}
