//! The largest stiffness or smallest mass the sound bound allows, at one
//! damping or at the best one, on one pose or every pose.

use super::{admittance_coupling_tf, dc_series, impedance_coupling_tf, slack, Analysis};
use core::ops::RangeInclusive;

/// Largest `x` in `[lo, hi]` with `ok(x)`, assuming `ok` holds below a
/// threshold and fails above it; `None` if `ok(lo)` fails. Log bisection to
/// 1e-6 relative.
fn largest(lo: f64, hi: f64, ok: impl Fn(f64) -> bool) -> Option<f64> {
    if !ok(lo) {
        return None;
    }
    if ok(hi) {
        return Some(hi);
    }
    let (mut a, mut b) = (lo.ln(), hi.ln());
    while b - a > 1e-6 {
        let m = 0.5 * (a + b);
        if ok(m.exp()) {
            a = m;
        } else {
            b = m;
        }
    }
    Some(a.exp())
}

/// Search range for the coupling stiffness (N/m).
pub const K_RANGE: RangeInclusive<f64> = 1.0..=1.0e8;
/// Search range for the coupling mass (kg).
pub const M_RANGE: RangeInclusive<f64> = 1.0e-3..=1.0e4;
/// Search range for coupling damping in the best-pair search (N s/m).
pub const B_RANGE: RangeInclusive<f64> = 1.0..=1.0e4;

/// Where a design is impossible at any gain because of the limit toward
/// DC: every coupling's real part vanishes as `ω -> 0`, so a bound whose
/// limit there is clearly positive (above a hundredth of the bound at the
/// grid's lowest frequencies, so not the rounding of a bound that vanishes
/// as `ω²`) cannot be met by any finite stiffness or mass. Returns that
/// limit (the bound's unit), or `None`.
pub fn low_frequency_obstacle(a: &Analysis, bound: &[f64]) -> Option<f64> {
    let (beta0, _) = dc_series(a, bound)?;
    let scale = bound[0].abs().max(bound[a.dc_pair?].abs());
    (beta0.is_finite() && beta0 > 0.01 * scale).then_some(beta0)
}

/// One design inequality per pose of the device: its analysis and bound.
/// A coupling is proven for a device with several poses when it meets
/// every pose's bound, so each limit below is the worst over the poses,
/// and a design over `n` poses costs `n` single-pose designs.
pub type Poses<'a> = [(&'a Analysis, &'a [f64])];

/// The greatest `k_cI` (N/m) that meets the impedance-display bound with
/// damping `b` (N s/m); `None` if even `k = 1 N/m` does not.
pub fn max_stiffness(a: &Analysis, bound: &[f64], b_nspm: f64) -> Option<f64> {
    max_stiffness_poses(&[(a, bound)], b_nspm)
}

/// [`max_stiffness`] over every pose: the least of their limits. Each pose
/// searches below the least limit so far, so a pose that allows it costs
/// one check.
pub fn max_stiffness_poses(poses: &Poses, b_nspm: f64) -> Option<f64> {
    let mut hi = *K_RANGE.end();
    for (a, bound) in poses {
        let t = a.period_s;
        hi = largest(*K_RANGE.start(), hi, |k| {
            impedance_coupling_tf(k, b_nspm, t)
                .map(|tf| slack(a, bound, |z| tf.eval(z).inv().re) >= 0.0)
                .unwrap_or(false)
        })?;
    }
    Some(hi)
}

/// The least `m_cA` (kg) that meets the admittance-display bound with
/// damping `b` (N s/m); `None` if no mass up to 10^4 kg does.
pub fn min_mass(a: &Analysis, bound: &[f64], b_nspm: f64) -> Option<f64> {
    min_mass_poses(&[(a, bound)], b_nspm)
}

/// [`min_mass`] over every pose: the greatest of their limits (each pose
/// searches above the greatest so far).
pub fn min_mass_poses(poses: &Poses, b_nspm: f64) -> Option<f64> {
    // Heavier is more stable: search 1/m for the largest feasible.
    let mut hi = 1.0 / M_RANGE.start();
    for (a, bound) in poses {
        let t = a.period_s;
        let ok = |m: f64| {
            admittance_coupling_tf(m, b_nspm, t)
                .map(|tf| slack(a, bound, |z| tf.eval(z).re) >= 0.0)
                .unwrap_or(false)
        };
        hi = largest(1.0 / M_RANGE.end(), hi, |inv| ok(1.0 / inv))?;
    }
    Some(1.0 / hi)
}

/// Maximise `score(b)` over `B_RANGE` on a log scan refined by golden
/// section; returns `(b, score)` or `None` if nowhere feasible.
fn best_over_b(score: impl Fn(f64) -> Option<f64>) -> Option<(f64, f64)> {
    let n = 33;
    let (lo, hi) = (B_RANGE.start().ln(), B_RANGE.end().ln());
    let at = |i: usize| lo + (hi - lo) * i as f64 / (n - 1) as f64;
    let (mut best_i, mut best) = (None, f64::NEG_INFINITY);
    for i in 0..n {
        if let Some(s) = score(at(i).exp()) {
            if s > best {
                (best_i, best) = (Some(i), s);
            }
        }
    }
    let i = best_i?;
    let (mut a, mut c) = (at(i.saturating_sub(1)), at((i + 1).min(n - 1)));
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let f = |x: f64| score(x.exp()).unwrap_or(f64::NEG_INFINITY);
    let (mut x1, mut x2) = (c - g * (c - a), a + g * (c - a));
    let (mut f1, mut f2) = (f(x1), f(x2));
    while c - a > 1e-4 {
        if f1 >= f2 {
            c = x2;
            (x2, f2) = (x1, f1);
            x1 = c - g * (c - a);
            f1 = f(x1);
        } else {
            a = x1;
            (x1, f1) = (x2, f2);
            x2 = a + g * (c - a);
            f2 = f(x2);
        }
    }
    let b = (0.5 * (a + c)).exp();
    score(b).map(|s| (b, s)).or(Some((at(i).exp(), best)))
}

/// The best impedance coupling: the `(k_cI, b_cI)` with the greatest
/// stiffness that meets the bound. No coupling damping at all is a
/// candidate too: on a lightly damped device any `b_cI` costs stiffness
/// (Colgate's `b > K T/2 + B`).
pub fn best_impedance(a: &Analysis, bound: &[f64]) -> Option<(f64, f64)> {
    best_impedance_poses(&[(a, bound)])
}

/// [`best_impedance`] over every pose.
pub fn best_impedance_poses(poses: &Poses) -> Option<(f64, f64)> {
    let scanned = best_over_b(|b| max_stiffness_poses(poses, b)).map(|(b, k)| (k, b));
    let undamped = max_stiffness_poses(poses, 0.0).map(|k| (k, 0.0));
    match (scanned, undamped) {
        (Some(s), Some(u)) if u.0 > s.0 => Some(u),
        (s, u) => s.or(u),
    }
}

/// The best admittance coupling: the `(m_cA, b_cA)` with the least mass
/// that meets the bound.
pub fn best_admittance(a: &Analysis, bound: &[f64]) -> Option<(f64, f64)> {
    best_admittance_poses(&[(a, bound)])
}

/// [`best_admittance`] over every pose.
pub fn best_admittance_poses(poses: &Poses) -> Option<(f64, f64)> {
    best_over_b(|b| min_mass_poses(poses, b).map(|m| -m)).map(|(b, m)| (-m, b))
}
