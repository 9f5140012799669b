//! The proof at a linkage's pose for hands bounded above by the paper's
//! `Z_max` (the grasp can be no stiffer than `Z_max` in any direction).
//!
//! For a unit vector `x` the hand's effect at alias `k`,
//! `ζ_k = x^*(Z_k + Z_h)^-1 x` with `Z_k = jω_k M_x + D_x`, is
//! `t / (jω_k m + d + h)`: with `u = (Z_k + Z_h)^-1 x`, `conj(ζ_k)` is
//! `u^* (Z_k + Z_h) u`, so `m` and `d` are Rayleigh quotients of `M_x` and
//! `D_x` (between their extreme eigenvalues), `h` one of the hand's
//! impedance, and `t = |u|² |s|² ≤ 1` since `|ζ_k| ≤ |u|`. A hand bounded by
//! `Z_max` has the admittance `I/Z_max + Y_p` with `Y_p` passive, and every
//! Rayleigh quotient `h` of its impedance then has
//! `Re(1/h) ≥ Re(1/Z_max(jω_k)) = g_k`: `h` lies in the disk through 0 of
//! diameter `1/g_k`. Letting `t`, `m`, `d` and `h` range independently,
//! and every alias independently, is a superset of the real hands, so the
//! bound it gives is sound. Each alias's least `Re(e^{-jθ} ζ_k)` is
//! `min(0, min Re(e^{-jθ}/s))` over a rounded rectangle of `s`, where the
//! harmonic `Re(e^{-jθ}/s)` takes its least value on the boundary: four
//! segments and four quarter circles, each minimised in closed form.

use crate::network::HumanBound;
use num_complex::Complex64;
use std::f64::consts::PI;

/// What the proof needs of a pose: the extreme eigenvalues of the handle's
/// mass (kg) and damping (N s/m, the least grasp's included).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PoseRanges {
    /// `(λ_min, λ_max)` of `M_x` (kg).
    pub mass_kg: (f64, f64),
    /// `(λ_min, λ_max)` of `D_x` plus the least grasp (N s/m).
    pub damping_nspm: (f64, f64),
}

/// Aliases summed term by term on each side; the rest is bounded.
const ALIASES: i32 = 60;

/// The frequencies (rad per sample, `θ = ωT`) the bound is checked at: a
/// log grid from 0.05 Hz's to Nyquist, Nyquist on it exactly.
pub fn theta_grid(period_s: f64, points: usize) -> Vec<f64> {
    let lo = 2.0 * PI * 0.05 * period_s;
    let n = points.max(2);
    (0..n)
        .map(|i| {
            if i + 1 == n {
                PI
            } else {
                lo * (PI / lo).powf(i as f64 / (n - 1) as f64)
            }
        })
        .collect()
}

/// `Re(c/s)`.
fn re_over(c: Complex64, s: Complex64) -> f64 {
    (c / s).re
}

/// The least `Re(c/s)` on the segment from `p` to `q`: its ends, and where
/// the derivative of `Re(c/(p + τ e))` vanishes, `Re(c e conj(s)²) = 0`,
/// a quadratic in `τ`.
fn segment_min(c: Complex64, p: Complex64, q: Complex64) -> f64 {
    let mut best = re_over(c, p).min(re_over(c, q));
    let len = (q - p).norm();
    if len == 0.0 {
        return best;
    }
    let e = (q - p) / len;
    let a = (c * e.conj()).re;
    let b = 2.0 * (c * p.conj()).re;
    let k = (c * e * p.conj() * p.conj()).re;
    let mut roots = [f64::NAN; 2];
    if a.abs() > 1e-300 {
        let disc = b * b - 4.0 * a * k;
        if disc >= 0.0 {
            let r = disc.sqrt();
            // (The stable form: no cancellation between `-b` and `r`.)
            let q0 = -0.5 * (b + b.signum() * r);
            roots = [q0 / a, if q0 != 0.0 { k / q0 } else { f64::NAN }];
        }
    } else if b != 0.0 {
        roots[0] = -k / b;
    }
    for tau in roots {
        if tau > 0.0 && tau < len {
            best = best.min(re_over(c, p + e * tau));
        }
    }
    best
}

/// The least `Re(c/s)` on the arc `centre + ρ e^{jψ}` about the centre
/// `corner + ρ`, `ψ` from `from` to
/// `from + π/2` (the ends are some segment's, and are not counted). `1/s`
/// maps the arc's circle (0 outside it) to a circle whose point of least
/// `Re(c w)` is closed-form; it counts if it came from the arc.
fn arc_min(c: Complex64, corner: (f64, f64), rho: f64, from: f64) -> f64 {
    let centre = Complex64::new(corner.0 + rho, corner.1);
    // `|centre|² - ρ²` without the cancellation of two large squares.
    let den = corner.0 * (corner.0 + 2.0 * rho) + corner.1 * corner.1;
    if rho <= 0.0 || den <= 0.0 || c.norm() == 0.0 {
        return f64::INFINITY;
    }
    let wc = centre.conj() / den;
    let rw = rho / den;
    let w = wc - c.conj() / c.norm() * rw;
    if w.norm() == 0.0 {
        return f64::INFINITY;
    }
    let s = w.inv();
    let psi = (s - centre).arg().rem_euclid(2.0 * PI);
    let lo = from.rem_euclid(2.0 * PI);
    let along = (psi - lo).rem_euclid(2.0 * PI);
    if along <= PI / 2.0 {
        re_over(c, s)
    } else {
        f64::INFINITY
    }
}

