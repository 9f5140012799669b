//! The handle port without the paper's approximation: design bounds that
//! hold for the exact sampled-data loop.
//!
//! The paper's hybrid two-port treats the handle port with continuous
//! transfer functions times the hold, which neglects aliasing: a hand force
//! at `ω + 2πk/T` also reaches the sampled actuator signals. Here the hand is
//! a passive impedance whose value at every alias frequency is free (a
//! superset of the real hands, so the bound stays sufficient), and the hand
//! enters the discrete loop through the exact alias sums. `docs/soundness.md`
//! has the derivation; in short, with `P = Y_ah Y_ha`, `θ = ωT`,
//! `ω_k = ω + 2πk/T` and `R_k = Re Y_hh(jω_k)` (the human bound folded in):
//!
//! * **impedance display**, exact for any passive hand and VE:
//!   `Re(1/Z_cI) >= -Re Y_cc* + Σ_k 4 sin²(θ/2) / (T ω_k)² (|P_k| + Re(e^{-jθ} P_k)) / (2 R_k)`.
//!   The `k = 0` term is the paper's; on a rigid device the sum is exactly
//!   Colgate's passivity bound `(1 - cos θ)/(2 b)`, i.e. `b > K T/2 + |B|`.
//! * **admittance display**, a sufficient condition: the paper's bound plus
//!   the worst change the aliased hand terms can make to `G_cc*` (a bound on
//!   the perturbation of a ratio), infinite where the aliased hand could
//!   destabilise the regulated device.
//!
//! Aliases are summed outward pair by pair until, past the device's highest
//! mode times 3, the rest is below 1e-4 of the sum: the rest is bounded by
//! the last alias's ratio and the exact tail
//! `Σ_{|k|>N} 1/(θ + 2πk)² <= 2/(4π² (N - 1/2))`, which assumes the ratios
//! grow no further beyond `N` (true above the device's modes, where the
//! handle's inertia dominates).

mod admittance;
mod forms;

pub use admittance::{admittance_bound, admittance_bound_with};
pub use forms::{hand_forms, Disk, HandForms};

use crate::network::{design_bound, impedance_display, HumanBound};
use crate::{Plant, PlantPoint};
use num_complex::Complex64;
use std::f64::consts::PI;
use std::sync::Mutex;

/// From how many aliases either side of the base band the sums may stop:
/// past three times the device's highest mode, where the tail bound's
/// assumption holds (at least 16).
pub fn alias_count(plant: &Plant) -> usize {
    let ws = 2.0 * PI / plant.period_s();
    let top = plant.modes().iter().map(|m| m.omega_n).fold(0.0, f64::max);
    ((3.0 * top / ws).ceil() as usize).clamp(16, MAX_ALIASES)
}

/// The most aliases either side a sum takes.
pub const MAX_ALIASES: usize = 4096;

/// A sum stops once its tail bound is below this share of what it bounds.
const TAIL_SHARE: f64 = 1e-4;

/// The device's hand-side terms at one alias frequency `ω_k` (rad/s, any
/// sign): `Y_hh` with the human bound, `P = Y_ah Y_ha`, and `F_mh Y_ha`.
struct Alias {
    omega: f64,
    re_yhh: f64,
    p: Complex64,
    /// `F_mh Y_ha`.
    fy: Complex64,
    /// `|P|`.
    p_abs: f64,
}

/// The device's own terms at one alias frequency, before any human:
/// `ω_k`, `Y_hh`, `P = Y_ah Y_ha` and `F_mh Y_ha`.
#[derive(Clone, Copy, Debug)]
struct Raw {
    omega: f64,
    yhh: Complex64,
    p: Complex64,
    fy: Complex64,
}

/// The device's terms at each grid point's aliases, evaluated once and
/// shared by every bound (both displays, any regulator, any human) that
/// sums them there: the device's continuous response at the aliases is
/// what the sampled-data bounds spend their time on. A sum that goes
/// further than the ones before extends its point's list.
#[derive(Debug, Default)]
pub struct AliasCache {
    /// Per point, the alias pairs `ω ± 2πn/T` for `n = 1, 2, ...`.
    points: Vec<Mutex<Vec<[Raw; 2]>>>,
}

impl AliasCache {
    /// An empty cache for `n` points.
    pub fn new(n: usize) -> Self {
        AliasCache {
            points: (0..n).map(|_| Mutex::new(Vec::new())).collect(),
        }
    }

