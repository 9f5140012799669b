//! Small allocation-free complex solvers for the per-frequency work: each
//! frequency point solves one small system, so the solvers reuse buffers.

use nalgebra::{DMatrix, Schur};
use num_complex::Complex64;

/// The eigenvalues of a real square matrix, or `None` where it has a
/// number that is not finite or the QR iteration does not settle (at a
/// deflation tolerance of up to 4,096 ulps). Every
/// eigenvalue in the crate goes through here: nalgebra's own
/// `complex_eigenvalues` iterates without a bound, and a degenerate
/// model (a spring of 10^14 N/m on a gram) would hang a design.
pub fn eigenvalues(a: &DMatrix<f64>) -> Option<Vec<Complex64>> {
    if !a.iter().all(|x| x.is_finite()) {
        return None;
    }
    let n = a.nrows().max(1);
    // Deflation at more ulps where one ulp does not settle: a loop with
    // several poles at z = 1 (free motion, the laws' integrators, a wave
    // filter's pole beside them) can cycle at the strictest tolerance, and
    // what a looser one moves an eigenvalue by (about 1e-7 at 4,096 ulps
    // in such a cluster) is far less than the Gelfand estimate's rounding
    // there.
    let schur = [1.0, 4.0, 64.0, 4096.0]
        .iter()
        .find_map(|ulps| Schur::try_new(a.clone(), ulps * f64::EPSILON, 1000 * n))?;
    Some(schur.complex_eigenvalues().iter().copied().collect())
}

/// The spectral radius of a real square matrix by Gelfand's formula,
/// `ρ = lim ||A^n||^(1/n)`, with `n = 2^40` reached by squaring, each
/// square scaled back to norm one and the scale kept as a logarithm. It
/// needs no eigenvalue to converge, so it answers where the QR iteration
/// of [`eigenvalues`] does not settle (a stiff termination whose sampled
/// modes span twenty decades); it is larger than `ρ` by at most a factor
/// `(κ n_dim)^(2^-40)`, below 1e-10 for any matrix here. `None` for a
/// number that is not finite.
pub fn spectral_radius_gelfand(a: &DMatrix<f64>) -> Option<f64> {
    if !a.iter().all(|x| x.is_finite()) {
        return None;
    }
    let mut m = a.clone();
    // ||A^(2^k)|| = e^e_k, m = A^(2^k) / e^e_k.
    let mut e = 0.0f64;
    for k in 0..=40 {
        let norm = m.norm();
        if norm == 0.0 {
            return Some(0.0);
        }
        if !norm.is_finite() {
            return None;
        }
        m /= norm;
        e += norm.ln() / 2f64.powi(k);
        if k < 40 {
            m = &m * &m;
        }
    }
    Some(e.exp())
}

/// Solve `a x = b` in place by LU with partial pivoting: `a` is n x n
/// row-major, `b` is n x m row-major; on return `b` holds `x`. Returns
/// `false` for a singular `a` (a zero pivot).
pub fn lu_solve(a: &mut [Complex64], n: usize, b: &mut [Complex64], m: usize) -> bool {
    for k in 0..n {
        let mut p = k;
        let mut best = a[k * n + k].norm_sqr();
        for r in k + 1..n {
            let v = a[r * n + k].norm_sqr();
            if v > best {
                (p, best) = (r, v);
            }
        }
        if best == 0.0 || !best.is_finite() {
            return false;
        }
        if p != k {
            for c in 0..n {
                a.swap(k * n + c, p * n + c);
            }
            for c in 0..m {
                b.swap(k * m + c, p * m + c);
            }
        }
        let inv = a[k * n + k].inv();
        for r in k + 1..n {
            let f = a[r * n + k] * inv;
            if f == Complex64::new(0.0, 0.0) {
                continue;
            }
            for c in k + 1..n {
                let t = a[k * n + c];
                a[r * n + c] -= f * t;
            }
            for c in 0..m {
                let t = b[k * m + c];
                b[r * m + c] -= f * t;
            }
        }
    }
    back_substitute(a, n, b, m);
    true
}

fn back_substitute(a: &[Complex64], n: usize, b: &mut [Complex64], m: usize) {
    for k in (0..n).rev() {
        let inv = a[k * n + k].inv();
        for c in 0..m {
            let mut s = b[k * m + c];
            for j in k + 1..n {
                s -= a[k * n + j] * b[j * m + c];
            }
            b[k * m + c] = s * inv;
        }
    }
}

