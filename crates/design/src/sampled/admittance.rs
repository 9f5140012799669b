//! The admittance display's sampled-data bound on `Re Z_cA`.
//!
//! The hand enters both signals the board reads: the encoder through
//! `X_h = X_aa^d - α_0 w_0 - Σ α_k w_k` and the load cell through
//! `F_h = F_ma^d - φ_0 w_0 - Σ φ_k w_k` (`k != 0` the aliases, each `w_k` in
//! the disk through 0 of diameter `1/R_k`), and the VE port sees
//! `G = K I F_h / (1 + K X_h)`. Two sufficient bounds on `-min Re G` are
//! computed, and the smaller is used:
//!
//! * **the perturbation bound**: the paper's exact base-band minimum plus a
//!   bound on how far the aliases can move a ratio;
//! * **the Möbius bound**: the aliases' share of the encoder folded into the
//!   base-band hand, which leaves `G = (I/α_0) (φ_0 + (R - η)/(w_p - w))`
//!   with `w` in a disk, `w_p` the regulated device's pole and
//!   `η = Σ (φ_k - φ_0 α_k/α_0) w_k` in a disk; the minimum over `w` is the
//!   disk's Möbius image, exact, and only `η`'s radius is bounded.
//!
//! The second is what keeps the bound finite toward DC without a human
//! bound, where the base-band hand can bring the regulated device to the
//! edge of resonance (`w` near `w_p`) and the first grows as `1/ω²`.

use super::{alias_count, each_alias_pair, tail_sum, AliasCache, Flow, TAIL_SHARE};
use crate::network::{admittance_display, design_bound, HumanBound};
use crate::{Plant, PlantPoint};
use num_complex::Complex64;
use twoport_control::ZTransfer;

/// The admittance-display bound on `Re Z_cA` at each point for the
/// regulator `kp`, sufficient for the sampled loop (see the module docs).
/// It is never below the paper's.
pub fn admittance_bound(
    plant: &Plant,
    points: &[PlantPoint],
    kp: &ZTransfer,
    human: Option<HumanBound>,
) -> Vec<f64> {
    admittance_bound_with(plant, points, kp, human, &AliasCache::default())
}

/// [`admittance_bound`], the device's alias terms kept in `cache` (made
/// for `points`).
pub fn admittance_bound_with(
    plant: &Plant,
    points: &[PlantPoint],
    kp: &ZTransfer,
    human: Option<HumanBound>,
    cache: &AliasCache,
) -> Vec<f64> {
    crate::par::map(points.len(), |i| {
        let p = &points[i];
        let (Some(base), Some(reach)) =
            (Base::at(p, human), alias_reach(plant, (i, p), human, cache))
        else {
            return f64::INFINITY;
        };
        let (paper, bound) = perturbation_bound(p, &reach, kp, human, base);
        // Where the perturbation bound is within 1e-4 of the paper's, the
        // Möbius bound (never below the paper's) has next to nothing to
        // gain.
        if bound - paper <= 1e-4 * paper.abs().max(1.0) {
            return bound;
        }
        let disks = alias_disks(plant, (i, p), human, cache, (base, &reach));
        let k = kp.eval(p.z) * p.delay;
        bound.min(mobius_bound(p, &disks, k, base))
    })
}

/// The base band's hand terms, per unit `q = (1 - z^-1)/T`: `α_0 = q a_0`,
/// `φ_0 = q f_0`, and the hand disk's radius `1/(2 R_0)`.
#[derive(Clone, Copy, Debug)]
pub(super) struct Base {
    pub(super) a0: Complex64,
    pub(super) f0: Complex64,
    pub(super) r0: f64,
}

impl Base {
    /// `None` where the handle is lossless at `ω` (`R_0 <= 0`) or the
    /// actuator does not move the handle (`a_0 = 0`).
    pub(super) fn at(p: &PlantPoint, human: Option<HumanBound>) -> Option<Base> {
        let y0 = p.y[0][0] + human.map_or(Complex64::new(0.0, 0.0), |h| h.admittance(p.s));
        // (The held force, delayed by the latency, drives the handle.)
        let lag = p.latency();
        let a0 = -(p.y[1][0] * p.y[0][1]) / (p.omega * p.omega) * lag;
        (y0.re > 0.0 && a0.norm() > 0.0).then(|| Base {
            a0,
            f0: p.f[0] * p.y[0][1] / p.s * lag,
            r0: 0.5 / y0.re,
        })
    }
}

