//! The integrators that advance the plant's [`System`] over a fixed
//! sub-step, with the human's nonlinear forces entering as `E F_nl`.

use super::System;
use crate::Error;
use nalgebra::DMatrix;

/// How the plant is advanced over one sub-step `h`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// Zero-order-hold exact: `x <- e^{Ah} x + (∫e^{At}dt) (B u + E F)`.
    ExactZoh,
    /// Explicit (forward) Euler.
    Euler,
    /// Semi-implicit (symplectic) Euler: velocities first, then positions.
    SemiImplicitEuler,
    /// Classical fourth-order Runge-Kutta.
    Rk4,
}

impl Method {
    /// Name as in scene files.
    pub fn name(self) -> &'static str {
        match self {
            Method::ExactZoh => "exact_zoh",
            Method::Euler => "euler",
            Method::SemiImplicitEuler => "semi_implicit_euler",
            Method::Rk4 => "rk4",
        }
    }

    /// Whether a linear mode at `λ` (rad/s) stays bounded under this method
    /// at step `h` (s): `|R(hλ)| <= 1` for the method's amplification `R`.
    /// For semi-implicit Euler on a lightly damped mode, the condition is
    /// `h ω < 2`. Exact ZOH is exact.
    pub fn stable_for(self, lambda: nalgebra::Complex<f64>, h: f64) -> bool {
        let z = lambda * h;
        let one = nalgebra::Complex::new(1.0, 0.0);
        match self {
            Method::ExactZoh => true,
            Method::Euler => (one + z).norm() <= 1.0 + 1e-12,
            Method::Rk4 => {
                (one + z + z * z / 2.0 + z * z * z / 6.0 + z * z * z * z / 24.0).norm()
                    <= 1.0 + 1e-12
            }
            Method::SemiImplicitEuler => lambda.norm() * h < 2.0,
        }
    }
}

/// A discrete stepper for a [`System`] at a fixed sub-step.
#[derive(Clone, Debug)]
pub struct Stepper {
    method: Method,
    h: f64,
    ns: usize,
    n: usize,
    /// Column-major `A` (continuous) or `A_d` (exact ZOH).
    a: Vec<f64>,
    /// Column-major `B` (ns x 2) or `B_d`.
    b: Vec<f64>,
    /// Column-major `E` (ns x n) or `E_d`.
    e: Vec<f64>,
    k: [Vec<f64>; 4],
    tmp: Vec<f64>,
    force: Vec<f64>,
}

/// A nonlinear force law: fills a force vector on the coordinates (N) for a
/// state.
pub type Nonlinear<'a> = &'a mut dyn FnMut(&[f64], &mut [f64]);

/// `A x + B u` for `N` states, column-major `A` (N x N) and `B` (N x 2);
/// `None` when the slices are not those sizes.
#[inline(always)]
fn affine_fixed<const N: usize>(a: &[f64], b: &[f64], x: &[f64], u: [f64; 2]) -> Option<[f64; N]> {
    // Whole arrays, not iterators over chunks, so that the loops unroll
    // without per-column bounds checks.
    let a = <&[[f64; N]; N]>::try_from(a.as_chunks::<N>().0).ok()?;
    let b = <&[[f64; N]; 2]>::try_from(b.as_chunks::<N>().0).ok()?;
    let x = <&[f64; N]>::try_from(x.get(..N)?).ok()?;
    let mut acc = [0.0f64; N];
    for i in 0..N {
        acc[i] = b[0][i] * u[0] + b[1][i] * u[1];
    }
    for j in 0..N {
        for i in 0..N {
            acc[i] += a[j][i] * x[j];
        }
    }
    Some(acc)
}

/// `x <- A x + B u` in place for `N` states; `false` when the sizes differ.
#[inline(always)]
fn affine_fixed_in_place<const N: usize>(a: &[f64], b: &[f64], x: &mut [f64], u: [f64; 2]) -> bool {
    match (affine_fixed::<N>(a, b, x, u), x.get_mut(..N)) {
        (Some(y), Some(x)) => {
            x.copy_from_slice(&y);
            true
        }
        _ => false,
    }
}