/// Solve `(z I - h) y = b` for an upper-Hessenberg `h` (n x n row-major,
/// real) in O(n^2), using `work` (n x n) as scratch; `b` becomes `y`.
/// Returns `false` if `z` is an eigenvalue.
pub fn hessenberg_shift_solve(
    h: &[f64],
    n: usize,
    z: Complex64,
    work: &mut [Complex64],
    b: &mut [Complex64],
) -> bool {
    for r in 0..n {
        for c in 0..n {
            let d = if r == c { z } else { Complex64::new(0.0, 0.0) };
            work[r * n + c] = d - h[r * n + c];
        }
    }
    // Only the subdiagonal needs eliminating; pivot between rows k, k+1.
    for k in 0..n.saturating_sub(1) {
        let (top, below) = (work[k * n + k], work[(k + 1) * n + k]);
        if below.norm_sqr() > top.norm_sqr() {
            for c in k..n {
                work.swap(k * n + c, (k + 1) * n + c);
            }
            b.swap(k, k + 1);
        }
        let piv = work[k * n + k];
        if piv.norm_sqr() == 0.0 {
            return false;
        }
        let f = work[(k + 1) * n + k] / piv;
        for c in k..n {
            let t = work[k * n + c];
            work[(k + 1) * n + c] -= f * t;
        }
        let t = b[k];
        b[k + 1] -= f * t;
    }
    if work[(n - 1) * n + n - 1].norm_sqr() == 0.0 {
        return false;
    }
    back_substitute(work, n, b, 1);
    true
}

/// Parlett-Reinsch balancing: diagonal `d` (powers of two) such that
/// `d^-1 a d` has rows and columns of similar norms.
pub fn balance(a: &DMatrix<f64>) -> Vec<f64> {
    let n = a.nrows();
    let mut d = vec![1.0f64; n];
    for _ in 0..100 {
        let mut done = true;
        for i in 0..n {
            let (mut c, mut r) = (0.0, 0.0);
            for j in (0..n).filter(|&j| j != i) {
                c += (a[(j, i)] * d[i] / d[j]).abs();
                r += (a[(i, j)] * d[j] / d[i]).abs();
            }
            if c == 0.0 || r == 0.0 {
                continue;
            }
            let mut f = 1.0;
            let (mut cc, mut rr) = (c, r);
            while cc < rr / 2.0 {
                (f, cc, rr) = (f * 2.0, cc * 2.0, rr / 2.0);
            }
            while cc >= rr * 2.0 {
                (f, cc, rr) = (f / 2.0, cc / 2.0, rr * 2.0);
            }
            if (cc + rr) < 0.95 * (c + r) {
                d[i] *= f;
                done = false;
            }
        }
        if done {
            break;
        }
    }
    d
}

/// `e^a` computed on the balanced matrix, `e^a = d e^(d^-1 a d) d^-1`: a
/// stiff device model (entries from 1 to 1e10) loses digits in scaling and
/// squaring otherwise.
///
/// An error for a non-finite entry or a norm beyond [`EXPM_MAX_NORM`]:
/// scaling and squaring takes `log2 |a|` squarings, so an infinite norm
/// would never finish (the model-file fuzzer found one), and a norm that
/// large means time constants a million million times shorter than the
/// step, which no sampled model of a device has.
pub fn expm_balanced(a: &DMatrix<f64>) -> Result<DMatrix<f64>, crate::Error> {
    let bad = |why: String| Err(crate::Error::Exponential(why));
    let n = a.nrows();
    if a.iter().any(|v| !v.is_finite()) {
        return bad("the matrix exponential's argument is not finite".into());
    }
    let norm = (0..n)
        .map(|j| a.column(j).iter().map(|v| v.abs()).sum::<f64>())
        .fold(0.0, f64::max);
    if norm > EXPM_MAX_NORM {
        return bad(format!(
            "the matrix exponential's argument has norm {norm:.3e} (> {EXPM_MAX_NORM:e}): \
             the model's dynamics are far faster than the sample period"
        ));
    }
    let d = balance(a);
    let b = DMatrix::from_fn(n, n, |i, j| a[(i, j)] * d[j] / d[i]);
    let e = b.exp();
    let out = DMatrix::from_fn(n, n, |i, j| e[(i, j)] * d[i] / d[j]);
    if out.iter().any(|v| !v.is_finite()) {
        return bad("the matrix exponential is not finite".into());
    }
    Ok(out)
}

/// The largest 1-norm [`expm_balanced`] accepts.
pub const EXPM_MAX_NORM: f64 = 1.0e15;