    fn point(&self, i: usize) -> Option<std::sync::MutexGuard<'_, Vec<[Raw; 2]>>> {
        // (A poisoned lock still holds whole pairs: each is pushed at once.)
        self.points
            .get(i)
            .map(|m| m.lock().unwrap_or_else(|e| e.into_inner()))
    }
}

impl Clone for AliasCache {
    fn clone(&self) -> Self {
        AliasCache {
            points: (0..self.points.len())
                .map(|i| Mutex::new(self.point(i).map(|v| v.clone()).unwrap_or_default()))
                .collect(),
        }
    }
}

/// What a sum does after a pair of aliases.
enum Flow {
    Go,
    Stop,
}

/// Hand `f` the aliases `ω ± 2πn/T` of point `i` (`p`) pair by pair,
/// `n = 1, 2, ...`, until it stops, at most [`MAX_ALIASES`] pairs; false
/// where a term is unbounded (a lossless handle at an alias). The device's
/// terms come from `cache` where an earlier sum evaluated them.
fn each_alias_pair(
    plant: &Plant,
    (i, p): (usize, &PlantPoint),
    human: Option<HumanBound>,
    cache: &AliasCache,
    mut f: impl FnMut(&[Alias; 2], usize) -> Flow,
) -> bool {
    let mut work = plant.scratch();
    let ws = 2.0 * PI / p.period_s;
    let mut raw = |k: f64| {
        let omega = p.omega + ws * k;
        let mut h = plant.hand_terms(omega.abs(), &mut work);
        if omega < 0.0 {
            h = h.map(|v| v.conj());
        }
        let [yhh, yha, yah, fmh] = h;
        let p = yah * yha;
        let fy = fmh * yha;
        Raw { omega, yhh, p, fy }
    };
    let with_human = |r: Raw| {
        let h = human.map_or(Complex64::new(0.0, 0.0), |h| {
            h.admittance(Complex64::new(0.0, r.omega))
        });
        Alias {
            omega: r.omega,
            re_yhh: (r.yhh + h).re,
            p: r.p,
            fy: r.fy,
            // (A modulus without libm's hypot, its slowest part: these are
            // far from overflow, and a rounding's difference is 1e-16.)
            p_abs: r.p.norm_sqr().sqrt(),
        }
    };
    let mut own = Vec::new();
    let mut cached = cache.point(i);
    if let Some(c) = cached.as_deref_mut() {
        c.reserve(alias_count(plant).saturating_sub(c.len()));
    }
    let pairs = cached.as_deref_mut().unwrap_or(&mut own);
    for n in 1..=MAX_ALIASES {
        if pairs.len() < n {
            pairs.push([raw(n as f64), raw(-(n as f64))]);
        }
        let pair = pairs[n - 1].map(with_human);
        if pair.iter().any(|a| a.re_yhh.is_nan() || a.re_yhh <= 0.0) {
            return false;
        }
        if let Flow::Stop = f(&pair, n) {
            return true;
        }
    }
    true
}

/// `Σ_{|k|>N} 1/(θ + 2πk)²` is at most this (for `0 <= θ <= π`).
fn tail_sum(n: usize) -> f64 {
    2.0 / (4.0 * PI * PI * (n as f64 - 0.5))
}

/// The alias terms of the impedance display at one point: what the
/// aliased hand adds to the paper's bound `paper` on `Re(1/Z_cI)`.
fn impedance_alias_terms(
    plant: &Plant,
    (i, p): (usize, &PlantPoint),
    human: Option<HumanBound>,
    cache: &AliasCache,
    paper: f64,
) -> f64 {
    let n_min = alias_count(plant);
    let t = p.period_s;
    let th = p.omega * t;
    let s2 = 4.0 * (0.5 * th).sin().powi(2);
    // e^{-jθ} from the hold and the first difference, times the delay (and
    // the latency, at each alias's own frequency).
    let rot = Complex64::from_polar(1.0, -th) * p.delay;
    let (mut sum, mut tail) = (0.0, 0.0);
    let bounded = each_alias_pair(plant, (i, p), human, cache, |pair, n| {
        let mut ratio = 0.0f64;
        for a in pair {
            let wt = a.omega * t;
            let re = (rot * p.latency_at(a.omega) * a.p).re;
            sum += s2 / (wt * wt) * (a.p_abs + re) / (2.0 * a.re_yhh);
            ratio = ratio.max(a.p_abs / a.re_yhh);
        }
        tail = ratio * s2 * tail_sum(n);
        if n >= n_min && tail <= TAIL_SHARE * (paper.abs() + sum) {
            Flow::Stop
        } else {
            Flow::Go
        }
    });
    if bounded {
        sum + tail
    } else {
        f64::INFINITY
    }
}

