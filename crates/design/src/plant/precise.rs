//! The sampled terms `X_aa^d(z)`, `F_ma^d(z)` near DC, in double-double
//! arithmetic (about 32 digits).
//!
//! A device that floats (no spring to ground) has a double pole of
//! `X_aa^d` at `z = 1`, and the design inequality near DC is the small
//! difference of two terms that grow toward it. In `f64` the exponential
//! `A_d = e^{AT}` of a stiff device holds that double pole only to its
//! largest entries' rounding, which splits it, and the resolvent near `z =
//! 1` multiplies the split by `1/θ²`: at `T = 0.1` ms on a 7.3 kHz flexure
//! the bound at 0.05 Hz came out 4e-9 m/(N s) off where it is 4.5e-10. In
//! double-double, `M^-1 K`, the exponential and the solve keep the pole to
//! 1e-30 of the matrix, and the terms come back to `f64` rounding.

use crate::DeviceModel;
use nalgebra::DMatrix;
use num_complex::Complex64;
use std::ops::{Add, Div, Mul, Neg, Sub};

/// An unevaluated sum `hi + lo` with `|lo| <= ulp(hi)/2`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Dd {
    hi: f64,
    lo: f64,
}

/// `a + b` exactly as a sum of two doubles (Knuth's two-sum).
fn two_sum(a: f64, b: f64) -> Dd {
    let s = a + b;
    let bb = s - a;
    Dd {
        hi: s,
        lo: (a - (s - bb)) + (b - bb),
    }
}

impl Dd {
    const ZERO: Dd = Dd { hi: 0.0, lo: 0.0 };

    fn of(x: f64) -> Dd {
        Dd { hi: x, lo: 0.0 }
    }

    fn abs(self) -> f64 {
        self.hi.abs()
    }
}

impl Add for Dd {
    type Output = Dd;
    fn add(self, o: Dd) -> Dd {
        let s = two_sum(self.hi, o.hi);
        let t = two_sum(self.lo, o.lo);
        let v = two_sum(s.hi, s.lo + t.hi);
        two_sum(v.hi, v.lo + t.lo)
    }
}

impl Neg for Dd {
    type Output = Dd;
    fn neg(self) -> Dd {
        Dd {
            hi: -self.hi,
            lo: -self.lo,
        }
    }
}

impl Sub for Dd {
    type Output = Dd;
    fn sub(self, o: Dd) -> Dd {
        self + (-o)
    }
}

impl Mul for Dd {
    type Output = Dd;
    fn mul(self, o: Dd) -> Dd {
        // The product's rounding error, exactly, by a fused multiply-add.
        let p = self.hi * o.hi;
        let e = self.hi.mul_add(o.hi, -p);
        two_sum(p, e + (self.hi * o.lo + self.lo * o.hi))
    }
}

impl Div for Dd {
    type Output = Dd;
    fn div(self, o: Dd) -> Dd {
        // One Newton step on the f64 quotient.
        let q = self.hi / o.hi;
        let r = self - o * Dd::of(q);
        let q2 = r.hi / o.hi;
        two_sum(q, q2)
    }
}

/// A complex double-double.
#[derive(Clone, Copy, Debug, Default)]
struct Cdd {
    re: Dd,
    im: Dd,
}

impl Add for Cdd {
    type Output = Cdd;
    fn add(self, o: Cdd) -> Cdd {
        Cdd {
            re: self.re + o.re,
            im: self.im + o.im,
        }
    }
}

impl Sub for Cdd {
    type Output = Cdd;
    fn sub(self, o: Cdd) -> Cdd {
        Cdd {
            re: self.re - o.re,
            im: self.im - o.im,
        }
    }
}

impl Mul for Cdd {
    type Output = Cdd;
    fn mul(self, o: Cdd) -> Cdd {
        Cdd {
            re: self.re * o.re - self.im * o.im,
            im: self.re * o.im + self.im * o.re,
        }
    }
}

impl Div for Cdd {
    type Output = Cdd;
    fn div(self, o: Cdd) -> Cdd {
        let den = o.re * o.re + o.im * o.im;
        let num = self
            * Cdd {
                re: o.re,
                im: -o.im,
            };
        Cdd {
            re: num.re / den,
            im: num.im / den,
        }
    }
}