#[cfg(test)]
mod tests {
    use super::*;

    /// Gelfand's radius agrees with the eigenvalues': a rotation scaled
    /// by 0.999, a Jordan block at 1 (its powers grow like n, its radius
    /// is 1), a nilpotent matrix (0), and a matrix spanning twenty decades.
    #[test]
    fn the_radius_from_powers_is_the_eigenvalues() {
        let th: f64 = 0.3;
        let r = DMatrix::from_row_slice(2, 2, &[th.cos(), -th.sin(), th.sin(), th.cos()]) * 0.999;
        let jordan = DMatrix::from_row_slice(2, 2, &[1.0, 1.0, 0.0, 1.0]);
        let nil = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, 0.0, 0.0]);
        let wide =
            DMatrix::from_row_slice(3, 3, &[0.5, 1e10, 0.0, 0.0, 1e-10, 1e10, 0.0, 0.0, 0.9]);
        for (m, want) in [(r, 0.999), (jordan, 1.0), (nil, 0.0), (wide, 0.9)] {
            let got = spectral_radius_gelfand(&m).unwrap();
            let eig = eigenvalues(&m)
                .unwrap()
                .iter()
                .map(|l| l.norm())
                .fold(0.0, f64::max);
            assert!((got - want).abs() < 1e-9, "{got} against {want}");
            assert!(
                (got - eig).abs() < 1e-9,
                "{got} against the eigenvalues' {eig}"
            );
        }
        assert_eq!(
            spectral_radius_gelfand(&DMatrix::from_element(1, 1, f64::NAN)),
            None
        );
    }

    fn c(re: f64, im: f64) -> Complex64 {
        Complex64::new(re, im)
    }

    /// A damped oscillator's poles come back; a matrix with a number that
    /// is not finite gives none, rather than an iteration that never ends.
    #[test]
    fn eigenvalues_are_found_or_refused() {
        // x'' + 2 x' + 5 x = 0: poles -1 ± 2j.
        let a = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -5.0, -2.0]);
        let mut l = eigenvalues(&a).unwrap();
        l.sort_by(|x, y| x.im.total_cmp(&y.im));
        assert!((l[0] - c(-1.0, -2.0)).norm() < 1e-12, "{l:?}");
        assert!((l[1] - c(-1.0, 2.0)).norm() < 1e-12, "{l:?}");
        for bad in [f64::NAN, f64::INFINITY] {
            let a = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, bad, -2.0]);
            assert!(eigenvalues(&a).is_none());
        }
    }

    #[test]
    fn lu_solves_a_pivoting_system() {
        // [[0, 1], [2, 3]] x = [[1], [8]] -> x = [2.5, 1]
        let mut a = vec![c(0.0, 0.0), c(1.0, 0.0), c(2.0, 0.0), c(3.0, 0.0)];
        let mut b = vec![c(1.0, 0.0), c(8.0, 0.0)];
        assert!(lu_solve(&mut a, 2, &mut b, 1));
        assert!((b[0] - c(2.5, 0.0)).norm() < 1e-14 && (b[1] - c(1.0, 0.0)).norm() < 1e-14);
        let mut s = vec![c(1.0, 0.0), c(2.0, 0.0), c(2.0, 0.0), c(4.0, 0.0)];
        assert!(!lu_solve(&mut s, 2, &mut b, 1));
    }

    #[test]
    fn hessenberg_solve_agrees_with_lu() {
        let n = 4;
        let h: Vec<f64> = (0..n * n)
            .map(|i| {
                let (r, col) = (i / n, i % n);
                if r > col + 1 {
                    0.0
                } else {
                    ((i * 7 + 3) % 11) as f64 - 5.0
                }
            })
            .collect();
        let z = c(0.3, 0.8);
        let rhs: Vec<Complex64> = (0..n).map(|i| c(i as f64 + 1.0, -(i as f64))).collect();
        let mut y = rhs.clone();
        let mut work = vec![c(0.0, 0.0); n * n];
        assert!(hessenberg_shift_solve(&h, n, z, &mut work, &mut y));
        let mut a: Vec<Complex64> = (0..n * n)
            .map(|i| if i / n == i % n { z } else { c(0.0, 0.0) } - h[i])
            .collect();
        let mut x = rhs;
        assert!(lu_solve(&mut a, n, &mut x, 1));
        for i in 0..n {
            assert!((x[i] - y[i]).norm() < 1e-12 * x[i].norm().max(1.0));
        }
    }
}
