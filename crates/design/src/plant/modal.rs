//! The device's transfer functions in modal (residue) form: O(n) per
//! frequency, checked against the LU before it is used.

use crate::linalg::{balance, lu_solve};
use nalgebra::DMatrix;
use num_complex::Complex64;

/// `Y(s)` and `F(s)` as sums of first-order terms, `Σ R_i / (s - λ_i)`
/// over the poles of the augmented model `[q, q', w]`: O(n) per frequency.
/// Built by inverse iteration for the eigenvectors and kept only if it
/// agrees with the LU at check frequencies (see [`Plant::new`]).
#[derive(Clone, Debug)]
pub(super) struct Modal {
    poles: Vec<Complex64>,
    /// Per pole: `[Y_hh, Y_ha, Y_ah, Y_aa, F_mh, F_ma]` residues.
    residues: Vec<[Complex64; 6]>,
}

impl Modal {
    /// `a` (na x na), `b` (na x 2), outputs `c` (3 x na): rows v_h, -v_a, f_m.
    pub(super) fn new(a: &DMatrix<f64>, b: &DMatrix<f64>, c: &DMatrix<f64>) -> Option<Self> {
        let na = a.nrows();
        // Balance first: the load-cell row alone is ~1e10, which would
        // leave the eigenvalues (the rigid-body pole near 0 above all) with
        // absolute errors of 1e-6. A diagonal similarity by powers of two
        // changes no transfer function and rounds nothing.
        let d = balance(a);
        let a = DMatrix::from_fn(na, na, |i, j| a[(i, j)] * d[j] / d[i]);
        let b = DMatrix::from_fn(na, 2, |i, j| b[(i, j)] / d[i]);
        let c = DMatrix::from_fn(3, na, |i, j| c[(i, j)] * d[j]);
        let ac = a.map(|x| Complex64::new(x, 0.0));
        let act = ac.transpose();
        let mut poles = Vec::with_capacity(na);
        let mut residues = Vec::with_capacity(na);
        for l in crate::linalg::eigenvalues(&a)? {
            let shift = l + Complex64::new(1e-9, 1e-9) * l.norm().max(1.0);
            let v = inverse_iteration(&ac, shift)?;
            let w = inverse_iteration(&act, shift)?;
            let wv: Complex64 = w.iter().zip(&v).map(|(x, y)| x * y).sum();
            if wv.norm() < 1e-12 {
                return None; // (nearly) defective: no modal form
            }
            // Rayleigh quotient w^T A v / w^T v: the pole to working precision.
            let av = &ac * nalgebra::DVector::from_column_slice(&v);
            let l = w
                .iter()
                .zip(av.iter())
                .map(|(x, y)| x * y)
                .sum::<Complex64>()
                / wv;
            poles.push(l);
            let cv: Vec<Complex64> = (0..3)
                .map(|r| (0..na).map(|j| v[j] * c[(r, j)]).sum())
                .collect();
            let wb: Vec<Complex64> = (0..2)
                .map(|k| (0..na).map(|j| w[j] * b[(j, k)]).sum::<Complex64>() / wv)
                .collect();
            residues.push([
                cv[0] * wb[0],
                cv[0] * wb[1],
                cv[1] * wb[0],
                cv[1] * wb[1],
                cv[2] * wb[0],
                cv[2] * wb[1],
            ]);
        }
        Some(Modal { poles, residues })
    }

    /// [`eval`](Self::eval)'s `[Y_hh, Y_ha, Y_ah, F_mh]` alone.
    pub(super) fn eval_hand(&self, s: Complex64) -> [Complex64; 4] {
        let mut out = [Complex64::new(0.0, 0.0); 4];
        for (l, r) in self.poles.iter().zip(&self.residues) {
            let g = (s - l).inv();
            for (o, ri) in out.iter_mut().zip([r[0], r[1], r[2], r[4]]) {
                *o += ri * g;
            }
        }
        out
    }

    pub(super) fn eval(&self, s: Complex64) -> [Complex64; 6] {
        let mut out = [Complex64::new(0.0, 0.0); 6];
        for (l, r) in self.poles.iter().zip(&self.residues) {
            let g = (s - l).inv();
            for (o, ri) in out.iter_mut().zip(r) {
                *o += ri * g;
            }
        }
        out
    }
}

/// A null vector of `a - shift I` by two steps of inverse iteration.
fn inverse_iteration(a: &DMatrix<Complex64>, shift: Complex64) -> Option<Vec<Complex64>> {
    let n = a.nrows();
    let mut x: Vec<Complex64> = (0..n)
        .map(|i| Complex64::new(1.0 + 0.1 * i as f64, 0.3 - 0.05 * i as f64))
        .collect();
    for _ in 0..2 {
        let mut m: Vec<Complex64> = (0..n * n)
            .map(|i| {
                a[(i / n, i % n)]
                    - if i / n == i % n {
                        shift
                    } else {
                        Complex64::new(0.0, 0.0)
                    }
            })
            .collect();
        if !lu_solve(&mut m, n, &mut x, 1) {
            return None;
        }
        let norm = x.iter().map(|v| v.norm_sqr()).sum::<f64>().sqrt();
        if !norm.is_finite() || norm == 0.0 {
            return None;
        }
        x.iter_mut().for_each(|v| *v /= norm);
    }
    Some(x)
}
