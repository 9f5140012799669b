//! The frequency response of a periodic experiment, with its variance.
//!
//! For each whole period `p` (after the transient) the record's DFT at
//! harmonic `h` gives `F_p(h)` (the force) and `X_p(h)` (the position).
//! The estimate is the ratio of the averages, `H = X̄/F̄`: what repeats
//! from period to period is the excitation's response alone, so the
//! noise a position loop feeds back into the force averages out of both.
//! Its variance follows from the spread of the periods (first order in
//! the noise): `σ²_H = |H|² (σ²_X/|X̄|² + σ²_F/|F̄|² - 2 Re(σ_XF/(X̄ F̄*))) / P`.

use crate::IdentifyError;
use num_complex::Complex64;

/// A measured frequency response at the excited harmonics.
#[derive(Clone, Debug, PartialEq)]
pub struct Frf {
    /// Each harmonic's frequency (Hz).
    pub freq_hz: Vec<f64>,
    /// The response there, position over force (m/N).
    pub response: Vec<Complex64>,
    /// Its variance, `E|H - H_true|²` (m²/N²).
    pub variance: Vec<f64>,
    /// Whole periods averaged.
    pub periods: usize,
}

impl Frf {
    /// The coherence each harmonic's estimate implies: the share of one
    /// period's response the excitation explains, `γ² = 1/(1 + P σ²/|H|²)`
    /// (1 where the periods agree exactly; 1/2 where a period's noise is
    /// as large as its response). Computed from the spread of the periods,
    /// so in closed loop it is the excitation's, not the feedback's.
    pub fn coherence(&self) -> Vec<f64> {
        self.response
            .iter()
            .zip(&self.variance)
            .map(|(h, v)| {
                let snr = h.norm_sqr() / (self.periods as f64 * v);
                if snr.is_finite() {
                    snr / (1.0 + snr)
                } else {
                    1.0
                }
            })
            .collect()
    }
}

/// Each whole period's DFT, `Σ x_n e^{-j 2π h n/N}`, at each of
/// `harmonics`: `[period][harmonic]`, for the `periods` periods after the
/// first `skip`. One FFT a period (rustfft, any length): a 30 s record at
/// 1 kHz with 450 harmonics is then milliseconds, where a DFT a harmonic
/// was seconds.
pub(crate) fn spectra(
    x: &[f64],
    period: usize,
    harmonics: &[usize],
    skip: usize,
    periods: usize,
) -> Vec<Vec<Complex64>> {
    let fft = rustfft::FftPlanner::new().plan_fft_forward(period);
    let mut buf = vec![Complex64::new(0.0, 0.0); period];
    (skip..skip + periods)
        .map(|k| {
            for (b, v) in buf.iter_mut().zip(&x[k * period..(k + 1) * period]) {
                *b = Complex64::new(*v, 0.0);
            }
            fft.process(&mut buf);
            harmonics.iter().map(|&h| buf[h]).collect()
        })
        .collect()
}

/// The average over the whole periods after the first `skip` of
/// `signal`'s DFT at each of `harmonics` of a period of `period` samples
/// (none where there is no such period).
pub fn mean_spectrum(
    signal: &[f64],
    period: usize,
    harmonics: &[usize],
    skip: usize,
) -> Vec<Complex64> {
    let periods = (signal.len() / period.max(1)).saturating_sub(skip);
    if periods == 0 || harmonics.iter().any(|h| *h >= period) {
        return vec![Complex64::new(0.0, 0.0); harmonics.len()];
    }
    mean_of(&spectra(signal, period, harmonics, skip, periods))
}

/// The average over the periods of [`spectra`]' `[period][harmonic]`.
pub(crate) fn mean_of(spectra: &[Vec<Complex64>]) -> Vec<Complex64> {
    let harmonics = spectra.first().map_or(0, Vec::len);
    (0..harmonics)
        .map(|i| spectra.iter().map(|p| p[i]).sum::<Complex64>() / spectra.len() as f64)
        .collect()
}

/// The whole periods after the first `skip` that a record of `force_n`
/// and `position_m` gives at `harmonics` of a period of `period`
/// samples, or why it gives none: signals of different lengths, a sample
/// that is not a number, a harmonic at 0 or past Nyquist, fewer than two
/// periods.
pub(crate) fn whole_periods(
    force_n: &[f64],
    position_m: &[f64],
    period: usize,
    harmonics: &[usize],
    skip: usize,
) -> Result<usize, IdentifyError> {
    if position_m.len() != force_n.len() {
        return Err(IdentifyError::Length {
            what: "position",
            len: position_m.len(),
            force: force_n.len(),
        });
    }
    for (what, x) in [("force", force_n), ("position", position_m)] {
        if let Some((at, v)) = x.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(IdentifyError::NotFinite {
                what,
                at,
                value: *v,
            });
        }
    }
    let max = period.saturating_sub(1) / 2;
    if let Some(&h) = harmonics.iter().find(|&&h| h == 0 || h > max) {
        return Err(IdentifyError::Harmonic {
            harmonic: h,
            period,
            max,
        });
    }
    let periods = (force_n.len() / period.max(1)).saturating_sub(skip);
    if periods < 2 {
        return Err(IdentifyError::TooShort {
            periods,
            skipped: skip,
            period,
        });
    }
    Ok(periods)
}