/// What the aliases `k != 0` can add, per unit `q`, with `a_k = P_k/(jω_k)²`
/// and `f_k = F_mh Y_ha/(jω_k)` and every `w_k` in its disk (centre and
/// radius `1/(2 R_k)`): `Σ |a_k|/R_k` and `Σ |f_k|/R_k`, the perturbation
/// bound's reach into the encoder and the load cell, with their tails.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Reach {
    x: f64,
    f: f64,
    tail_x: f64,
    tail_f: f64,
    /// How many alias pairs the sums took.
    pairs: usize,
}

/// The disks the Möbius bound needs, over the same aliases as a [`Reach`]
/// (tails included: a centre known to within a tail widens its disk by it).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Disks {
    /// `Σ a_k w_k`.
    pub(super) a_centre: Complex64,
    pub(super) a_radius: f64,
    /// `Σ (f_k - (f_0/a_0) a_k) w_k`.
    pub(super) b_centre: Complex64,
    pub(super) b_radius: f64,
}

/// The aliases' [`Reach`] at point `i`, `None` where unbounded.
pub(super) fn alias_reach(
    plant: &Plant,
    (i, p): (usize, &PlantPoint),
    human: Option<HumanBound>,
    cache: &AliasCache,
) -> Option<Reach> {
    let n_min = alias_count(plant);
    let t2 = p.period_s * p.period_s;
    let mut r = Reach::default();
    let bounded = each_alias_pair(plant, (i, p), human, cache, |pair, n| {
        let (mut ratio_x, mut ratio_f) = (0.0f64, 0.0f64);
        for a in pair {
            let w = a.omega.abs();
            let fy_abs = a.fy.norm_sqr().sqrt();
            r.x += a.p_abs / (w * w * a.re_yhh);
            r.f += fy_abs / (w * a.re_yhh);
            ratio_x = ratio_x.max(a.p_abs / a.re_yhh);
            ratio_f = ratio_f.max(fy_abs * w / a.re_yhh);
        }
        // Σ_{|k|>N} 1/ω_k² = T² Σ 1/(θ + 2πk)².
        (r.tail_x, r.tail_f) = (ratio_x * t2 * tail_sum(n), ratio_f * t2 * tail_sum(n));
        r.pairs = n;
        if n >= n_min && r.tail_x <= TAIL_SHARE * r.x && r.tail_f <= TAIL_SHARE * r.f {
            Flow::Stop
        } else {
            Flow::Go
        }
    });
    r.x += r.tail_x;
    r.f += r.tail_f;
    bounded.then_some(r)
}

/// The [`Disks`] over the aliases `reach` summed (their terms come from
/// `cache` where it holds them).
pub(super) fn alias_disks(
    plant: &Plant,
    (i, p): (usize, &PlantPoint),
    human: Option<HumanBound>,
    cache: &AliasCache,
    (base, reach): (Base, &Reach),
) -> Disks {
    let rho = base.f0 / base.a0;
    let mut d = Disks::default();
    let mut radius_a = 0.0;
    each_alias_pair(plant, (i, p), human, cache, |pair, n| {
        for a in pair {
            // a_k = P/(jω)² and f_k = F_mh Y_ha/(jω), without a division.
            let inv = 1.0 / a.omega;
            let lag = p.latency_at(a.omega);
            let ak = a.p * -(inv * inv) * lag;
            let fk = Complex64::new(a.fy.im * inv, -a.fy.re * inv) * lag;
            let bk = fk - rho * ak;
            let half = 0.5 / a.re_yhh;
            d.a_centre += ak * half;
            radius_a += a.p_abs * inv * inv * half;
            d.b_centre += bk * half;
            d.b_radius += bk.norm_sqr().sqrt() * half;
        }
        if n >= reach.pairs {
            Flow::Stop
        } else {
            Flow::Go
        }
    });
    d.a_radius = radius_a + reach.tail_x;
    d.b_radius += reach.tail_f + rho.norm() * reach.tail_x;
    d
}