impl Cdd {
    fn real(x: Dd) -> Cdd {
        Cdd {
            re: x,
            im: Dd::ZERO,
        }
    }

    fn mag(self) -> f64 {
        self.re.abs() + self.im.abs()
    }

    fn of(z: Complex64) -> Cdd {
        Cdd {
            re: Dd::of(z.re),
            im: Dd::of(z.im),
        }
    }

    fn round(&self) -> Complex64 {
        Complex64::new(self.re.hi + self.re.lo, self.im.hi + self.im.lo)
    }
}

/// A square matrix, row-major.
type Mat = Vec<Dd>;

fn matmul(a: &Mat, b: &Mat, n: usize) -> Mat {
    let mut out = vec![Dd::ZERO; n * n];
    for i in 0..n {
        for k in 0..n {
            let aik = a[i * n + k];
            if aik.hi == 0.0 {
                continue;
            }
            for j in 0..n {
                out[i * n + j] = out[i * n + j] + aik * b[k * n + j];
            }
        }
    }
    out
}

/// `A^-1 B` for the `n`×`n` `A` and `n`×`cols` `B`, row-major (Gaussian
/// elimination with partial pivoting); `None` if a pivot is zero.
fn solve(mut a: Vec<Cdd>, mut x: Vec<Cdd>, n: usize, cols: usize) -> Option<Vec<Cdd>> {
    for c in 0..n {
        let p = (c..n).max_by(|&r, &s| a[r * n + c].mag().total_cmp(&a[s * n + c].mag()))?;
        if a[p * n + c].mag() == 0.0 {
            return None;
        }
        for k in 0..n {
            a.swap(c * n + k, p * n + k);
        }
        for k in 0..cols {
            x.swap(c * cols + k, p * cols + k);
        }
        for r in c + 1..n {
            let f = a[r * n + c] / a[c * n + c];
            for k in c..n {
                a[r * n + k] = a[r * n + k] - f * a[c * n + k];
            }
            for k in 0..cols {
                x[r * cols + k] = x[r * cols + k] - f * x[c * cols + k];
            }
        }
    }
    for c in (0..n).rev() {
        for k in 0..cols {
            let mut s = x[c * cols + k];
            for j in c + 1..n {
                s = s - a[c * n + j] * x[j * cols + k];
            }
            x[c * cols + k] = s / a[c * n + c];
        }
    }
    Some(x)
}

/// The real matrix `M^-1 B` in double-double.
fn solve_real(m: &[f64], b: &[f64], n: usize, cols: usize) -> Option<Mat> {
    let c = |v: &[f64]| v.iter().map(|&x| Cdd::real(Dd::of(x))).collect();
    Some(solve(c(m), c(b), n, cols)?.iter().map(|v| v.re).collect())
}

/// `A^-1 B` (`n`×`n`, `n`×`cols`, row-major) in double-double: an f64
/// LU of `A` rounded, refined with the residual `B - A X` taken in
/// double-double (mixed-precision iterative refinement). Rounding `A`
/// splits a double pole, so the LU alone keeps few digits near one, but
/// each step gains as many as it does keep, at the cost of a product
/// rather than an elimination; where the steps do not settle, Gaussian
/// elimination in double-double.
fn refined_solve(a: &[Cdd], b: &[Cdd], n: usize, cols: usize) -> Option<Vec<Cdd>> {
    let lu = DMatrix::from_fn(n, n, |i, j| a[i * n + j].round()).lu();
    let mut x = vec![Cdd::default(); n * cols];
    for _ in 0..REFINEMENTS {
        let r = DMatrix::from_fn(n, cols, |i, k| {
            let mut acc = b[i * cols + k];
            for j in 0..n {
                acc = acc - a[i * n + j] * x[j * cols + k];
            }
            acc.round()
        });
        let Some(d) = lu.solve(&r) else { break };
        let mut size = 0.0f64;
        for (i, xi) in x.iter_mut().enumerate() {
            *xi = *xi + Cdd::of(d[(i / cols, i % cols)]);
            size = size.max(xi.mag());
        }
        // (About 1e-24 is the residual's own rounding on a stiff device.)
        if d.iter().map(|v| v.norm()).fold(0.0, f64::max) <= 1e-20 * size {
            return Some(x);
        }
    }
    solve(a.to_vec(), b.to_vec(), n, cols)
}

