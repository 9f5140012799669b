//! Coupling synthesis, absolute-stability checks and impedance ranges, on a
//! frequency grid refined where the device resonates.
//!
//! Every coupling and regulator response here is the control crate's own
//! law, built with the f32 parameters the board would get, through its
//! `tf()`: the law analysed is the law run.

use crate::PlantPoint;

mod check;
mod grid;
mod range;
mod region;
mod synthesis;
mod teleop;
mod teleop_range;

pub use check::*;
pub use grid::{feature_grid, grid, log_grid, Analysis, GridSpec};
use num_complex::Complex64;
pub use range::*;
pub use region::{region_admittance, region_impedance, region_rust_source};
pub use synthesis::*;
pub use teleop::{check_teleop, closing_hands, teleop_slack, TeleopAnalysis, TeleopCheck};
pub use teleop_range::{felt_at_low_frequency, teleop_range, Felt};
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
        // (Nearly coincident points give a parabola of rounding noise.)
        if (x1 - x0).min(x2 - x1) <= grid::COINCIDENT * x1 {
            continue;
        }
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
