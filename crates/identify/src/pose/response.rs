//! The exact sampled response of a rigid body at a pose,
//! `M x'' + D x' = f`, its force held over each period `T` (zero-order
//! hold) and its position sampled: position over force (m/N).
//!
//! With `M = L Lᵀ` and the eigenvectors `V` of `L^-1 D L^-T`
//! (eigenvalues `λ_i`, 1/s), `Φ = L^-T V` makes both diagonal:
//! `Φᵀ M Φ = I`, `Φᵀ D Φ = Λ`. The body is then `n` decoupled units
//! `1/(s (s + λ))`, whose hold-equivalent is, with `x = λT`,
//! `p = e^{-x}`,
//!
//! `g(z) = T² (φ(x) (z - 1) + ψ(x)) / ((z - 1) (z - p))`,
//!
//! `φ(x) = (x + e^{-x} - 1)/x²` and `ψ(x) = (1 - e^{-x})/x`, each by its
//! series near 0 (a body with no damping: `T² (z + 1) / (2 (z - 1)²)`).
//! The response is `Φ diag(g_i) Φᵀ`.

use nalgebra::DMatrix;
use num_complex::Complex64;

/// `(x + e^{-x} - 1)/x²`, accurate at any `x` (no cancellation near 0).
fn phi(x: f64) -> f64 {
    if x.abs() < 1e-3 {
        0.5 - x / 6.0 + x * x / 24.0 - x * x * x / 120.0
    } else {
        (x + (-x).exp_m1()) / (x * x)
    }
}

/// `(1 - e^{-x})/x`, 1 at 0.
fn psi(x: f64) -> f64 {
    if x.abs() < 1e-9 {
        1.0 - x / 2.0
    } else {
        -(-x).exp_m1() / x
    }
}

/// The response at each of `freq_hz` of the body of mass `m` (kg) and
/// damping `d` (N s/m), sampled every `period_s`: `None` where `m` is not
/// positive definite or `d` is not symmetric enough to diagonalise.
pub fn sampled(
    m: &DMatrix<f64>,
    d: &DMatrix<f64>,
    period_s: f64,
    freq_hz: &[f64],
) -> Option<Vec<DMatrix<Complex64>>> {
    let n = m.nrows();
    let l = m.clone().cholesky()?.l();
    let l_inv = l.try_inverse()?;
    let c = &l_inv * d * l_inv.transpose();
    let eig = ((&c + c.transpose()) * 0.5).symmetric_eigen();
    let phi_m = l_inv.transpose() * &eig.eigenvectors;
    let t = period_s;
    let modes: Vec<(f64, f64, f64)> = eig
        .eigenvalues
        .iter()
        .map(|lam| {
            let x = lam * t;
            (phi(x), psi(x), (-x).exp())
        })
        .collect();
    let phi_c = phi_m.map(|v| Complex64::new(v, 0.0));
    let out = freq_hz
        .iter()
        .map(|f| {
            let z = Complex64::from_polar(1.0, std::f64::consts::TAU * f * t);
            let g = DMatrix::from_fn(n, n, |r, c| {
                if r != c {
                    return Complex64::new(0.0, 0.0);
                }
                let (a, b, p) = modes[r];
                t * t * ((z - 1.0) * a + b) / ((z - 1.0) * (z - p))
            });
            &phi_c * g * phi_c.transpose()
        })
        .collect();
    Some(out)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A three-axis body whose axes are coupled in both its mass (kg)
    /// and its damping (N s/m), one direction lightly damped.
    pub(crate) fn coupled_body() -> (DMatrix<f64>, DMatrix<f64>) {
        let m =
            DMatrix::from_row_slice(3, 3, &[0.3, 0.05, -0.02, 0.05, 0.2, 0.01, -0.02, 0.01, 0.1]);
        let d = DMatrix::from_row_slice(3, 3, &[2.0, 0.3, 0.0, 0.3, 0.5, -0.1, 0.0, -0.1, 0.2]);
        (m, d)
    }

    /// Against the state-space hold-equivalent computed independently
    /// (the matrix exponential of the augmented system, `C (zI - A_d)^-1
    /// B_d`), for a coupled, damped three-axis body and for one with no
    /// damping, to 1e-9 relative.
    #[test]
    fn matches_the_state_space_hold_equivalent() {
        let (m, d_some) = coupled_body();
        let t = 1e-3;
        for d in [d_some, DMatrix::zeros(3, 3)] {
            // States [x; v; f]: the force held by a zero eigenvalue block.
            let minv = m.clone().try_inverse().unwrap();
            let mut a = DMatrix::zeros(9, 9);
            a.view_mut((0, 3), (3, 3))
                .copy_from(&DMatrix::identity(3, 3));
            a.view_mut((3, 3), (3, 3)).copy_from(&(-&minv * &d));
            a.view_mut((3, 6), (3, 3)).copy_from(&minv);
            let e = (a * t).exp();
            let ad = e.view((0, 0), (6, 6)).into_owned();
            let bd = e.view((0, 6), (6, 3)).into_owned();
            let freqs = [0.7, 13.0, 211.0, 480.0];
            let got = sampled(&m, &d, t, &freqs).unwrap();
            for (f, g) in freqs.iter().zip(&got) {
                let z = Complex64::from_polar(1.0, std::f64::consts::TAU * f * t);
                let zi =
                    DMatrix::<Complex64>::identity(6, 6) * z - ad.map(|v| Complex64::new(v, 0.0));
                let h = zi.try_inverse().unwrap() * bd.map(|v| Complex64::new(v, 0.0));
                let want = h.view((0, 0), (3, 3)).into_owned();
                let err = (g - &want).norm() / want.norm();
                assert!(err < 1e-9, "{f} Hz: {err}");
            }
        }
    }
}
