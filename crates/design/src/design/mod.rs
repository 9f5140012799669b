//! Coupling synthesis, absolute-stability checks and impedance ranges, on a
//! frequency grid refined where the device resonates.
//!
//! Every coupling and regulator response here is the control crate's own
//! law, built with the f32 parameters the board would get, through its
//! `tf()`: the law analysed is the law run.

use crate::twoport::{
    admittance_display, impedance_display, llewellyn_margin, with_admittance_coupling,
    with_impedance_coupling, HumanBound,
};
use crate::{Plant, PlantPoint};

mod grid;
mod region;

pub use grid::{grid, log_grid, Analysis, GridSpec};
use num_complex::Complex64;
pub use region::{region_admittance, region_impedance, region_rust_source};
use std::f64::consts::PI;
use twoport_control::{
    AdmittanceCoupling, ImpedanceCoupling, ParamError, PositionRegulator, ZTransfer,
};

/// The z-domain form of the impedance coupling the board would run:
/// stiffness `k` (N/m), damping `b` (N s/m), period `t` (s).
pub fn impedance_coupling_tf(k: f64, b: f64, t: f64) -> Result<ZTransfer, ParamError> {
    ImpedanceCoupling::new(k as f32, b as f32, t as f32).map(|c| c.tf())
}

/// The z-domain form of the admittance coupling the board would run:
/// mass `m` (kg), damping `b` (N s/m), period `t` (s).
pub fn admittance_coupling_tf(m: f64, b: f64, t: f64) -> Result<ZTransfer, ParamError> {
    AdmittanceCoupling::new(m as f32, b as f32, t as f32).map(|c| c.tf())
}

/// The z-domain form of the position regulator the board would run:
/// stiffness `kp` (N/m), damping `bp` (N s/m), period `t` (s).
pub fn regulator_tf(kp: f64, bp: f64, t: f64) -> Result<ZTransfer, ParamError> {
    PositionRegulator::new(kp as f32, bp as f32, t as f32).map(|r| r.tf())
}

/// Smallest `lhs(ω) - bound(ω)` over the grid and between its points (see
/// [`least`]), or the negative [`dc_margin`] where the limit toward DC
/// fails.
fn slack(a: &Analysis, bound: &[f64], lhs: impl Fn(Complex64) -> f64) -> f64 {
    let d: Vec<f64> = a
        .points
        .iter()
        .zip(bound)
        .map(|(p, b)| lhs(p.z) - b)
        .collect();
    least(&a.points, &d)
        .0
        .min(dc_margin(a, bound, &lhs).min(0.0))
}

/// The least of `v` (a smooth function sampled at `points`) and where
/// (rad/s), between the points too: at each local minimum of the samples,
/// the vertex of the parabola through it and its neighbours. The grid
/// resolves every feature of the design inequality on its own scale (see
/// [`grid`]), so the function is smooth on the scale of three neighbouring
/// points and the parabola finds the dip between them; the samples alone
/// miss it by up to the curvature times the spacing squared (on the
/// Excalibur at 82 Hz, 8e-6 of the stiffness).
pub fn least(points: &[PlantPoint], v: &[f64]) -> (f64, f64) {
    let mut best = (f64::INFINITY, points.first().map_or(0.0, |p| p.omega));
    for (i, (p, y)) in points.iter().zip(v).enumerate() {
        if *y < best.0 || y.is_nan() {
            best = (if y.is_nan() { f64::NEG_INFINITY } else { *y }, p.omega);
        }
        if i == 0 || i + 1 >= v.len() || !(*y <= v[i - 1] && *y <= v[i + 1]) {
            continue;
        }
        let (x0, x1, x2) = (points[i - 1].omega, p.omega, points[i + 1].omega);
        let (y0, y1, y2) = (v[i - 1], *y, v[i + 1]);
        if !(y0.is_finite() && y1.is_finite() && y2.is_finite()) {
            continue;
        }
        // The parabola's vertex, from its divided differences.
        let d01 = (y1 - y0) / (x1 - x0);
        let d12 = (y2 - y1) / (x2 - x1);
        let c2 = (d12 - d01) / (x2 - x0);
        if c2 <= 0.0 {
            continue;
        }
        let xv = 0.5 * (x0 + x1) - d01 / (2.0 * c2);
        if xv <= x0 || xv >= x2 {
            continue;
        }
        let yv = y1 + d01 * (xv - x1) + c2 * (xv - x0) * (xv - x1);
        if yv < best.0 {
            best = (yv, xv);
        }
    }
    best
}