/// The ratio of the means of `x` and `f`, one value a period (or a
/// block), and its variance from their spread; `None` where the force's
/// mean is not above what its spread allows (the excitation does not
/// reach it).
pub(crate) fn ratio(f: &[Complex64], x: &[Complex64]) -> Option<(Complex64, f64)> {
    let p = f.len() as f64;
    let fm: Complex64 = f.iter().sum::<Complex64>() / p;
    let xm: Complex64 = x.iter().sum::<Complex64>() / p;
    // The force's harmonic against what the periods' spread allows.
    let var_f = f.iter().map(|v| (v - fm).norm_sqr()).sum::<f64>() / (p - 1.0);
    if fm.norm() <= 1e-12 || fm.norm_sqr() <= var_f / p {
        return None;
    }
    let var_x = x.iter().map(|v| (v - xm).norm_sqr()).sum::<f64>() / (p - 1.0);
    let cov: Complex64 = f
        .iter()
        .zip(x)
        .map(|(f, x)| (x - xm) * (f - fm).conj())
        .sum::<Complex64>()
        / (p - 1.0);
    let hh = xm / fm;
    let rel = var_x / xm.norm_sqr().max(f64::MIN_POSITIVE) + var_f / fm.norm_sqr()
        - 2.0 * (cov / (xm * fm.conj())).re;
    Some((hh, hh.norm_sqr() * rel.max(0.0) / p))
}

