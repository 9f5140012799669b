//! The device as one body at its lowest harmonics: its mass and damping,
//! a spring to the frame where the record shows one, and the band in
//! which it moves as one body.

use super::features::rigid_band_hz;
use super::MODEL_FLOOR;
use crate::frf::Frf;
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64;
use std::f64::consts::TAU;

/// Total mass (kg) and damping (N s/m) from the lowest harmonics, where
/// the device moves as one body: `1/H ≈ -m ω² + j ω d` once the hold's
/// half-tick delay is taken out.
pub(super) fn rigid_estimate(data: &Frf, period_s: f64) -> Option<(f64, f64)> {
    let take = data.freq_hz.len().clamp(1, 5);
    let (mut mm, mut dd) = (0.0, 0.0);
    for i in 0..take {
        let w = TAU * data.freq_hz[i];
        let z = 1.0 / (data.response[i] * Complex64::from_polar(1.0, w * period_s / 2.0));
        mm += -z.re / (w * w);
        dd += z.im / w;
    }
    let (m, d) = (mm / take as f64, dd / take as f64);
    (m > 0.0).then_some((m, d.max(1e-3 * m)))
}

/// Stiffness to the frame (N/m), its standard deviation, mass (kg) and
/// damping (N s/m) from the harmonics below where the device moves as
/// one body: `Re 1/H ≈ k - m ω² + c ω⁴` once the hold's half-tick delay
/// is taken out (`c` the modes above bending the band), by least squares
/// weighted by each harmonic's deviation (with the model floor), and
/// `Im 1/H ≈ ω d`. `None` where those harmonics cannot tell a spring from
/// a mass (fewer than four).
fn grounded_estimate(data: &Frf, period_s: f64) -> Option<(f64, f64, f64, f64)> {
    let below = rigid_band_hz(data);
    let take = data
        .freq_hz
        .iter()
        .take_while(|f| **f <= below)
        .count()
        .max(5)
        .min(data.freq_hz.len());
    if take < 4 {
        return None;
    }
    let (mut a, mut y) = (DMatrix::zeros(take, 3), DVector::zeros(take));
    let mut dd = 0.0;
    for i in 0..take {
        let w = TAU * data.freq_hz[i];
        let h = data.response[i];
        let z = 1.0 / (h * Complex64::from_polar(1.0, w * period_s / 2.0));
        // The real part's deviation: |Z| times the relative deviation,
        // over √2.
        let rel = (data.variance[i] / h.norm_sqr().max(f64::MIN_POSITIVE)
            + MODEL_FLOOR * MODEL_FLOOR)
            .sqrt();
        let weight = std::f64::consts::SQRT_2 / (rel * z.norm()).max(f64::MIN_POSITIVE);
        a[(i, 0)] = weight;
        a[(i, 1)] = -w * w * weight;
        a[(i, 2)] = w.powi(4) * weight;
        y[i] = z.re * weight;
        dd += z.im / w;
    }
    let normal = a.transpose() * &a;
    let inverse = normal.try_inverse()?;
    let km = &inverse * (a.transpose() * y);
    let (k, m, d) = (km[0], km[1], dd / take as f64);
    let sigma_k = inverse[(0, 0)].max(0.0).sqrt();
    (k.is_finite() && m.is_finite() && m > 0.0).then_some((k, sigma_k, m, d.max(1e-3 * m)))
}

/// A spring to the frame the record shows (its stiffness, N/m; the mass,
/// kg, and damping, N s/m, beside it): the low harmonics' stiffness, if it
/// is five of its standard deviations above zero and at least half the
/// inertia at the lowest harmonic (the body's resonance on it at least
/// 0.7 of that harmonic). Friction and cogging left in a free body's
/// record read as a stiffness too, a few per cent to a third of that
/// inertia on the simulated devices (cogging is a spring over each of its
/// periods): a spring weaker than this is not told from them.
pub(crate) fn ground_shown(data: &Frf, period_s: f64) -> Option<(f64, f64, f64)> {
    let (k, sigma_k, m, d) = grounded_estimate(data, period_s)?;
    let w = TAU * data.freq_hz.first()?;
    (k > 5.0 * sigma_k && k > 0.5 * m * w * w).then_some((k, m, d))
}

/// Below where the device moves as one body (Hz): a quarter of the way to
/// its lowest resonance (see [`rigid_band_hz`]); for a device held to the
/// frame, the lowest of its chain's, the spring taken out, not the body's
/// own on the spring.
pub(crate) fn body_band_hz(x: &Frf, period_s: f64) -> f64 {
    match ground_shown(x, period_s) {
        Some((k, ..)) => rigid_band_hz(&Frf {
            response: x.response.iter().map(|h| 1.0 / (1.0 / h - k)).collect(),
            ..x.clone()
        }),
        None => rigid_band_hz(x),
    }
}