/// The impedance-display bound on `Re(1/Z_cI)` at each point, exact for the
/// sampled loop (see the module docs). It is never below the paper's.
pub fn impedance_bound(
    plant: &Plant,
    points: &[PlantPoint],
    human: Option<HumanBound>,
) -> Vec<f64> {
    impedance_bound_with(plant, points, human, &AliasCache::default())
}

/// [`impedance_bound`], the device's alias terms kept in `cache` (made
/// for `points`).
pub fn impedance_bound_with(
    plant: &Plant,
    points: &[PlantPoint],
    human: Option<HumanBound>,
    cache: &AliasCache,
) -> Vec<f64> {
    crate::par::map(points.len(), |i| {
        let p = &points[i];
        let paper = design_bound(&impedance_display(p, human));
        paper + impedance_alias_terms(plant, (i, p), human, cache, paper)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rigid(m: f64, b: f64) -> Plant {
        Plant::new(&crate::model::rigid_for_tests(m, b), 1e-3).unwrap()
    }

    /// On a rigid device the exact bound is Colgate & Schenkel's passivity
    /// condition `(1 - cos θ)/(2 b)` for every mass, and never below it:
    /// the alias sums are what the paper's approximation leaves out.
    #[test]
    fn rigid_device_bound_is_colgates() {
        for (m, b) in [(1.0, 20.0), (0.1, 5.0), (10.0, 200.0)] {
            let plant = rigid(m, b);
            let omegas = crate::analysis::log_grid(1.0, plant.nyquist(), 60);
            let pts = plant.response(&omegas);
            let exact = impedance_bound(&plant, &pts, None);
            let paper: Vec<f64> = pts
                .iter()
                .map(|p| design_bound(&impedance_display(p, None)))
                .collect();
            for ((p, e), pa) in pts.iter().zip(&exact).zip(&paper) {
                let colgate = (1.0 - (p.omega * 1e-3).cos()) / (2.0 * b);
                assert!(
                    *e >= colgate * (1.0 - 1e-9),
                    "m {m} at {}: {e} < {colgate}",
                    p.omega
                );
                assert!(
                    *e <= colgate * 1.01,
                    "m {m} at {}: {e} vs {colgate}",
                    p.omega
                );
                assert!(pa <= e);
            }
            // At Nyquist the paper's approximation misses a good part of it.
            let last = pts.len() - 1;
            assert!(
                paper[last] < 0.8 * exact[last],
                "{} {}",
                paper[last],
                exact[last]
            );
        }
    }

    /// The tail bound's assumption, on every shipped device with and without
    /// the human bound: past [`alias_count`] the ratios `|P|/R` and
    /// `|F_mh Y_ha| ω/R` never exceed their value where the sums may stop.
    #[test]
    fn tail_ratios_do_not_grow_past_the_alias_count() {
        for model in crate::model::shipped_for_tests() {
            let plant = Plant::new(&model, 1e-3).unwrap();
            let ws = 2.0 * PI / plant.period_s();
            let start = (alias_count(&plant) as f64 - 0.5) * ws;
            let mut work = plant.scratch();
            for human in [Some(HumanBound::PAPER), None] {
                let mut ratios = |w: f64| {
                    let (y, f) = plant.continuous(w, &mut work);
                    let h = human.map_or(Complex64::new(0.0, 0.0), |h| {
                        h.admittance(Complex64::new(0.0, w))
                    });
                    let r = (y[0][0] + h).re;
                    let p = (y[1][0] * y[0][1]).norm();
                    (p / r, (f[0] * y[0][1]).norm() * w / r)
                };
                let (x0, f0) = ratios(start);
                for i in 1..400 {
                    let w = start * 100f64.powf(i as f64 / 399.0);
                    let (x, f) = ratios(w);
                    assert!(
                        x <= x0 * (1.0 + 1e-6),
                        "{}: |P|/R at {w}: {x} > {x0}",
                        model.name
                    );
                    // (The load cell's only matters with one.)
                    assert!(
                        !model.force_sensor || f <= f0 * (1.0 + 1e-6),
                        "{}: F ratio at {w}: {f} > {f0}",
                        model.name
                    );
                }
            }
        }
    }
}