/// The response from `force_n` to `position_m`, sampled every `period_s`,
/// at `harmonics` of a period of `period` samples, over the whole periods
/// after the first `skip`.
pub fn periodic(
    force_n: &[f64],
    position_m: &[f64],
    period_s: f64,
    period: usize,
    harmonics: &[usize],
    skip: usize,
) -> Result<Frf, IdentifyError> {
    let periods = whole_periods(force_n, position_m, period, harmonics, skip)?;
    let hz = |h: usize| h as f64 / (period as f64 * period_s);
    let mut out = Frf {
        freq_hz: Vec::with_capacity(harmonics.len()),
        response: Vec::with_capacity(harmonics.len()),
        variance: Vec::with_capacity(harmonics.len()),
        periods,
    };
    let p = periods as f64;
    let (fs, xs) = (
        spectra(force_n, period, harmonics, skip, periods),
        spectra(position_m, period, harmonics, skip, periods),
    );
    for (i, &h) in harmonics.iter().enumerate() {
        let f: Vec<Complex64> = fs.iter().map(|s| s[i]).collect();
        let x: Vec<Complex64> = xs.iter().map(|s| s[i]).collect();
        let Some((hh, variance)) = ratio(&f, &x) else {
            let fm = f.iter().sum::<Complex64>() / p;
            return Err(IdentifyError::NoExcitation {
                harmonic: h,
                hz: hz(h),
                force: 2.0 * fm.norm() / period as f64,
            });
        };
        out.freq_hz.push(hz(h));
        out.response.push(hh);
        out.variance.push(variance);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix2, Matrix3, Vector2};
    use std::f64::consts::TAU;
    use twoport_control::multisine::Multisine;

    /// A mass-damper (kg, N s/m) under the hold, sampled every `t`: its
    /// exact discrete state matrices (position, velocity).
    fn zoh(m: f64, b: f64, t: f64) -> (Matrix2<f64>, Vector2<f64>) {
        let a = Matrix3::new(0.0, 1.0, 0.0, 0.0, -b / m, 1.0 / m, 0.0, 0.0, 0.0) * t;
        let e = a.exp();
        (
            Matrix2::new(e[(0, 0)], e[(0, 1)], e[(1, 0)], e[(1, 1)]),
            Vector2::new(e[(0, 2)], e[(1, 2)]),
        )
    }

    fn rng(seed: &mut u64) -> f64 {
        *seed ^= *seed << 13;
        *seed ^= *seed >> 7;
        *seed ^= *seed << 17;
        (*seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    }

    /// In closed loop (a weak PD loop keeps the device centred and feeds
    /// the encoder's 1 µm quantum and its noise back into the force, plus
    /// force noise at the actuator), the estimate from the commanded force
    /// to the encoder matches the device's exact sampled response,
    /// `C (zI - A_d)^-1 B_d`, within four standard deviations it reports
    /// itself, at every excited harmonic from 0.5 to 100 Hz; and its
    /// reported uncertainty is small where the excitation is strong.
    #[test]
    fn closed_loop_estimate_matches_the_sampled_device() {
        let (m, b, t) = (0.5, 3.0, 1e-3);
        let (ad, bd) = zoh(m, b, t);
        let ms = Multisine::new(2000, 1, 200, 4.0).unwrap();
        let (kp, kd) = (200.0, 2.0);
        let ticks = 2000 * 17;
        let (mut x, mut y_prev): (Vector2<f64>, f64) = (Vector2::zeros(), 0.0);
        let mut seed = 0x1234_5678_u64;
        let (mut force, mut pos) = (Vec::new(), Vec::new());
        for n in 0..ticks {
            let y = ((x[0] + 2e-6 * rng(&mut seed)) / 1e-6).round() * 1e-6;
            let u = ms.at(n) as f64 - kp * y - kd * (y - y_prev) / t;
            y_prev = y;
            force.push(u);
            pos.push(y);
            x = ad * x + bd * (u + 0.05 * rng(&mut seed));
        }
        let harmonics: Vec<usize> = ms.harmonics().map(|h| h as usize).collect();
        let f = periodic(&force, &pos, t, 2000, &harmonics, 1).unwrap();
        assert_eq!(f.periods, 16);
        for (i, &h) in harmonics.iter().enumerate() {
            let z = Complex64::from_polar(1.0, TAU * h as f64 / 2000.0);
            let g = {
                // C (zI - A)^-1 B for the 2 x 2 system.
                let (a11, a12, a21, a22) = (ad[(0, 0)], ad[(0, 1)], ad[(1, 0)], ad[(1, 1)]);
                let det = (z - a11) * (z - a22) - a12 * a21;
                ((z - a22) * bd[0] + a12 * bd[1]) / det
            };
            let err = (f.response[i] - g).norm();
            let sd = f.variance[i].sqrt();
            assert!(
                err <= 4.0 * sd + 1e-6 * g.norm(),
                "h {h}: {err:e} against σ {sd:e}, |G| {:e}",
                g.norm()
            );
            assert!(sd < 0.02 * g.norm(), "h {h}: σ {sd:e}, |G| {:e}", g.norm());
        }
    }

    /// Where each period's noise at a harmonic is as large as the
    /// response there, the coherence is a half; with no noise, one.
    #[test]
    fn coherence_is_the_share_the_excitation_explains() {
        let (n, periods, harmonics) = (200, 60, 40);
        let force: Vec<f64> = (0..n * periods)
            .map(|i| {
                (1..=harmonics)
                    .map(|h| (TAU * h as f64 * (i % n) as f64 / n as f64 + h as f64).cos())
                    .sum()
            })
            .collect();
        // A harmonic of amplitude 1 has a DFT of n/2; white noise of
        // variance s² has n s² there: equal when s² = n/4.
        let s = (n as f64 / 4.0).sqrt() * 12f64.sqrt();
        let mut seed = 0x5eed_u64;
        let noisy: Vec<f64> = force.iter().map(|f| f + s * rng(&mut seed)).collect();
        let hs: Vec<usize> = (1..=harmonics).collect();
        let clean = periodic(&force, &force, 1e-3, n, &hs, 0).unwrap();
        assert!(clean.coherence().iter().all(|c| *c > 1.0 - 1e-9));
        let c = periodic(&force, &noisy, 1e-3, n, &hs, 0)
            .unwrap()
            .coherence();
        let mean = c.iter().sum::<f64>() / c.len() as f64;
        assert!((mean - 0.5).abs() < 0.06, "{mean}: {c:?}");
    }

    #[test]
    fn bad_records_are_refused_with_the_reason() {
        let x = vec![0.0; 5000];
        let e = periodic(&x, &x[..10], 1e-3, 1000, &[3], 0).unwrap_err();
        assert!(e.to_string().contains("position: 10 samples"), "{e}");
        let e = periodic(&x, &x, 1e-3, 1000, &[3], 4).unwrap_err();
        assert!(e.to_string().contains("1 whole periods"), "{e}");
        let mut nan = x.clone();
        nan[77] = f64::NAN;
        let e = periodic(&nan, &x, 1e-3, 1000, &[3], 0).unwrap_err();
        assert!(e.to_string().contains("force[77]"), "{e}");
        let e = periodic(&x, &x, 1e-3, 1000, &[500], 0).unwrap_err();
        assert!(e.to_string().contains("between 1 and 499"), "{e}");
        let e = periodic(&x, &x, 1e-3, 1000, &[3], 0).unwrap_err();
        assert!(e.to_string().contains("no component"), "{e}");
    }
}