/// The relative margin of `lhs(ω) >= bound(ω)` in the limit `ω -> 0`, taken
/// analytically below the grid. Both sides are real parts of real-rational
/// functions of `jω` and `e^{jωT}`, so they are even in `ω`:
/// `q(ω) = q_0 + q_2 ω² + O(ω⁴)`. Every coupling here has `lhs_0 = 0` (a
/// spring's or a mass's real part vanishes at DC). From the grid's lowest
/// frequency `ω_1` and `2 ω_1`, Richardson's step gives `q_0` and `q_2`
/// with an error of order `ω_1⁴`. A bound with `β_0 > 0` (it stays positive
/// toward DC) cannot be met (margin -1); one with `β_0 = 0` is met iff
/// `lhs_2 >= β_2`. The grid's own points stay where the evaluation is
/// accurate: below about 0.05 Hz at 1 kHz, `1 - cos ωT` and the sampled
/// terms near their rigid-body pole lose more digits than the result can
/// spare.
pub fn dc_margin(a: &Analysis, bound: &[f64], lhs: &dyn Fn(Complex64) -> f64) -> f64 {
    let Some((beta0, beta2)) = dc_series(a, bound) else {
        // A grid without its DC pair (Analysis::on): no limit to take.
        return f64::INFINITY;
    };
    if !(beta0.is_finite() && beta2.is_finite()) {
        return -1.0;
    }
    let i2 = a.dc_pair.unwrap_or(0);
    let (_, c2q) = even_series(a, lhs(a.points[0].z), lhs(a.points[i2].z));
    // A bound whose limit is clearly non-zero decides alone: met strictly
    // (β_0 < 0 = lhs_0) or never (β_0 > 0). Otherwise β_0 is the O(ω_1⁴)
    // residue of a bound that vanishes as ω², and the ω² terms decide.
    let (b1, b2) = (bound[0], bound[i2]);
    if beta0.abs() > 0.01 * b1.abs().max(b2.abs()) {
        return relative_margin(0.0, beta0);
    }
    relative_margin(c2q, beta2)
}

/// `(q_0, q_2)` of `q(ω) = q_0 + q_2 ω² + O(ω⁴)` from `q(ω_1) = q1` and
/// `q(2 ω_1) = q2` at the grid's lowest frequency `ω_1`.
fn even_series(a: &Analysis, q1: f64, q2: f64) -> (f64, f64) {
    let w2 = a.points[0].omega * a.points[0].omega;
    ((4.0 * q1 - q2) / 3.0, (q2 - q1) / (3.0 * w2))
}

/// The bound's [`even_series`] toward DC, where the grid has its DC pair.
fn dc_series(a: &Analysis, bound: &[f64]) -> Option<(f64, f64)> {
    a.dc_pair.map(|i2| even_series(a, bound[0], bound[i2]))
}

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
pub const K_RANGE: (f64, f64) = (1.0, 1.0e8);
/// Search range for the coupling mass (kg).
pub const M_RANGE: (f64, f64) = (1.0e-3, 1.0e4);
/// Search range for coupling damping in the best-pair search (N s/m).
pub const B_RANGE: (f64, f64) = (1.0, 1.0e4);