/// `x <- A x + B u` in place for the common state counts (rigid 2-3, the
/// 5-DOF Excalibur 10-13); `false` for any other size.
fn affine_in_place(a: &[f64], b: &[f64], x: &mut [f64], u: [f64; 2]) -> bool {
    match x.len() {
        2 => affine_fixed_in_place::<2>(a, b, x, u),
        3 => affine_fixed_in_place::<3>(a, b, x, u),
        10 => affine_fixed_in_place::<10>(a, b, x, u),
        11 => affine_fixed_in_place::<11>(a, b, x, u),
        12 => affine_fixed_in_place::<12>(a, b, x, u),
        13 => affine_fixed_in_place::<13>(a, b, x, u),
        _ => false,
    }
}

fn column_major(m: &DMatrix<f64>) -> Vec<f64> {
    m.as_slice().to_vec()
}

impl Stepper {
    /// A stepper for `sys` with method `method` and sub-step `h` (s).
    pub fn new(sys: &System, method: Method, h: f64) -> Result<Self, Error> {
        let (ns, n) = (sys.states(), sys.n);
        let (a, b, e) = match method {
            Method::ExactZoh => {
                // exp([[A, B, E], [0, 0, 0]] h) = [[A_d, B_d, E_d], [0, I, 0]]
                let m = 2 + n;
                let mut blk = DMatrix::<f64>::zeros(ns + m, ns + m);
                blk.view_mut((0, 0), (ns, ns)).copy_from(&(&sys.a * h));
                blk.view_mut((0, ns), (ns, 2)).copy_from(&(&sys.b * h));
                blk.view_mut((0, ns + 2), (ns, n)).copy_from(&(&sys.e * h));
                let x = twoport_design::linalg::expm_balanced(&blk)?;
                (
                    column_major(&x.view((0, 0), (ns, ns)).into_owned()),
                    column_major(&x.view((0, ns), (ns, 2)).into_owned()),
                    column_major(&x.view((0, ns + 2), (ns, n)).into_owned()),
                )
            }
            _ => (
                column_major(&sys.a),
                column_major(&sys.b),
                column_major(&sys.e),
            ),
        };
        Ok(Stepper {
            method,
            h,
            ns,
            n,
            a,
            b,
            e,
            k: std::array::from_fn(|_| vec![0.0; ns]),
            tmp: vec![0.0; ns],
            force: vec![0.0; n],
        })
    }

    /// The method.
    pub fn method(&self) -> Method {
        self.method
    }

    /// `out = A x + B u + E f` (continuous) or the ZOH map, as a sum of
    /// columns (axpy form, which vectorises; the matrices are stored
    /// column-major).
    fn affine(&self, x: &[f64], u: [f64; 2], f: Option<&[f64]>, out: &mut [f64]) {
        // The common sizes (rigid 2-3 states, the 5-DOF Excalibur 10-11)
        // get fixed-size loops the compiler unrolls and vectorises.
        if f.is_none() {
            if let (Some(o), Some(x)) = (out.get_mut(..self.ns), x.get(..self.ns)) {
                o.copy_from_slice(x);
                if affine_in_place(&self.a, &self.b, o, u) {
                    return;
                }
            }
        }
        let ns = self.ns;
        let out = &mut out[..ns];
        let (b0, b1) = self.b.split_at(ns);
        for ((o, p), q) in out.iter_mut().zip(b0).zip(b1) {
            *o = p * u[0] + q * u[1];
        }
        for (col, xj) in self.a.chunks_exact(ns).zip(x) {
            for (o, c) in out.iter_mut().zip(col) {
                *o += c * xj;
            }
        }
        if let Some(f) = f {
            for (col, fj) in self.e.chunks_exact(ns).zip(f) {
                for (o, c) in out.iter_mut().zip(col) {
                    *o += c * fj;
                }
            }
        }
    }

    /// `out = f(x)` for the current method's map, with the nonlinear force
    /// (if any) evaluated at `x` into `force`.
    fn eval(
        &self,
        x: &[f64],
        u: [f64; 2],
        nl: &mut Option<Nonlinear<'_>>,
        force: &mut [f64],
        out: &mut [f64],
    ) {
        match nl {
            Some(g) => {
                force.fill(0.0);
                g(x, force);
                self.affine(x, u, Some(force), out);
            }
            None => self.affine(x, u, None, out),
        }
    }

