//! Coupling synthesis, absolute-stability checks and impedance ranges, on a
//! frequency grid refined where the device resonates.
//!
//! Every coupling and regulator response here is the control crate's own
//! law, built with the f32 parameters the board would get, through its
//! `tf()`: the law analysed is the law run.

use crate::twoport::{
    admittance_display, design_bound, impedance_display, llewellyn_margin,
    with_admittance_coupling, with_impedance_coupling, HumanBound,
};
use crate::{sampled, Plant, PlantPoint};
use num_complex::Complex64;
use std::f64::consts::PI;
use twoport_control::{
    AdmittanceCoupling, ImpedanceCoupling, ParamError, PositionRegulator, ZTransfer,
};

/// How finely to sample frequency.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridSpec {
    /// Lowest frequency (Hz).
    pub f_min_hz: f64,
    /// Log-spaced points from `f_min_hz` to Nyquist.
    pub base_points: usize,
    /// Points across each resonance (see [`grid`]): linearly spaced over
    /// its shape, this many in all.
    pub points_per_mode: usize,
    /// Points per decade of distance from each feature's centre, from a
    /// hundredth of its half-width out to its shape's edge.
    pub points_per_decade: usize,
}

impl GridSpec {
    /// The default design grid. Doubling every count moves no design result
    /// by more than 0.5% (tested). Below its lowest frequency the limit
    /// `ω -> 0` is taken analytically (see [`dc_margin`]), so starting it
    /// lower moves no result either (tested).
    pub const DEFAULT: GridSpec = GridSpec {
        f_min_hz: 0.05,
        base_points: 1500,
        points_per_mode: 300,
        points_per_decade: 24,
    };

    /// This grid started at `f_min_hz` instead, with the same density.
    pub fn from_hz(self, f_min_hz: f64) -> GridSpec {
        let decades = (f_min_hz / self.f_min_hz).log10();
        let per_decade = self.base_points as f64 / (500.0 / self.f_min_hz).log10();
        GridSpec {
            f_min_hz,
            base_points: (self.base_points as f64 - decades * per_decade)
                .round()
                .max(2.0) as usize,
            ..self
        }
    }

    /// This grid with twice the points.
    pub fn doubled(self) -> GridSpec {
        GridSpec {
            base_points: self.base_points * 2,
            points_per_mode: self.points_per_mode * 2,
            points_per_decade: self.points_per_decade * 2,
            ..self
        }
    }
}

/// Angular frequencies (rad/s), increasing, in `(0, π/T]`, ending at `π/T`.
///
/// A log grid, refined at every [`Feature`](crate::plant::Feature) of the
/// device: its free modes, its modes with the handle held (still, or by
/// the stiffest grasp), each folded into the base band, and its discrete
/// poles. Each term of a design inequality is a sum of terms
/// `r/(jω - λ)` (or their alias sums, which have the same folded poles), and
/// such a term changes by a large fraction of itself only within a few
/// half-widths `|Re λ|` of `Im λ`. So around each feature the grid places
/// points log-spaced in the distance from its centre, from 1/100 of its
/// half-width out to its shape's edge (20 half-widths, at least 2% of the
/// centre): however lightly damped, a mode is resolved on its own scale,
/// where a fixed spacing would step over a mode narrower than it.
pub fn grid(plant: &Plant, spec: GridSpec) -> Vec<f64> {
    let nyq = plant.nyquist();
    let lo = (2.0 * PI * spec.f_min_hz).min(nyq / 10.0);
    let mut w = log_grid(lo, nyq, spec.base_points);
    let mut push = |x: f64| {
        if x > 0.0 && x <= nyq {
            w.push(x);
        }
    };
    for f in plant.features() {
        let (c, beta) = (f.omega, f.half_width.max(1e-12 * f.omega));
        let edge = (20.0 * beta).max(0.02 * c);
        // Linear over the shape, as the eye would sample it.
        let k = spec.points_per_mode.max(2);
        for i in 0..k {
            push(c - edge + 2.0 * edge * i as f64 / (k - 1) as f64);
        }
        // Log in the distance from the centre, down to 1/100 half-width.
        push(c);
        let per = spec.points_per_decade.max(1) as f64;
        let mut j = 0.0;
        loop {
            let u = 0.01 * beta * 10f64.powf(j / per);
            if u > edge {
                break;
            }
            push(c - u);
            push(c + u);
            j += 1.0;
        }
    }
    // The exact ends: Nyquist, and twice the lowest frequency for the
    // limit toward DC.
    w.push(nyq);
    w.push(2.0 * lo);
    w.sort_by(f64::total_cmp);
    w.dedup_by(|a, b| (*a - *b).abs() <= 1e-12 * b.abs());
    w
}