/// Refinement steps before [`refined_solve`] falls back to elimination.
const REFINEMENTS: usize = 8;

/// `e^X` by scaling and squaring a Taylor series: `X/2^s` has norm at
/// most 1/2, where 30 terms leave 1e-40 of it.
fn expm(x: &Mat, n: usize) -> Option<Mat> {
    let norm = (0..n)
        .map(|i| (0..n).map(|j| x[i * n + j].abs()).sum::<f64>())
        .fold(0.0, f64::max);
    if !norm.is_finite() {
        return None;
    }
    let s = if norm > 0.5 {
        (norm / 0.5).log2().ceil() as i32
    } else {
        0
    };
    let scale = Dd::of(0.5f64.powi(s));
    let y: Mat = x.iter().map(|&v| v * scale).collect();
    let mut sum: Mat = (0..n * n)
        .map(|i| Dd::of(if i / n == i % n { 1.0 } else { 0.0 }))
        .collect();
    let mut term = sum.clone();
    for k in 1..=30 {
        term = matmul(&term, &y, n);
        let inv = Dd::of(1.0) / Dd::of(k as f64);
        for v in term.iter_mut() {
            *v = *v * inv;
        }
        for (a, t) in sum.iter_mut().zip(&term) {
            *a = *a + *t;
        }
    }
    for _ in 0..s {
        sum = matmul(&sum, &sum, n);
    }
    Some(sum)
}

/// `h` (`n`×`n`, row-major) to upper Hessenberg form by stabilised
/// elementary similarities (a row operation and its inverse on the
/// columns, the largest entry below the subdiagonal as the pivot), with
/// the input column `b` and the output rows `c` carried along, so `c (zI -
/// h)^-1 b` is unchanged.
fn hessenberg(h: &mut Mat, b: &mut [Dd], c: &mut [Vec<Dd>; 2], n: usize) {
    for k in 0..n.saturating_sub(2) {
        let Some(p) = (k + 1..n).max_by(|&r, &s| h[r * n + k].abs().total_cmp(&h[s * n + k].abs()))
        else {
            continue;
        };
        if h[p * n + k].abs() == 0.0 {
            continue;
        }
        if p != k + 1 {
            for j in 0..n {
                h.swap(p * n + j, (k + 1) * n + j);
            }
            for i in 0..n {
                h.swap(i * n + p, i * n + k + 1);
            }
            b.swap(p, k + 1);
            for row in c.iter_mut() {
                row.swap(p, k + 1);
            }
        }
        for i in k + 2..n {
            let f = h[i * n + k] / h[(k + 1) * n + k];
            if f.abs() == 0.0 {
                continue;
            }
            for j in k..n {
                h[i * n + j] = h[i * n + j] - f * h[(k + 1) * n + j];
            }
            b[i] = b[i] - f * b[k + 1];
            for r in 0..n {
                h[r * n + k + 1] = h[r * n + k + 1] + f * h[r * n + i];
            }
            for row in c.iter_mut() {
                row[k + 1] = row[k + 1] + f * row[i];
            }
        }
    }
}

/// The device's ZOH-exact state matrices in double-double, and the outputs
/// for `-x_a` and `f_m`.
#[derive(Clone, Debug)]
pub(super) struct Precise {
    /// Degrees of freedom.
    n: usize,
    /// `M`, `D`, `K` (row-major, `n`×`n`), `G` (`n`×2), `C_v` (2×`n`),
    /// `C_f` (1×`n`), as the model gives them.
    mdk: [Vec<f64>; 3],
    g: Vec<f64>,
    c_v: Vec<f64>,
    c_f: Vec<f64>,
    /// The load cell's pole (rad/s).
    pole: f64,
    /// The augmented state's size (`2n`, and the load cell's filter).
    na: usize,
    /// `A_d - I` reduced to upper Hessenberg form `H` by a similarity, so
    /// each frequency's solve costs O(na²); its input column and the
    /// output rows for `-x_a` and `f_m`, carried through the similarity.
    h: Mat,
    b: Vec<Dd>,
    c: [Vec<Dd>; 2],
}