/// The least `Re(c/s)` over `s = x + jy + h` with `x` in `xs`, `y` in
/// `ys` and `h` in the disk of centre and radius `rho` (the rectangle
/// rounded by the disk and moved right by `rho`).
fn rounded_min(c: Complex64, xs: (f64, f64), ys: (f64, f64), rho: f64) -> f64 {
    let z = |x: f64, y: f64| Complex64::new(x, y);
    let (x1, x2) = (xs.0 + rho, xs.1 + rho);
    let (y1, y2) = ys;
    let sides = [
        segment_min(c, z(xs.0, y1), z(xs.0, y2)),
        segment_min(c, z(x2 + rho, y1), z(x2 + rho, y2)),
        segment_min(c, z(x1, y1 - rho), z(x2, y1 - rho)),
        segment_min(c, z(x1, y2 + rho), z(x2, y2 + rho)),
        arc_min(c, (xs.0, y1), rho, PI),
        arc_min(c, (xs.1, y1), rho, 1.5 * PI),
        arc_min(c, (xs.1, y2), rho, 0.0),
        arc_min(c, (xs.0, y2), rho, 0.5 * PI),
    ];
    sides.into_iter().fold(f64::INFINITY, f64::min)
}

/// The radius of the disk the hand's impedance lies in at `ω` (rad/s),
/// `1/(2 Re(1/Z_max(jω)))` (N s/m).
fn hand_radius(human: &HumanBound, omega: f64) -> f64 {
    let g = human.admittance(Complex64::new(0.0, omega.abs())).re;
    0.5 / g
}

/// `B(θ)`: the least `Re(1/Z_c(e^{jθ}))` that keeps the loop at the pose
/// stable for every hand the bound allows and every passive VE. The
/// aliases past the 60th on each side are bounded: `|ζ_k| ≤ 1/|s| ≤ 1/(|ω_k| m_min
/// - ρ)`, summed as an integral.
pub fn bound_at(pose: &PoseRanges, human: &HumanBound, period_s: f64, theta: f64) -> f64 {
    let t = period_s;
    let c = Complex64::from_polar(1.0, -theta);
    let s2 = 4.0 * (theta / 2.0).sin().powi(2);
    let (m1, m2) = pose.mass_kg;
    let mut sum = 0.0;
    for k in -ALIASES..=ALIASES {
        let x = theta + 2.0 * PI * k as f64;
        let omega = x / t;
        let a = s2 / (x * x);
        let ys = if omega >= 0.0 {
            (omega * m1, omega * m2)
        } else {
            (omega * m2, omega * m1)
        };
        let rho = hand_radius(human, omega);
        sum += a * rounded_min(c, pose.damping_nspm, ys, rho).min(0.0);
    }
    // The rest, `|k| > K`: `|x_k| ≥ 2π(|k| - 1/2)`, so each side's sum is
    // below the integral from `x0 = 2π(K - 1/2)`. Each term is at least the
    // one any passive hand gives, `a_k (cos θ - 1)/(2 d_min)`, and where
    // `x m_min ≥ 2 ρ T` at most `2 s2 T/(m_min x³)` below zero.
    let x0 = 2.0 * PI * (ALIASES as f64 - 0.5);
    let any_hand = 2.0 * s2 / (2.0 * PI * x0) * (1.0 - theta.cos()) / (2.0 * pose.damping_nspm.0);
    let rho = hand_radius(human, x0 / t);
    let bounded = if x0 * m1 >= 2.0 * rho * t {
        2.0 * s2 * t / (2.0 * PI * m1 * x0 * x0)
    } else {
        f64::INFINITY
    };
    -sum + any_hand.min(bounded)
}