/// The device's responses on a grid, ready for design and checks.
#[derive(Clone, Debug)]
pub struct Analysis {
    /// The per-frequency plant terms.
    pub points: Vec<PlantPoint>,
    /// The sample period (s).
    pub period_s: f64,
    /// The device, for the alias sums of the sampled-data bounds.
    plant: Plant,
    /// The index of twice the lowest frequency, where the grid has it: with
    /// the lowest, the pair the limit toward DC is taken from.
    dc_pair: Option<usize>,
}

impl Analysis {
    /// Evaluate `plant` on the grid `spec`.
    ///
    /// # Examples
    ///
    /// ```
    /// use twoport_design::design::{max_stiffness, Analysis, GridSpec};
    /// use twoport_design::twoport::HumanBound;
    /// use twoport_design::{DeviceModel, Plant};
    /// let m = DeviceModel::excalibur()?;
    /// let a = Analysis::new(&Plant::new(&m, 1e-3)?, GridSpec::DEFAULT);
    /// let k = max_stiffness(&a, &a.impedance_bound(Some(HumanBound::PAPER)), 90.0).unwrap();
    /// assert!((k - 51_000.0).abs() < 0.03 * 51_000.0); // the paper's design
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn new(plant: &Plant, spec: GridSpec) -> Self {
        Analysis::from_points(plant, plant.response(&grid(plant, spec)))
    }

    /// `model` at its own period on the default grid: where most designs
    /// start. The error names what the model's dynamics refused.
    pub fn of(model: &crate::DeviceModel) -> Result<Self, String> {
        Plant::new(model, model.period_s).map(|p| Analysis::new(&p, GridSpec::DEFAULT))
    }

    /// The paper's Excalibur (the built-in model) at 1 ms on the default
    /// grid.
    pub fn excalibur() -> Self {
        let m = crate::DeviceModel::excalibur().expect("the built-in Excalibur model is valid");
        Analysis::of(&m).expect("the built-in Excalibur model discretises")
    }

    /// Evaluate `plant` on the given angular frequencies (rad/s).
    pub fn on(plant: &Plant, omegas: &[f64]) -> Self {
        Analysis::from_points(plant, plant.response(omegas))
    }

    fn from_points(plant: &Plant, points: Vec<PlantPoint>) -> Self {
        let dc_pair = points.first().and_then(|p1| {
            points
                .iter()
                .position(|p| (p.omega - 2.0 * p1.omega).abs() <= 1e-12 * p.omega)
        });
        Analysis {
            points,
            period_s: plant.period_s(),
            plant: plant.clone(),
            dc_pair,
        }
    }

    /// The device this analysis is of.
    pub fn plant(&self) -> &Plant {
        &self.plant
    }

    /// The impedance-display bound on `Re(1/Z_cI)` at each grid point,
    /// sound for the sampled-data loop (aliasing at the handle port
    /// included, see [`crate::sampled`]): what designs and checks use.
    pub fn impedance_bound(&self, human: Option<HumanBound>) -> Vec<f64> {
        sampled::impedance_bound(&self.plant, &self.points, human)
    }

    /// The admittance-display bound on `Re Z_cA` at each grid point, for
    /// the regulator `kp`, sound for the sampled-data loop.
    pub fn admittance_bound(&self, kp: &ZTransfer, human: Option<HumanBound>) -> Vec<f64> {
        sampled::admittance_bound(&self.plant, &self.points, kp, human)
    }

    /// The paper's impedance-display bound (eq 25 as corrected): the handle
    /// port's cross terms as continuous transfer functions times the hold,
    /// aliasing neglected. Reported beside the sound one, never used alone
    /// to prove.
    pub fn paper_impedance_bound(&self, human: Option<HumanBound>) -> Vec<f64> {
        self.points
            .iter()
            .map(|p| design_bound(&impedance_display(p, human)))
            .collect()
    }