/// The paper's exact base-band minimum, and it plus a bound on how far the
/// aliases move the ratio `G` (infinite where the aliased hand could
/// destabilise the regulated device).
fn perturbation_bound(
    p: &PlantPoint,
    reach: &Reach,
    kp: &ZTransfer,
    human: Option<HumanBound>,
    base: Base,
) -> (f64, f64) {
    let g = admittance_display(p, kp, human);
    let paper = design_bound(&g);
    let g_hh = g[0][0].re;
    if !paper.is_finite() || g_hh <= 0.0 {
        return (f64::INFINITY, f64::INFINITY);
    }
    let t = p.period_s;
    let one = Complex64::new(1.0, 0.0);
    let q = (one - p.z.inv()) / t;
    let k = kp.eval(p.z) * p.delay;
    let rho_d = (k * q).norm() * reach.x;
    // |K I q| ρ_F with I = T/(1 - z^-1): I q = 1.
    let c_rho_f = k.norm() * reach.f;
    // The base-band hand's reach into the regulator loop's denominator
    // D = 1 + K X_aa^d - K α_0 w_0, w_0 in the disk of diameter 1/R_0.
    let den = one + k * p.xaa_d;
    let ka = k * q * base.a0;
    let d_min = (den - ka * base.r0).norm() - ka.norm() * base.r0;
    if d_min <= rho_d {
        return (paper, f64::INFINITY);
    }
    let cross = -(g[0][1] * g[1][0]);
    let g_max = g[1][1].norm() + cross.norm() / g_hh;
    (paper, paper + (c_rho_f + g_max * rho_d) / (d_min - rho_d))
}

/// `-min Re G` from the Möbius form (see the module docs), infinite where
/// the hand's disk reaches the regulated device's pole.
fn mobius_bound(p: &PlantPoint, disks: &Disks, k: Complex64, base: Base) -> f64 {
    let one = Complex64::new(1.0, 0.0);
    let q = (one - p.z.inv()) / p.period_s;
    let (alpha0, phi0) = (q * base.a0, q * base.f0);
    // w = w_0 + Σ α_k w_k / α_0 lies in this disk.
    let w_centre = base.r0 + disks.a_centre / base.a0;
    let w_radius = base.r0 + disks.a_radius / base.a0.norm();
    let w_pole = (one + k * p.xaa_d) / (k * alpha0);
    let gap = w_pole - w_centre;
    let den = gap.norm_sqr() - w_radius * w_radius;
    if den.is_nan() || den <= 0.0 {
        return f64::INFINITY;
    }
    // u = 1/(w_p - w) lies in the disk (u_centre, u_radius).
    let u_centre = gap.conj() / den;
    let u_radius = w_radius / den;
    let c = one / (q * alpha0);
    let residue = p.fma_d - phi0 * w_pole;
    let eta_centre = q * disks.b_centre;
    let eta_radius = q.norm() * disks.b_radius;
    let a = c * (residue - eta_centre);
    let min_re = (c * phi0).re + min_on_disk(a, c.norm() * eta_radius, u_centre, u_radius);
    if min_re.is_nan() {
        f64::INFINITY
    } else {
        -min_re
    }
}

/// A lower bound on `min Re(a u) - ε |u|` over the disk `|u - centre| <=
/// radius`. Near the regulated pole the disk is huge and nearly tangent to
/// the line the linear term is smallest on, so `ε |u|` costs only about
/// `ε² radius / |a|` there, not `ε radius`: with `|u| <= (|u|² + λ²)/(2λ)`
/// for any `λ > 0` the rest is a concave quadratic whose minimum on the
/// circle is closed-form, and the best of a scan of `λ` is taken.
fn min_on_disk(a: Complex64, eps: f64, centre: Complex64, radius: f64) -> f64 {
    let linear = (a * centre).re - a.norm() * radius;
    let plain = linear - eps * (centre.norm() + radius);
    // (Where `ε |u|` costs next to nothing the scan cannot gain.)
    if linear - plain <= 1e-9 * linear.abs() {
        return plain;
    }
    // The scan starts at |u| where the linear term is smallest.
    let at = (centre - a.conj() / a.norm() * radius).norm().max(1e-300);
    let mut best = plain;
    for j in -24..=24 {
        let lambda = at * 2f64.powf(j as f64 / 2.0);
        let bound = (a * centre).re
            - eps / (2.0 * lambda) * (centre.norm_sqr() + radius * radius)
            - radius * (a - centre.conj() * (eps / lambda)).norm()
            - eps * lambda / 2.0;
        best = best.max(bound);
    }
    best
}

#[cfg(test)]
mod tests;
