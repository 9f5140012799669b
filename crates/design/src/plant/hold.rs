//! The device discretised: its continuous state space, the zero-order
//! hold's exact equivalent, and the hold delayed inside the tick.

use crate::linalg::expm_balanced;
use nalgebra::{DMatrix, DVector};

/// The device's state space on `x = [q, q', w]`, `w` the load cell's
/// filter state (`w' = -p w + p C_f q`): `(A, B)` with one column of `B`
/// per input, from `M^-1 K`, `M^-1 D` and `M^-1 G` (the caller solves with
/// `M`), the strain-gauge row `c_f` (1 x n) and the pole `p` (rad/s).
pub(crate) fn augmented(
    minv_k: &DMatrix<f64>,
    minv_d: &DMatrix<f64>,
    minv_g: &DMatrix<f64>,
    c_f: &DMatrix<f64>,
    p: f64,
) -> (DMatrix<f64>, DMatrix<f64>) {
    let n = minv_k.nrows();
    let na = 2 * n + 1;
    let mut a = DMatrix::<f64>::zeros(na, na);
    let mut b = DMatrix::<f64>::zeros(na, minv_g.ncols());
    for i in 0..n {
        a[(i, n + i)] = 1.0;
        for j in 0..n {
            a[(n + i, j)] = -minv_k[(i, j)];
            a[(n + i, n + j)] = -minv_d[(i, j)];
        }
        for j in 0..minv_g.ncols() {
            b[(n + i, j)] = minv_g[(i, j)];
        }
        a[(2 * n, i)] = p * c_f[(0, i)];
    }
    a[(2 * n, 2 * n)] = -p;
    (a, b)
}

/// The zero-order-hold equivalent `(A_d, B_d)` of `(A, B)` at period `t`
/// (s): `exp([[A, B], [0, 0]] t) = [[A_d, B_d], [0, I]]`.
fn zoh(a: &DMatrix<f64>, b: &DMatrix<f64>, t: f64) -> Result<(DMatrix<f64>, DMatrix<f64>), String> {
    let (na, m) = (a.nrows(), b.ncols());
    let mut blk = DMatrix::<f64>::zeros(na + m, na + m);
    blk.view_mut((0, 0), (na, na)).copy_from(&(a * t));
    blk.view_mut((0, na), (na, m)).copy_from(&(b * t));
    let e = expm_balanced(&blk).map_err(|e| e.to_string())?;
    Ok((
        e.view((0, 0), (na, na)).into_owned(),
        e.view((0, na), (na, m)).into_owned(),
    ))
}

/// The zero-order hold of one input delayed inside the tick: the force a
/// tick computes acts from `τ` after its sample, the previous tick's force
/// before it, so `x[k+1] = A_d x[k] + b_now u[k] + b_prev u[k-1]`.
#[derive(Clone, Debug)]
pub(crate) struct DelayedHold {
    /// `e^{AT}`.
    pub(crate) ad: DMatrix<f64>,
    /// `∫_0^{T-τ} e^{As} ds b`.
    pub(crate) b_now: DVector<f64>,
    /// `e^{A(T-τ)} ∫_0^τ e^{As} ds b`; zero without a latency.
    pub(crate) b_prev: DVector<f64>,
}

impl DelayedHold {
    /// The hold of the input `b` at period `t` (s), delayed by `fraction`
    /// of it. At `fraction = 0` it is [`zoh`]'s, with `b_prev = 0`.
    pub(crate) fn new(
        a: &DMatrix<f64>,
        b: &DVector<f64>,
        t: f64,
        fraction: f64,
    ) -> Result<Self, String> {
        let b = DMatrix::from_column_slice(b.len(), 1, b.as_slice());
        if fraction == 0.0 {
            let (ad, bd) = zoh(a, &b, t)?;
            return Ok(DelayedHold {
                ad,
                b_now: bd.column(0).into_owned(),
                b_prev: DVector::zeros(a.nrows()),
            });
        }
        let tau = fraction * t;
        let (e_rest, b_rest) = zoh(a, &b, t - tau)?;
        let (e_tau, b_tau) = zoh(a, &b, tau)?;
        Ok(DelayedHold {
            ad: &e_rest * e_tau,
            b_now: b_rest.column(0).into_owned(),
            b_prev: (&e_rest * b_tau).column(0).into_owned(),
        })
    }

    /// The first `n` states alone (where the rest do not feed them).
    pub(crate) fn leading(&self, n: usize) -> DelayedHold {
        DelayedHold {
            ad: self.ad.view((0, 0), (n, n)).into_owned(),
            b_now: self.b_now.rows(0, n).into_owned(),
            b_prev: self.b_prev.rows(0, n).into_owned(),
        }
    }

    /// As one discrete system: the state gains the previous tick's force,
    /// `[x; u[k-1]]`, with `[[A_d, b_prev], [0, 0]]` and input `[b_now;
    /// 1]` (an output row gains a zero: [`padded`]). Without a latency the
    /// system is `(A_d, b_now)` as it is.
    pub(crate) fn latched(&self) -> (DMatrix<f64>, Vec<f64>) {
        let mut b = self.b_now.as_slice().to_vec();
        if self.b_prev.iter().all(|v| *v == 0.0) {
            return (self.ad.clone(), b);
        }
        let n = self.ad.nrows();
        let mut a = DMatrix::<f64>::zeros(n + 1, n + 1);
        a.view_mut((0, 0), (n, n)).copy_from(&self.ad);
        for (i, v) in self.b_prev.iter().enumerate() {
            a[(i, n)] = *v;
        }
        b.push(1.0);
        (a, b)
    }
}

/// `c` with zeros up to `n` entries: an output row of a [`latched`] system.
pub(crate) fn padded(c: &[f64], n: usize) -> Vec<f64> {
    let mut c = c.to_vec();
    c.resize(n, 0.0);
    c
}
