//! Where the design inequality's terms change fast: the poles of every
//! transfer function it is built from, folded into the base band, each
//! with the half-width over which it acts. The frequency grid is refined
//! around them ([`crate::analysis::grid`]).

use super::augmented;
use crate::DeviceModel;
use nalgebra::DMatrix;
use num_complex::Complex64;

/// A narrow feature of the design inequality's terms, folded into the base
/// band: a pole of one of them, where the term can change by its whole size
/// within a few half-widths.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Feature {
    /// Where it sits in the base band (rad/s, in `(0, π/T]`).
    pub omega: f64,
    /// Its half-power half-width (rad/s): the pole's decay rate.
    pub half_width: f64,
}

/// `ω` (rad/s) folded into the base band `[0, π/T]` as sampling folds it.
fn fold(omega: f64, period_s: f64) -> f64 {
    let ws = 2.0 * std::f64::consts::PI / period_s;
    let r = omega.rem_euclid(ws);
    r.min(ws - r)
}

/// The oscillating poles (`Im λ > 0`) of `M q'' + D q' + K q = 0`, where
/// `M` is invertible: `(ω_d, σ)`, `λ = -σ + jω_d`.
fn oscillating_poles(m: &DMatrix<f64>, d: &DMatrix<f64>, k: &DMatrix<f64>) -> Vec<(f64, f64)> {
    let n = m.nrows();
    let Some(minv) = m.clone().lu().try_inverse() else {
        return Vec::new();
    };
    // The device's own state matrix, with no load cell: its filter state
    // then sits at s = 0, which no oscillating pole is.
    let none = (DMatrix::zeros(n, 0), DMatrix::zeros(1, n));
    let (a, _) = augmented(&(&minv * k), &(&minv * d), &none.0, &none.1, 0.0);
    crate::linalg::eigenvalues(&a)
        .map(|poles| oscillating(&poles))
        .unwrap_or_default()
}

/// `(Im λ, -Re λ)` of the poles with `Im λ > 0`.
fn oscillating(poles: &[Complex64]) -> Vec<(f64, f64)> {
    poles
        .iter()
        .filter(|l| l.im > 0.0)
        .map(|l| (l.im, -l.re))
        .collect()
}

/// A basis (as columns) of the vectors orthogonal to `v`.
fn orthogonal_complement(v: &[f64]) -> Option<DMatrix<f64>> {
    let n = v.len();
    let norm = v.iter().map(|x| x * x).sum::<f64>().sqrt();
    if n < 2 || norm == 0.0 {
        return None;
    }
    // Householder: H = I - 2 u u^T maps v to ±|v| e_p; its other columns
    // span v's complement.
    let p = (0..n).max_by(|&i, &j| v[i].abs().total_cmp(&v[j].abs()))?;
    let mut u: Vec<f64> = v.iter().map(|x| x / norm).collect();
    u[p] += u[p].signum();
    let un = u.iter().map(|x| x * x).sum::<f64>().sqrt();
    u.iter_mut().for_each(|x| *x /= un);
    let h = DMatrix::from_fn(n, n, |i, j| f64::from(u8::from(i == j)) - 2.0 * u[i] * u[j]);
    let cols: Vec<usize> = (0..n).filter(|&j| j != p).collect();
    Some(h.select_columns(&cols))
}

/// The features of [`Plant::features`](super::Plant::features), from the
/// free device's poles and the sampled device's `discrete_poles`.
pub(super) fn of(
    model: &DeviceModel,
    free_poles: &[Complex64],
    discrete_poles: &[Complex64],
    period_s: f64,
) -> Vec<Feature> {
    let mut continuous = oscillating(free_poles);
    let (m, d, k) = (&model.m, &model.d, &model.k);
    let c_h: Vec<f64> = model.c_v.row(0).iter().copied().collect();
    let g_h: Vec<f64> = model.g.column(0).iter().copied().collect();
    // Held by the paper's stiffest grasp: f_h = -(b v_h + k x_h) through
    // the handle's force column.
    let grasp = crate::network::HumanBound::PAPER;
    let gc = DMatrix::from_fn(m.nrows(), m.ncols(), |i, j| g_h[i] * c_h[j]);
    continuous.extend(oscillating_poles(
        m,
        &(d + &gc * grasp.damping_nspm),
        &(k + &gc * grasp.stiffness_npm),
    ));
    // Held still: q = N r with c_h^T N = 0, the constraint force along g_h
    // projected out by L^T g_h = 0.
    if let (Some(nq), Some(l)) = (orthogonal_complement(&c_h), orthogonal_complement(&g_h)) {
        let lt = l.transpose();
        continuous.extend(oscillating_poles(
            &(&lt * m * &nq),
            &(&lt * d * &nq),
            &(&lt * k * &nq),
        ));
    }
    let mut out: Vec<Feature> = continuous
        .into_iter()
        .filter(|(w, s)| w.is_finite() && s.is_finite())
        .map(|(w, s)| Feature {
            omega: fold(w, period_s),
            half_width: s.abs(),
        })
        .collect();
    out.extend(of_discrete(discrete_poles, period_s));
    out.retain(|f| f.omega > 0.0);
    out.sort_by(|x, y| x.omega.total_cmp(&y.omega));
    out
}

/// The features of discrete poles `z` (one of each conjugate pair) at
/// period `period_s` (s): centre `arg z / T`, half-width `-ln |z| / T`.
pub(crate) fn of_discrete(poles: &[Complex64], period_s: f64) -> Vec<Feature> {
    poles
        .iter()
        .filter(|l| l.im > 0.0)
        .map(|l| Feature {
            omega: l.im.atan2(l.re) / period_s,
            half_width: (-l.norm().ln()).abs() / period_s,
        })
        .collect()
}