impl Precise {
    /// The device at period `t` (s), its force delayed by `fraction` of
    /// the period inside the tick (the state then gains the previous
    /// tick's force, as `super::latched` builds it); `None` where `M` is
    /// singular or the exponential is not finite.
    pub(super) fn new(
        model: &DeviceModel,
        t: f64,
        fraction: f64,
        c_xa: &[f64],
        c_fm: &[f64],
    ) -> Option<Self> {
        let n = model.dof();
        let rm = |m: &nalgebra::DMatrix<f64>| -> Vec<f64> {
            (0..m.nrows())
                .flat_map(|r| (0..m.ncols()).map(move |c| m[(r, c)]))
                .collect()
        };
        let m = rm(&model.m);
        let minv_k = solve_real(&m, &rm(&model.k), n, n)?;
        let minv_d = solve_real(&m, &rm(&model.d), n, n)?;
        let gcols = model.g.ncols();
        let minv_g = solve_real(&m, &rm(&model.g), n, gcols)?;
        // [[A t, b t], [0, 0]] for the augmented state and the actuator's
        // column, as the f64 path builds them.
        let na = 2 * n + 1;
        let nb = na + 1;
        let p = model.load_cell_pole_rad_s;
        let block = |t: f64| {
            let tt = Dd::of(t);
            let mut x = vec![Dd::ZERO; nb * nb];
            for i in 0..n {
                x[i * nb + n + i] = tt;
                for j in 0..n {
                    x[(n + i) * nb + j] = -minv_k[i * n + j] * tt;
                    x[(n + i) * nb + n + j] = -minv_d[i * n + j] * tt;
                }
                x[(n + i) * nb + na] = minv_g[i * gcols + 1] * tt;
                x[2 * n * nb + i] = Dd::of(p * model.c_f[(0, i)]) * tt;
            }
            x[2 * n * nb + 2 * n] = Dd::of(-p) * tt;
            expm(&x, nb)
        };
        // `e^{A t}` and the held input's column, or with a latency `τ`
        // their product over `t - τ` and `τ` and the previous force's column.
        let (ad, b_now, b_prev): (Mat, Vec<Dd>, Option<Vec<Dd>>) = if fraction == 0.0 {
            let e = block(t)?;
            let ad = (0..na * na).map(|i| e[(i / na) * nb + i % na]).collect();
            (ad, (0..na).map(|r| e[r * nb + na]).collect(), None)
        } else {
            let rest = block(t - fraction * t)?;
            let tau = block(fraction * t)?;
            let prod = matmul(&rest, &tau, nb);
            let ad = (0..na * na).map(|i| prod[(i / na) * nb + i % na]).collect();
            let b_now = (0..na).map(|r| rest[r * nb + na]).collect();
            let b_prev = (0..na)
                .map(|r| (0..na).fold(Dd::ZERO, |acc, k| acc + rest[r * nb + k] * tau[k * nb + na]))
                .collect();
            (ad, b_now, Some(b_prev))
        };
        let size = na + usize::from(b_prev.is_some());
        let mut h: Mat = (0..size * size)
            .map(|i| {
                let (r, c) = (i / size, i % size);
                let a = match (&b_prev, r < na, c < na) {
                    (_, true, true) => ad[r * na + c],
                    (Some(bp), true, false) => bp[r],
                    _ => Dd::ZERO,
                };
                a - Dd::of(if r == c { 1.0 } else { 0.0 })
            })
            .collect();
        let mut b = b_now;
        if b_prev.is_some() {
            b.push(Dd::of(1.0));
        }
        // (The filter's state does not feed the mechanics: `-x_a` over
        // every state is `-x_a` over the mechanical ones.)
        let row = |c: &[f64]| {
            (0..size)
                .map(|j| Dd::of(c.get(j).copied().unwrap_or(0.0)))
                .collect()
        };
        let mut c = [row(c_xa), row(c_fm)];
        let na = size;
        hessenberg(&mut h, &mut b, &mut c, na);
        Some(Precise {
            n,
            mdk: [m, rm(&model.d), rm(&model.k)],
            g: rm(&model.g),
            c_v: rm(&model.c_v),
            c_f: rm(&model.c_f),
            pole: p,
            na,
            h,
            b,
            c,
        })
    }