/// Where a design is impossible at any gain because of the limit toward
/// DC (see [`dc_margin`]): every coupling's real part vanishes as
/// `ω -> 0`, so a bound that stays positive there cannot be met by any
/// finite stiffness or mass. Returns the bound's DC limit (the bound's
/// unit), or `None`.
pub fn low_frequency_obstacle(a: &Analysis, bound: &[f64]) -> Option<f64> {
    (dc_margin(a, bound, &|_| 0.0) <= -1.0)
        .then(|| dc_series(a, bound).map(|(beta0, _)| beta0))
        .flatten()
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
    let mut hi = K_RANGE.1;
    for (a, bound) in poses {
        let t = a.period_s;
        hi = largest(K_RANGE.0, hi, |k| {
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
    let mut hi = 1.0 / M_RANGE.0;
    for (a, bound) in poses {
        let t = a.period_s;
        let ok = |m: f64| {
            admittance_coupling_tf(m, b_nspm, t)
                .map(|tf| slack(a, bound, |z| tf.eval(z).re) >= 0.0)
                .unwrap_or(false)
        };
        hi = largest(1.0 / M_RANGE.1, hi, |inv| ok(1.0 / inv))?;
    }
    Some(1.0 / hi)
}

/// Maximise `score(b)` over `B_RANGE` on a log scan refined by golden
/// section; returns `(b, score)` or `None` if nowhere feasible.
fn best_over_b(score: impl Fn(f64) -> Option<f64>) -> Option<(f64, f64)> {
    let n = 33;
    let (lo, hi) = (B_RANGE.0.ln(), B_RANGE.1.ln());
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

/// Result of an absolute-stability check.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Check {
    /// Whether the sound (sampled-data) design inequality holds at every
    /// grid frequency (and, for the admittance display, the regulated
    /// device is stable): absolutely stable for every passive hand and VE.
    pub absolutely_stable: bool,
    /// The smallest relative slack of the sound design inequality over the
    /// grid (see [`relative_margin`]): >= 0 is absolutely stable.
    pub min_margin: f64,
    /// Where it occurs (Hz).
    pub worst_frequency_hz: f64,
    /// For the admittance display: the largest pole radius of the regulated
    /// device (< 1 is stable); 0 for the impedance display.
    pub regulator_pole_radius: f64,
    /// The same check on the paper's approximation (aliasing at the handle
    /// port neglected), for comparison.
    pub paper: PaperCheck,
}

impl Check {
    /// Whether the sampled-data analysis decides differently from the
    /// paper's approximation: another verdict, or a margin smaller by more
    /// than 1e-6.
    pub fn sampled_binds(&self) -> bool {
        self.absolutely_stable != self.paper.absolutely_stable
            || self.paper.min_margin - self.min_margin > 1e-6
    }
}

/// The paper's approximate check beside the sound one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PaperCheck {
    /// Whether the paper's inequality holds everywhere.
    pub absolutely_stable: bool,
    /// Its least relative slack.
    pub min_margin: f64,
    /// Where (Hz).
    pub worst_frequency_hz: f64,
}

/// The relative slack `(c - β) / (|c| + |β|)` of a design inequality
/// `c >= β` (`c` the coupling's term, `β` the bound): +1 far inside, 0 on the
/// bound, negative where it is violated, -1 where `β` is infinite. Its sign
/// is that of Llewellyn's `η - 1` at the same frequency (the inequality is
/// `η >= 1` multiplied by `2 Re p11 > 0`), but unlike `η - 1` it does not
/// vanish at DC, where every coupling makes the rigid device a lossless link.
pub fn relative_margin(c: f64, bound: f64) -> f64 {
    if bound == f64::INFINITY || c.is_nan() || bound.is_nan() {
        return -1.0;
    }
    let den = c.abs() + bound.abs();
    if den == 0.0 {
        0.0
    } else {
        (c - bound) / den
    }
}

/// The least relative slack of `lhs(z) >= bound` over the grid (and
/// between its points, see [`least`]), and where (Hz).
fn worst(a: &Analysis, bound: &[f64], lhs: impl Fn(Complex64) -> f64) -> (f64, f64) {
    let dc = (dc_margin(a, bound, &lhs), 0.0);
    let m: Vec<f64> = a
        .points
        .iter()
        .zip(bound)
        .map(|(pt, b)| relative_margin(lhs(pt.z), *b))
        .collect();
    let (g, w) = least(&a.points, &m);
    if g < dc.0 {
        (g, w / (2.0 * PI))
    } else {
        dc
    }
}

fn paper_check((m, f): (f64, f64), extra: bool) -> PaperCheck {
    PaperCheck {
        absolutely_stable: m >= 0.0 && extra,
        min_margin: m,
        worst_frequency_hz: f,
    }
}

/// Absolute-stability check of the impedance display with coupling `(k, b)`.
pub fn check_impedance(a: &Analysis, k: f64, b: f64, human: Option<HumanBound>) -> Option<Check> {
    let tf = impedance_coupling_tf(k, b, a.period_s).ok()?;
    let lhs = |z: Complex64| tf.eval(z).inv().re;
    let (m, f) = worst(a, &a.impedance_bound(human), lhs);
    Some(Check {
        absolutely_stable: m >= 0.0,
        min_margin: m,
        worst_frequency_hz: f,
        regulator_pole_radius: 0.0,
        paper: paper_check(worst(a, &a.paper_impedance_bound(human), lhs), true),
    })
}

/// Absolute-stability check of the admittance display with regulator
/// `(kp, bp)` and coupling `(m, b)`.
pub fn check_admittance(
    plant: &Plant,
    a: &Analysis,
    (kp, bp): (f64, f64),
    (m, b): (f64, f64),
    human: Option<HumanBound>,
) -> Option<Check> {
    let (k, zc) = admittance_laws(a, (kp, bp), (m, b))?;
    let radius = plant.regulated_pole_radius(&k);
    let lhs = |z: Complex64| zc.eval(z).re;
    let (mg, f) = worst(a, &a.admittance_bound(&k, human), lhs);
    Some(Check {
        absolutely_stable: mg >= 0.0 && radius < 1.0,
        min_margin: mg,
        worst_frequency_hz: f,
        regulator_pole_radius: radius,
        paper: paper_check(
            worst(a, &a.paper_admittance_bound(&k, human), lhs),
            radius < 1.0,
        ),
    })
}

/// Llewellyn's `η - 1` of the full interface at every grid point (for
/// plots and cross-checks), impedance display.
pub fn llewellyn_impedance(
    a: &Analysis,
    k: f64,
    b: f64,
    human: Option<HumanBound>,
) -> Option<Vec<f64>> {
    let tf = impedance_coupling_tf(k, b, a.period_s).ok()?;
    Some(
        a.points
            .iter()
            .map(|p| {
                llewellyn_margin(&with_impedance_coupling(
                    &impedance_display(p, human),
                    tf.eval(p.z),
                ))
            })
            .collect(),
    )
}

/// The admittance display's regulator and coupling z-forms, as the board
/// would run them.
fn admittance_laws(
    a: &Analysis,
    (kp, bp): (f64, f64),
    (m, b): (f64, f64),
) -> Option<(ZTransfer, ZTransfer)> {
    Some((
        regulator_tf(kp, bp, a.period_s).ok()?,
        admittance_coupling_tf(m, b, a.period_s).ok()?,
    ))
}

/// Llewellyn's `η - 1` of the full interface at every grid point,
/// admittance display.
pub fn llewellyn_admittance(
    a: &Analysis,
    (kp, bp): (f64, f64),
    (m, b): (f64, f64),
    human: Option<HumanBound>,
) -> Option<Vec<f64>> {
    let (k, zc) = admittance_laws(a, (kp, bp), (m, b))?;
    Some(
        a.points
            .iter()
            .map(|p| {
                llewellyn_margin(&with_admittance_coupling(
                    &admittance_display(p, &k, human),
                    zc.eval(p.z),
                ))
            })
            .collect(),
    )
}

/// The impedance range (eqs 32, 33) at each grid point: `(Z_min, Z_max)`
/// (N s/m), the impedances the human feels with the VE port shorted
/// (free motion) and open (rigid constraint).
pub fn impedance_range_impedance(
    a: &Analysis,
    k: f64,
    b: f64,
) -> Option<Vec<(Complex64, Complex64)>> {
    let tf = impedance_coupling_tf(k, b, a.period_s).ok()?;
    Some(
        a.points
            .iter()
            .map(|p| {
                let y = impedance_display(p, None);
                let zmin = y[0][0].inv();
                let zmax = (y[0][0] - y[0][1] * y[1][0] / (y[1][1] + tf.eval(p.z).inv())).inv();
                (zmin, zmax)
            })
            .collect(),
    )
}

/// The admittance display's impedance range: `(Z_min, Z_max)` (N s/m).
pub fn impedance_range_admittance(
    a: &Analysis,
    (kp, bp): (f64, f64),
    (m, b): (f64, f64),
) -> Option<Vec<(Complex64, Complex64)>> {
    let (k, zc) = admittance_laws(a, (kp, bp), (m, b))?;
    Some(
        a.points
            .iter()
            .map(|p| {
                let g = admittance_display(p, &k, None);
                let zmax = g[0][0].inv();
                let zmin = (g[0][0] - g[0][1] * g[1][0] / (g[1][1] + zc.eval(p.z))).inv();
                (zmin, zmax)
            })
            .collect(),
    )
}