    /// Advance `x` by one sub-step with the inputs `u` held. Nonlinear
    /// forces come from `nl` (called at every stage of the explicit
    /// methods, held over the sub-step by exact ZOH); `None` is the linear
    /// fast path.
    #[inline]
    pub fn step(&mut self, x: &mut [f64], u: [f64; 2], nl: Option<Nonlinear<'_>>) {
        // The linear scene's whole update is one affine map, in place for
        // the common sizes; it stays small enough to inline at the caller.
        if self.method == Method::ExactZoh && nl.is_none() {
            if let Some(x) = x.get_mut(..self.ns) {
                if affine_in_place(&self.a, &self.b, x, u) {
                    return;
                }
            }
        }
        self.step_general(x, u, nl);
    }

    #[inline(never)]
    fn step_general(&mut self, x: &mut [f64], u: [f64; 2], mut nl: Option<Nonlinear<'_>>) {
        let (ns, n, h) = (self.ns, self.n, self.h);
        if self.method == Method::ExactZoh && nl.is_none() {
            let mut y = std::mem::take(&mut self.tmp);
            self.affine(x, u, None, &mut y);
            x[..ns].copy_from_slice(&y[..ns]);
            self.tmp = y;
            return;
        }
        let mut k = std::mem::take(&mut self.k);
        let mut y = std::mem::take(&mut self.tmp);
        let mut force = std::mem::take(&mut self.force);
        match self.method {
            Method::ExactZoh => {
                self.eval(x, u, &mut nl, &mut force, &mut y);
                x.copy_from_slice(&y);
            }
            Method::Euler => {
                self.eval(x, u, &mut nl, &mut force, &mut y);
                for (xi, di) in x.iter_mut().zip(&y) {
                    *xi += h * di;
                }
            }
            Method::SemiImplicitEuler => {
                self.eval(x, u, &mut nl, &mut force, &mut y);
                // Velocities (and the filter) first, then positions with the
                // new velocities.
                for i in n..ns {
                    x[i] += h * y[i];
                }
                for i in 0..n {
                    x[i] += h * x[n + i];
                }
            }
            Method::Rk4 => {
                self.eval(x, u, &mut nl, &mut force, &mut k[0]);
                for (stage, c) in [(1usize, 0.5), (2, 0.5), (3, 1.0)] {
                    for i in 0..ns {
                        y[i] = x[i] + c * h * k[stage - 1][i];
                    }
                    let (_, rest) = k.split_at_mut(stage);
                    self.eval(&y, u, &mut nl, &mut force, &mut rest[0]);
                }
                for i in 0..ns {
                    x[i] += h / 6.0 * (k[0][i] + 2.0 * k[1][i] + 2.0 * k[2][i] + k[3][i]);
                }
            }
        }
        self.k = k;
        self.tmp = y;
        self.force = force;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The unrolled, vectorised kernel gives the bits of a plain scalar
    /// loop in the same order, for every size it takes, and refuses the
    /// others: vector lanes do the same IEEE operations, and nothing is
    /// fused or reordered.
    #[test]
    fn affine_kernel_matches_the_scalar_loop_bit_for_bit() {
        // Arbitrary values of mixed sign and size (a Weyl sequence).
        let mut i = 0u32;
        let mut next = move || {
            i += 1;
            (i as f64 * 0.618_033_988_749_895).fract() - 0.5
        };
        for ns in [2usize, 3, 10, 11, 12, 13] {
            let a: Vec<f64> = (0..ns * ns).map(|_| next()).collect();
            let b: Vec<f64> = (0..ns * 2).map(|_| next()).collect();
            let x0: Vec<f64> = (0..ns).map(|_| next() * 1e-3).collect();
            let u = [next() * 10.0, next() * 200.0];
            let mut want = vec![0.0; ns];
            for i in 0..ns {
                want[i] = b[i] * u[0] + b[ns + i] * u[1];
            }
            for j in 0..ns {
                for i in 0..ns {
                    want[i] += a[j * ns + i] * x0[j];
                }
            }
            let mut x = x0.clone();
            assert!(affine_in_place(&a, &b, &mut x, u), "{ns} states");
            let same = x.iter().zip(&want).all(|(p, q)| p.to_bits() == q.to_bits());
            assert!(same, "{ns} states: {x:?} != {want:?}");
        }
        let mut x = vec![0.0; 4];
        assert!(!affine_in_place(&[0.0; 16], &[0.0; 8], &mut x, [0.0; 2]));
    }
}