    /// `(zI - A_d)^-1 b_d` at `z = e^{jθ}`, in the Hessenberg basis.
    fn resolvent(&self, theta: f64) -> Option<Vec<Cdd>> {
        let n = self.na;
        // `z - 1` from θ itself: `cos θ` rounded to f64 and less 1 keeps
        // only `ε/θ²` of it, which the double pole at `z = 1` magnifies.
        let half = (0.5 * theta).sin();
        let zm1 = Cdd {
            re: Dd::of(-2.0 * half) * Dd::of(half),
            im: Dd::of(theta.sin()),
        };
        let mut a: Vec<Cdd> = (0..n * n)
            .map(|i| {
                let d = if i / n == i % n { zm1 } else { Cdd::default() };
                d - Cdd::real(self.h[i])
            })
            .collect();
        let mut x: Vec<Cdd> = self.b.iter().map(|&v| Cdd::real(v)).collect();
        // Gaussian elimination of the one subdiagonal, the larger of each
        // adjacent pair as the pivot.
        for k in 0..n.saturating_sub(1) {
            if a[(k + 1) * n + k].mag() > a[k * n + k].mag() {
                for j in k..n {
                    a.swap(k * n + j, (k + 1) * n + j);
                }
                x.swap(k, k + 1);
            }
            if a[k * n + k].mag() == 0.0 {
                return None;
            }
            let f = a[(k + 1) * n + k] / a[k * n + k];
            for j in k + 1..n {
                a[(k + 1) * n + j] = a[(k + 1) * n + j] - f * a[k * n + j];
            }
            x[k + 1] = x[k + 1] - f * x[k];
        }
        for k in (0..n).rev() {
            let mut acc = x[k];
            for j in k + 1..n {
                acc = acc - a[k * n + j] * x[j];
            }
            if a[k * n + k].mag() == 0.0 {
                return None;
            }
            x[k] = acc / a[k * n + k];
        }
        Some(x)
    }

    /// `Y(jω)` and `F(jω)`, as `Plant::continuous` gives them: the
    /// dynamic stiffness `K - ω² M + jω D` of a floating stiff device is
    /// the large `K` less a small `ω² M` in its rigid direction, which
    /// `f64` keeps to `K`'s rounding only.
    pub(super) fn continuous(&self, omega: f64) -> ([[Complex64; 2]; 2], [Complex64; 2]) {
        let n = self.n;
        let w = Dd::of(omega);
        let w2 = w * w;
        let [m, d, k] = &self.mdk;
        let a: Vec<Cdd> = (0..n * n)
            .map(|i| Cdd {
                re: Dd::of(k[i]) - Dd::of(m[i]) * w2,
                im: Dd::of(d[i]) * w,
            })
            .collect();
        let g: Vec<Cdd> = self.g.iter().map(|&v| Cdd::real(Dd::of(v))).collect();
        let nan = Complex64::new(f64::NAN, f64::NAN);
        let Some(x) = refined_solve(&a, &g, n, 2) else {
            return ([[nan; 2]; 2], [nan; 2]);
        };
        let s = Cdd {
            re: Dd::ZERO,
            im: w,
        };
        let mut y = [[Complex64::new(0.0, 0.0); 2]; 2];
        let mut f = [Complex64::new(0.0, 0.0); 2];
        let filt = self.pole / (Complex64::new(0.0, omega) + self.pole);
        for col in 0..2 {
            for (row, y_row) in y.iter_mut().enumerate() {
                let mut acc = Cdd::default();
                for j in 0..n {
                    acc = acc + Cdd::real(Dd::of(self.c_v[row * n + j])) * x[j * 2 + col];
                }
                y_row[col] = (acc * s).round();
            }
            let mut acc = Cdd::default();
            for j in 0..n {
                acc = acc + Cdd::real(Dd::of(self.c_f[j])) * x[j * 2 + col];
            }
            f[col] = acc.round() * filt;
        }
        (y, f)
    }

    /// `(X_aa^d(z), F_ma^d(z))` at `z = e^{jθ}`. The load cell's filter
    /// state does not feed the mechanics, so one solve gives both.
    pub(super) fn eval(&self, theta: f64) -> (Complex64, Complex64) {
        let Some(x) = self.resolvent(theta) else {
            let nan = Complex64::new(f64::NAN, f64::NAN);
            return (nan, nan);
        };
        let dot = |c: &[Dd]| {
            c.iter()
                .zip(&x)
                .fold(Cdd::default(), |acc, (c, x)| acc + Cdd::real(*c) * *x)
                .round()
        };
        (dot(&self.c[0]), dot(&self.c[1]))
    }
}