/// The stiffest `k_c` (N/m) at `b_c` for which `Re(1/Z_c) ≥ bound` at
/// `θ`, with `Z_c = k_c T/(1 - z^-1) + b_c`; `None` when no stiffness
/// does (the coupling's damping alone is past the bound).
pub fn stiffest_at(bound: f64, b_c: f64, period_s: f64, theta: f64) -> Option<f64> {
    let a = 1.0 - theta.cos();
    if bound <= 0.0 {
        return Some(f64::INFINITY);
    }
    if !bound.is_finite() {
        return None;
    }
    // B u² + (2 B b_c a - a) u + 2 a b_c (B b_c - 1) <= 0, u = k_c T.
    let qa = bound;
    let qb = 2.0 * bound * b_c * a - a;
    let qc = 2.0 * a * b_c * (bound * b_c - 1.0);
    let disc = qb * qb - 4.0 * qa * qc;
    if disc < 0.0 {
        return None;
    }
    let hi = (-qb + disc.sqrt()) / (2.0 * qa);
    let lo = (-qb - disc.sqrt()) / (2.0 * qa);
    (lo <= 0.0 && hi > 0.0).then_some(hi / period_s)
}

/// The stiffest `k_c` at `b_c` proven at the pose over `thetas`, and the
/// `θ` that binds; `None` if none is.
pub fn stiffest(
    pose: &PoseRanges,
    human: &HumanBound,
    b_c: f64,
    period_s: f64,
    thetas: &[f64],
) -> Option<(f64, f64)> {
    let mut best = (f64::INFINITY, PI);
    for &th in thetas {
        let k = stiffest_at(bound_at(pose, human, period_s, th), b_c, period_s, th)?;
        if k < best.0 {
            best = (k, th);
        }
    }
    Some(best)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The closed-form minima agree with a dense scan of the boundary, and
    /// with a scan of the rectangle's inside (the minimum is on the edge).
    #[test]
    fn the_rounded_minimum_matches_a_scan() {
        let mut r = crate::test_rng::uniform(7u64);
        for _ in 0..100 {
            let c = Complex64::from_polar(1.0, -PI * r());
            let x1 = 0.01 + r();
            let xs = (x1, x1 + 3.0 * r());
            let y1 = 20.0 * (r() - 0.5);
            let ys = (y1, y1 + 5.0 * r());
            let rho = 4.0 * r();
            let got = rounded_min(c, xs, ys, rho);
            // The sum's boundary is a rectangle's edge point plus a point
            // of the disk's circle: scan those.
            let mut scan = f64::INFINITY;
            let n = 200;
            for i in 0..=n {
                let u = i as f64 / n as f64;
                let (x, y) = (xs.0 + u * (xs.1 - xs.0), ys.0 + u * (ys.1 - ys.0));
                for base in [(xs.0, y), (xs.1, y), (x, ys.0), (x, ys.1)] {
                    for a in 0..2048 {
                        let h = Complex64::new(rho, 0.0)
                            + Complex64::from_polar(rho, a as f64 * PI / 1024.0);
                        scan = scan.min(re_over(c, Complex64::new(base.0, base.1) + h));
                    }
                }
            }
            assert!(got <= scan + 1e-12, "{got} above the scan's {scan}");
            assert!(got >= scan - 1e-3 * scan.abs(), "{got} vs {scan}");
        }
    }

    /// With no bound on the hand (the disk's radius without end) the
    /// bound is Colgate's, `(1 - cos θ)/(2 d)`, and the paper's `Z_max`
    /// never asks more than that.
    #[test]
    fn a_loose_bound_is_colgates_and_the_papers_is_never_above_it() {
        let pose = PoseRanges {
            mass_kg: (0.02, 2.0),
            damping_nspm: (0.005, 3.0),
        };
        let loose = HumanBound {
            damping_nspm: 1e12,
            stiffness_npm: 1e15,
        };
        for th in theta_grid(1e-3, 40) {
            let colgate = (1.0 - th.cos()) / (2.0 * 0.005);
            let b = bound_at(&pose, &loose, 1e-3, th);
            assert!(
                (b - colgate).abs() <= 1e-3 * colgate,
                "θ {th}: {b} vs {colgate}"
            );
            let p = bound_at(&pose, &HumanBound::PAPER, 1e-3, th);
            assert!(p <= colgate * (1.0 + 1e-9), "θ {th}: {p} vs {colgate}");
        }
        let (k, _) = stiffest(&pose, &loose, 0.0, 1e-3, &theta_grid(1e-3, 100)).unwrap();
        assert!((k - 10.0).abs() < 0.02, "{k}");
    }

    /// The coupling's inequality solved for `k_c` is tight: just inside it
    /// holds, just past it fails.
    #[test]
    fn the_stiffest_coupling_meets_the_bound() {
        for (bound, b_c, th) in [(0.3, 0.0, 0.4), (2.0, 0.1, 2.0), (50.0, 0.01, 3.0)] {
            let t = 1e-3;
            let k = stiffest_at(bound, b_c, t, th).unwrap();
            let re = |k: f64| {
                let q = Complex64::new(1.0, 0.0) - Complex64::from_polar(1.0, -th);
                (q / (k * t + b_c * q)).re
            };
            assert!(re(0.999 * k) >= bound, "{bound}");
            assert!(re(1.001 * k) < bound, "{bound}");
        }
        assert_eq!(stiffest_at(0.3, 10.0, 1e-3, 1.0), None);
    }
}