    /// The paper's admittance-display bound (eq 28), aliasing neglected.
    pub fn paper_admittance_bound(&self, kp: &ZTransfer, human: Option<HumanBound>) -> Vec<f64> {
        self.points
            .iter()
            .map(|p| design_bound(&admittance_display(p, kp, human)))
            .collect()
    }
}

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

/// The proven region for a board: for each damping on a log grid from
/// `b_lo` to `b_hi` (N s/m, `points` of them), the greatest coupling
/// stiffness (impedance display) over every pose. Dampings where nothing is
/// stable are left out. (One pose: `&[(&analysis, &bound)]`.)
pub fn region_impedance(poses: &Poses, range: (f64, f64), points: usize) -> Vec<(f64, f64)> {
    region(range, points, |b| max_stiffness_poses(poses, b))
}

/// The proven region for a board's admittance display (one regulator):
/// the least coupling mass for each damping on a log grid, over every pose.
pub fn region_admittance(poses: &Poses, range: (f64, f64), points: usize) -> Vec<(f64, f64)> {
    region(range, points, |b| min_mass_poses(poses, b))
}

fn region(
    (lo, hi): (f64, f64),
    points: usize,
    limit: impl Fn(f64) -> Option<f64>,
) -> Vec<(f64, f64)> {
    log_grid(lo, hi, points)
        .into_iter()
        .filter_map(|b| limit(b).map(|l| (b, l)))
        .collect()
}

/// `n` (at least 2) log-spaced values from `lo` to `hi`, both included.
pub fn log_grid(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    let n = n.max(2);
    (0..n)
        .map(|i| lo * (hi / lo).powf(i as f64 / (n - 1) as f64))
        .collect()
}

/// A proven region as Rust source for a board image (`twoport-board`'s
/// `Region`): the damping grid, the limits (rounded *toward safety*: a
/// stiffness down, a mass up, so that the f32 copy never proves more than
/// the f64 analysis did), and the regulator for an admittance region.
/// `how` is the command that made it, quoted in the header.
pub fn region_rust_source(
    rows: &[(f64, f64)],
    max_stiffness: bool,
    regulator: Option<(f64, f64)>,
    how: &str,
) -> String {
    use std::fmt::Write;
    let toward_safety = |l: f64| {
        let f = l as f32;
        let over = (f as f64) > l;
        match (max_stiffness, over) {
            (true, true) => f.next_down(),
            (false, false) if (f as f64) < l => f.next_up(),
            _ => f,
        }
    };
    let n = rows.len();
    let mut s = String::new();
    let _ = writeln!(s, "// Made by the designer: `{how}`. Do not edit;");
    let _ = writeln!(
        s,
        "// tests/shipped_region.rs checks it against the designer."
    );
    let bound = if max_stiffness {
        "MaxStiffness"
    } else {
        "MinMass"
    };
    let _ = writeln!(s, "/// What the region bounds.");
    let _ = writeln!(s, "pub const BOUND: Bound = Bound::{bound};");
    let _ = writeln!(s, "/// Coupling damping grid (N s/m).");
    let list = |v: &mut dyn Iterator<Item = f32>| {
        v.map(|x| format!("{x:?}")).collect::<Vec<_>>().join(", ")
    };
    let _ = writeln!(
        s,
        "pub const DAMPING_NSPM: [f32; {n}] = [{}];",
        list(&mut rows.iter().map(|r| r.0 as f32))
    );
    let unit = if max_stiffness { "N/m" } else { "kg" };
    let _ = writeln!(s, "/// The proven limit at each damping ({unit}).");
    let _ = writeln!(
        s,
        "pub const LIMIT: [f32; {n}] = [{}];",
        list(&mut rows.iter().map(|r| toward_safety(r.1)))
    );
    let _ = writeln!(
        s,
        "/// The regulator (k_p N/m, b_p N s/m) an admittance region holds for."
    );
    match regulator {
        Some((k, b)) => {
            let _ = writeln!(
                s,
                "pub const REGULATOR: Option<(f32, f32)> = Some(({:?}, {:?}));",
                k as f32, b as f32
            );
        }
        None => {
            let _ = writeln!(s, "pub const REGULATOR: Option<(f32, f32)> = None;");
        }
    }
    s
}
