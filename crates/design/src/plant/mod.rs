//! The device's frequency responses: the continuous `Y(s)`, `F(s)` by
//! complex LU, and the ZOH-exact discrete `X_aa^d(z)`, `F_ma^d(z)` from the
//! matrix exponential of the block matrix (docs/two-port.md, sampled terms).

mod features;
mod hold;
mod modal;
mod precise;

pub use features::Feature;
pub(crate) use hold::{augmented, padded, DelayedHold};

use modal::Modal;
use precise::Precise;

use crate::linalg::{balance, hessenberg_shift_solve, lu_solve};
use crate::model::Lag;
use crate::DeviceModel;
use nalgebra::{Cholesky, DMatrix};
use num_complex::Complex64;

/// Everything the two-port analysis needs about the device at one frequency.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlantPoint {
    /// Angular frequency `ω` (rad/s).
    pub omega: f64,
    /// Sample period `T` (s).
    pub period_s: f64,
    /// `s = jω`.
    pub s: Complex64,
    /// `z = e^{jωT}`.
    pub z: Complex64,
    /// Normalised zero-order hold `H = (1 - e^{-jωT}) / (jωT)`.
    pub hold: Complex64,
    /// `Y(jω)` (m/s per N): `[[Y_hh, Y_ha], [Y_ah, Y_aa]]`.
    pub y: [[Complex64; 2]; 2],
    /// `F(jω)` (N per N): `[F_mh, F_ma]`.
    pub f: [Complex64; 2],
    /// ZOH-exact held actuator force to sampled `-x_a`, `X_aa^d(z)` (m/N).
    pub xaa_d: Complex64,
    /// ZOH-exact held actuator force to sampled `f_m`, `F_ma^d(z)` (N/N).
    pub fma_d: Complex64,
    /// The device's measurement-to-actuation delay in whole ticks, `z^-d`
    /// (1 without one).
    pub delay: Complex64,
    /// The rest of the delay inside the tick, `τ = αT` (s): the held force
    /// changes `τ` after the tick's sample. `xaa_d` and `fma_d` include it
    /// (the modified z-transform); the held force's path to the handle
    /// takes [`latency`](Self::latency).
    pub latency_s: f64,
}

impl PlantPoint {
    /// `e^{-jωτ}`: the latency inside the tick on the held force's way to
    /// the handle (1 without one).
    pub fn latency(&self) -> Complex64 {
        self.latency_at(self.omega)
    }

    /// The same at another frequency `omega` (rad/s, any sign): at an
    /// alias the latency turns the held force by its own angle, a
    /// different one at each when `τ` is not a whole tick.
    pub fn latency_at(&self, omega: f64) -> Complex64 {
        if self.latency_s == 0.0 {
            Complex64::new(1.0, 0.0)
        } else {
            Complex64::from_polar(1.0, -omega * self.latency_s)
        }
    }
}

/// A single-input single-output discrete system `c (zI - H)^-1 b` with `H`
/// upper Hessenberg (similar to `A_d`), so each frequency costs O(n^2).
#[derive(Clone, Debug)]
struct Siso {
    n: usize,
    h: Vec<f64>,
    b: Vec<f64>,
    c: Vec<f64>,
}

impl Siso {
    fn new(a: DMatrix<f64>, b: Vec<f64>, c: Vec<f64>) -> Self {
        let n = a.nrows();
        // Balance first (d^-1 a d, d^-1 b, c d): the load-cell row makes A_d
        // span ten orders of magnitude, which costs the reduction digits.
        let d = balance(&a);
        let a = DMatrix::from_fn(n, n, |i, j| a[(i, j)] * d[j] / d[i]);
        let b: Vec<f64> = b.iter().zip(&d).map(|(x, di)| x / di).collect();
        let c: Vec<f64> = c.iter().zip(&d).map(|(x, di)| x * di).collect();
        let (q, h) = a.hessenberg().unpack();
        // a = q h q^T: c (zI - a)^-1 b = (c q) (zI - h)^-1 (q^T b).
        let qb: Vec<f64> = (0..n)
            .map(|i| (0..n).map(|k| q[(k, i)] * b[k]).sum())
            .collect();
        let cq: Vec<f64> = (0..n)
            .map(|j| (0..n).map(|k| c[k] * q[(k, j)]).sum())
            .collect();
        let mut hr = vec![0.0; n * n];
        for r in 0..n {
            for col in 0..n {
                // Below the subdiagonal is zero up to rounding; make it exact.
                hr[r * n + col] = if r > col + 1 { 0.0 } else { h[(r, col)] };
            }
        }
        Siso {
            n,
            h: hr,
            b: qb,
            c: cq,
        }
    }

    fn eval(&self, z: Complex64, work: &mut Scratch) -> Complex64 {
        let n = self.n;
        let y = &mut work.vec[..n];
        for (yi, bi) in y.iter_mut().zip(&self.b) {
            *yi = Complex64::new(*bi, 0.0);
        }
        if !hessenberg_shift_solve(&self.h, n, z, &mut work.mat[..n * n], y) {
            return Complex64::new(f64::INFINITY, 0.0);
        }
        y.iter().zip(&self.c).map(|(yi, ci)| yi * ci).sum()
    }
}

/// Reusable buffers for one thread's frequency evaluations.
#[derive(Clone, Debug, Default)]
pub struct Scratch {
    mat: Vec<Complex64>,
    vec: Vec<Complex64>,
}

/// A lightly damped mode of the device.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mode {
    /// Natural frequency (rad/s).
    pub omega_n: f64,
    /// Damping ratio.
    pub zeta: f64,
}

/// The device prepared for analysis at one sample period.
#[derive(Clone, Debug)]
pub struct Plant {
    n: usize,
    period_s: f64,
    pole: f64,
    m: Vec<f64>,
    d: Vec<f64>,
    k: Vec<f64>,
    g: Vec<f64>,
    c_v: Vec<f64>,
    c_f: Vec<f64>,
    xaa: Siso,
    fma: Siso,
    /// The augmented `A_d` (row-major), the actuator column of `B_d`, and
    /// the output rows for `-x_a` and `f_m`: kept for a second method.
    zoh: (usize, Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>),
    modal: Option<Modal>,
    /// The terms in double-double, for the limit toward DC.
    precise: Option<Precise>,
    modes: Vec<Mode>,
    discrete_angles: Vec<f64>,
    features: Vec<Feature>,
    lag: Lag,
}

fn row_major(a: &DMatrix<f64>) -> Vec<f64> {
    let mut v = Vec::with_capacity(a.len());
    for r in 0..a.nrows() {
        for c in 0..a.ncols() {
            v.push(a[(r, c)]);
        }
    }
    v
}

impl Plant {
    /// Prepare `model` for analysis at sample period `period_s` (s).
    ///
    /// # Examples
    ///
    /// ```
    /// use twoport_design::{DeviceModel, Plant};
    /// let p = Plant::new(&DeviceModel::excalibur()?, 1e-3)?;
    /// // The Excalibur's lightly damped modes: about 45, 79, 277 Hz and 3.5 kHz.
    /// assert_eq!(p.modes().len(), 4);
    /// assert!(Plant::new(&DeviceModel::excalibur()?, 0.0).is_err());
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn new(model: &DeviceModel, period_s: f64) -> Result<Self, crate::Error> {
        Self::build(model, period_s).map_err(|why| crate::Error::Dynamics {
            model: model.name.clone(),
            why,
        })
    }

    fn build(model: &DeviceModel, period_s: f64) -> Result<Self, String> {
        if !(period_s.is_finite() && period_s > 0.0) {
            return Err(format!("period {period_s} s must be finite and > 0"));
        }
        let n = model.dof();
        let chol = Cholesky::new(model.m.clone()).ok_or("M is not positive definite")?;
        let minv_k = chol.solve(&model.k);
        let minv_d = chol.solve(&model.d);
        let minv_g = chol.solve(&model.g);
        let p = model.load_cell_pole_rad_s;
        let na = 2 * n + 1;
        let (a, b) = augmented(&minv_k, &minv_d, &minv_g, &model.c_f, p);
        let lag = model.lag(period_s);
        let hold = DelayedHold::new(&a, &b.column(1).into_owned(), period_s, lag.fraction)?;
        // -x_a is C_v's second row applied to positions.
        let mut c_xa = vec![0.0; na];
        for (j, c) in c_xa.iter_mut().take(n).enumerate() {
            *c = model.c_v[(1, j)];
        }
        let mut c_fm = vec![0.0; na];
        c_fm[2 * n] = 1.0;
        // (The filter's state does not feed the mechanics: -x_a needs only
        // the mechanical states.)
        let (aq, bq) = hold.leading(2 * n).latched();
        let xaa = Siso::new(aq.clone(), bq, padded(&c_xa[..2 * n], aq.nrows()));
        let (al, bl) = hold.latched();
        let nl = al.nrows();
        let zoh = (
            nl,
            row_major(&al),
            bl.clone(),
            padded(&c_xa, nl),
            padded(&c_fm, nl),
        );
        let fma = Siso::new(al, bl, padded(&c_fm, nl));

        let a_q = a.view((0, 0), (2 * n, 2 * n)).into_owned();
        let unsettled = "the device's poles could not be found (a number is not finite, or the eigenvalue iteration did not settle)";
        let free_poles = crate::linalg::eigenvalues(&a_q).ok_or(unsettled)?;
        let mut modes: Vec<Mode> = free_poles
            .iter()
            .filter(|l| l.im > 0.0)
            .map(|l| Mode {
                omega_n: l.norm(),
                zeta: -l.re / l.norm(),
            })
            .collect();
        modes.sort_by(|x, y| x.omega_n.total_cmp(&y.omega_n));
        let discrete_poles = crate::linalg::eigenvalues(&hold.ad).ok_or(unsettled)?;
        let discrete_angles = discrete_poles
            .iter()
            .map(|l| l.im.atan2(l.re).abs())
            .filter(|t| *t > 0.0)
            .collect();
        let features = features::of(
            model,
            free_poles.as_slice(),
            discrete_poles.as_slice(),
            period_s,
        );
        let mut c_out = DMatrix::<f64>::zeros(3, na);
        for j in 0..n {
            c_out[(0, n + j)] = model.c_v[(0, j)];
            c_out[(1, n + j)] = model.c_v[(1, j)];
        }
        c_out[(2, 2 * n)] = 1.0;
        let modal = Modal::new(&a, &b, &c_out);
        let precise = Precise::new(model, period_s, lag.fraction, &c_xa, &c_fm);
        let mut plant = Plant {
            n,
            period_s,
            pole: p,
            m: row_major(&model.m),
            d: row_major(&model.d),
            k: row_major(&model.k),
            g: row_major(&model.g),
            c_v: row_major(&model.c_v),
            c_f: row_major(&model.c_f),
            xaa,
            fma,
            zoh,
            modal,
            precise,
            modes,
            discrete_angles,
            features,
            lag,
        };
        plant.keep_modal_if_exact();
        Ok(plant)
    }

    /// Keep the modal form only if it matches the LU to 1e-7 relative at
    /// log-spaced frequencies from 0.1 rad/s and at every mode below
    /// Nyquist. (On Excalibur the two agree to 1e-10 above 10 Hz; toward DC
    /// the rigid-body pole, within 1e-9 of zero, leaves a difference that
    /// grows to about 1e-8 at 0.02 Hz.)
    fn keep_modal_if_exact(&mut self) {
        let Some(modal) = &self.modal else { return };
        let nyq = self.nyquist();
        let mut checks = crate::analysis::log_grid(0.1, nyq, 40);
        checks.extend(self.modes.iter().map(|m| m.omega_n).filter(|w| *w < nyq));
        let mut work = self.scratch();
        let exact = checks.iter().all(|&w| {
            let (y, f) = self.continuous_lu(w, &mut work);
            let m = modal.eval(Complex64::new(0.0, w));
            let lu = [y[0][0], y[0][1], y[1][0], y[1][1], f[0], f[1]];
            let scale = lu.iter().map(|v| v.norm()).fold(0.0, f64::max);
            lu.iter()
                .zip(&m)
                .all(|(a, b)| (a - b).norm() <= 1e-7 * scale)
        });
        if !exact {
            self.modal = None;
        }
    }

    /// Whether `Y(s)`, `F(s)` are evaluated from the modal form (fast) or by
    /// LU at each frequency (the fallback for nearly defective models).
    pub fn uses_modal_form(&self) -> bool {
        self.modal.is_some()
    }

    /// The device's measurement-to-actuation delay at this period.
    pub fn lag(&self) -> Lag {
        self.lag
    }

    /// The sample period (s).
    pub fn period_s(&self) -> f64 {
        self.period_s
    }

    /// The Nyquist frequency `π/T` (rad/s).
    pub fn nyquist(&self) -> f64 {
        std::f64::consts::PI / self.period_s
    }

    /// The continuous modes, by natural frequency.
    pub fn modes(&self) -> &[Mode] {
        &self.modes
    }

    /// Angles of the discrete poles (rad/sample, in (0, π]): where the
    /// sampled terms resonate, aliased modes included.
    pub fn discrete_angles(&self) -> &[f64] {
        &self.discrete_angles
    }

    /// Every narrow feature of the design inequality's terms, in the base
    /// band: the free device's modes, the modes of the device with its
    /// handle held still and with it held by the paper's stiffest grasp
    /// (where `Re Y_hh` dips), each folded from wherever it sits, and the
    /// sampled device's discrete poles. A frequency grid that resolves each
    /// of these on the scale of its own half-width misses no dip of the
    /// inequality (see [`crate::analysis::grid`]).
    pub fn features(&self) -> &[Feature] {
        &self.features
    }

    /// Buffers sized for this plant.
    pub fn scratch(&self) -> Scratch {
        // (One more state for the previous tick's force, with a latency.)
        let na = 2 * self.n + 2;
        Scratch {
            mat: vec![Complex64::new(0.0, 0.0); na * na],
            vec: vec![Complex64::new(0.0, 0.0); na * 2],
        }
    }

    /// `Y(jω)` and `F(jω)`: from the modal form where it is exact,
    /// otherwise by LU.
    pub fn continuous(
        &self,
        omega: f64,
        work: &mut Scratch,
    ) -> ([[Complex64; 2]; 2], [Complex64; 2]) {
        match &self.modal {
            Some(m) => {
                let r = m.eval(Complex64::new(0.0, omega));
                ([[r[0], r[1]], [r[2], r[3]]], [r[4], r[5]])
            }
            None => self.continuous_lu(omega, work),
        }
    }

    /// The hand-side terms at `ω` (rad/s, > 0): `[Y_hh, Y_ha, Y_ah,
    /// F_mh]`, what the sampled-data bounds sum at every alias (the modal
    /// form's four of six residues, or the LU's).
    pub fn hand_terms(&self, omega: f64, work: &mut Scratch) -> [Complex64; 4] {
        match &self.modal {
            Some(m) => m.eval_hand(Complex64::new(0.0, omega)),
            None => {
                let (y, f) = self.continuous_lu(omega, work);
                [y[0][0], y[0][1], y[1][0], f[0]]
            }
        }
    }

    /// `Y(jω)` and `F(jω)` by one complex LU of `M s^2 + D s + K`.
    pub fn continuous_lu(
        &self,
        omega: f64,
        work: &mut Scratch,
    ) -> ([[Complex64; 2]; 2], [Complex64; 2]) {
        let n = self.n;
        let s = Complex64::new(0.0, omega);
        let s2 = s * s;
        let (a, x) = (&mut work.mat[..n * n], &mut work.vec[..n * 2]);
        for (i, ai) in a.iter_mut().enumerate() {
            *ai = self.m[i] * s2 + self.d[i] * s + self.k[i];
        }
        for (xi, gi) in x.iter_mut().zip(&self.g) {
            *xi = Complex64::new(*gi, 0.0);
        }
        let nan = Complex64::new(f64::NAN, f64::NAN);
        if !lu_solve(a, n, x, 2) {
            return ([[nan; 2]; 2], [nan; 2]);
        }
        let mut y = [[Complex64::new(0.0, 0.0); 2]; 2];
        let mut f = [Complex64::new(0.0, 0.0); 2];
        let filt = self.pole / (s + self.pole);
        for col in 0..2 {
            for (row, y_row) in y.iter_mut().enumerate() {
                let mut acc = Complex64::new(0.0, 0.0);
                for j in 0..n {
                    acc += self.c_v[row * n + j] * x[j * 2 + col];
                }
                y_row[col] = acc * s;
            }
            let mut acc = Complex64::new(0.0, 0.0);
            for j in 0..n {
                acc += self.c_f[j] * x[j * 2 + col];
            }
            f[col] = acc * filt;
        }
        (y, f)
    }

    /// All terms at `ω` (rad/s, 0 < ω <= π/T).
    pub fn at(&self, omega: f64, work: &mut Scratch) -> PlantPoint {
        let t = self.period_s;
        let s = Complex64::new(0.0, omega);
        let z = Complex64::from_polar(1.0, omega * t);
        let hold = (Complex64::new(1.0, 0.0) - z.inv()) / (s * t);
        let (y, f) = self.continuous(omega, work);
        PlantPoint {
            omega,
            period_s: t,
            s,
            z,
            hold,
            y,
            f,
            xaa_d: self.xaa.eval(z, work),
            fma_d: self.fma.eval(z, work),
            delay: z.powi(-(self.lag.ticks as i32)),
            latency_s: self.lag.fraction * t,
        }
    }

    /// [`at`](Self::at) with the device's terms in double-double
    /// arithmetic, rounded to `f64`: for the lowest frequencies, where the
    /// design inequality is the small difference of terms that grow toward
    /// DC. There a floating stiff device's terms in `f64` lose the rigid
    /// body's double pole at `z = 1` to its stiffness's rounding (see
    /// `precise`). `None` where the double-double model cannot be built.
    pub fn at_precise(&self, omega: f64, work: &mut Scratch) -> Option<PlantPoint> {
        let p = self.precise.as_ref()?;
        let mut point = self.at(omega, work);
        (point.y, point.f) = p.continuous(omega);
        (point.xaa_d, point.fma_d) = p.eval(omega * self.period_s);
        Some(point)
    }

    /// `X_aa^d` and `F_ma^d` alone at `omega` (rad/s), as [`at`](Self::at)
    /// gives them, without the continuous terms: what a fit evaluates
    /// thousands of times.
    pub fn sampled_at(&self, omega: f64, work: &mut Scratch) -> (Complex64, Complex64) {
        let z = Complex64::from_polar(1.0, omega * self.period_s);
        (self.xaa.eval(z, work), self.fma.eval(z, work))
    }

    /// The largest pole radius of the device under the position regulator
    /// `K_p` (the admittance display with the VE port held): the loop is
    /// stable iff it is < 1.
    pub fn regulated_pole_radius(&self, kp: &twoport_control::ZTransfer) -> f64 {
        match self.regulated_poles(kp) {
            Some(poles) => poles.iter().map(|l| l.norm()).fold(0.0, f64::max),
            None => f64::INFINITY,
        }
    }

    /// The narrow features the position regulator `K_p` adds to the
    /// admittance display's bound: its regulated loop's oscillating poles
    /// (the bound's terms divide by `1 + K_p X_aa^d`, which vanishes at
    /// them), with damping ratios below 0.05.
    pub fn regulated_features(&self, kp: &twoport_control::ZTransfer) -> Vec<Feature> {
        let poles = self.regulated_poles(kp).unwrap_or_default();
        features::of_discrete(&poles, self.period_s())
            .into_iter()
            .filter(|f| f.omega > 0.0 && f.half_width < 0.05 * f.omega)
            .collect()
    }

    /// The poles of the device under `K_p`, realised from its own z-domain
    /// form; `None` where it cannot be realised.
    fn regulated_poles(&self, kp: &twoport_control::ZTransfer) -> Option<Vec<Complex64>> {
        use crate::rational::{delayed, from_tf, realise};
        let n = self.xaa.n;
        // K_p z^-d in transposed direct form II.
        let (num, den) = from_tf(kp);
        let k = realise(&delayed(&num, self.lag.ticks as usize), &den).ok()?;
        let nk = k.b.len();
        let h = &self.xaa;
        let mut a = DMatrix::<f64>::zeros(n + nk, n + nk);
        for r in 0..n {
            for c in 0..n {
                // e = x_a - x_cmd = -(c x) with the VE port held.
                a[(r, c)] = h.h[r * n + c] - k.d * h.b[r] * h.c[c];
            }
            for j in 0..nk {
                a[(r, n + j)] = h.b[r] * k.c[j];
            }
        }
        for i in 0..nk {
            for c in 0..n {
                a[(n + i, c)] = -k.b[i] * h.c[c];
            }
            for j in 0..nk {
                a[(n + i, n + j)] = k.a[(i, j)];
            }
        }
        crate::linalg::eigenvalues(&a)
    }

    /// `X_aa^d` and `F_ma^d` at `ω` by a plain complex LU of `(zI - A_d)`
    /// on the augmented model: a second method for the Hessenberg path.
    pub fn sampled_by_lu(&self, omega: f64) -> (Complex64, Complex64) {
        let (na, ad, b, c_xa, c_fm) = &self.zoh;
        let na = *na;
        // The same balancing as the fast path: it is the data, not the
        // solver, that the two methods share.
        let dm = DMatrix::from_row_slice(na, na, ad);
        let d = balance(&dm);
        let ad: Vec<f64> = (0..na * na)
            .map(|i| ad[i] * d[i % na] / d[i / na])
            .collect();
        let b: Vec<f64> = b.iter().zip(&d).map(|(x, di)| x / di).collect();
        let c_xa: Vec<f64> = c_xa.iter().zip(&d).map(|(x, di)| x * di).collect();
        let c_fm: Vec<f64> = c_fm.iter().zip(&d).map(|(x, di)| x * di).collect();
        let z = Complex64::from_polar(1.0, omega * self.period_s);
        let mut m: Vec<Complex64> = (0..na * na)
            .map(|i| if i / na == i % na { z } else { Complex64::new(0.0, 0.0) } - ad[i])
            .collect();
        let mut x: Vec<Complex64> = b.iter().map(|v| Complex64::new(*v, 0.0)).collect();
        if !lu_solve(&mut m, na, &mut x, 1) {
            let inf = Complex64::new(f64::INFINITY, 0.0);
            return (inf, inf);
        }
        let dot = |c: &[f64]| x.iter().zip(c).map(|(a, b)| a * b).sum();
        (dot(&c_xa), dot(&c_fm))
    }

    /// All terms on a grid of angular frequencies (rad/s).
    pub fn response(&self, omegas: &[f64]) -> Vec<PlantPoint> {
        crate::par::map(omegas.len(), |i| self.at(omegas[i], &mut self.scratch()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn excalibur() -> Plant {
        let m =
            DeviceModel::from_toml(include_str!("../../../../models/excalibur.toml"), "x").unwrap();
        Plant::new(&m, 1e-3).unwrap()
    }

    /// `sampled_at` gives `at`'s sampled terms exactly, across the band.
    #[test]
    fn sampled_at_is_ats_sampled_terms() {
        let p = excalibur();
        let mut w = p.scratch();
        for i in 1..200 {
            let omega = p.nyquist() * i as f64 / 200.0;
            let full = p.at(omega, &mut w);
            assert_eq!(p.sampled_at(omega, &mut w), (full.xaa_d, full.fma_d));
        }
    }

    /// The paper's lightly damped modes: about 45, 79, 277 Hz and 3.5 kHz.
    #[test]
    fn excalibur_modes_are_the_papers() {
        let p = excalibur();
        let hz: Vec<f64> = p
            .modes()
            .iter()
            .map(|m| m.omega_n / (2.0 * std::f64::consts::PI))
            .collect();
        for want in [45.0, 79.0, 277.0, 3500.0] {
            assert!(
                hz.iter().any(|h| (h - want).abs() < 0.06 * want),
                "no mode near {want} Hz in {hz:?}"
            );
        }
    }

    /// The modal form and the LU are two methods for the same `Y`, `F`:
    /// on a dense grid, resonances and Nyquist included, they agree to 1e-7
    /// from 0.1 rad/s and to 1e-10 above 10 Hz.
    #[test]
    fn modal_form_agrees_with_lu_everywhere() {
        let p = excalibur();
        assert!(p.uses_modal_form());
        let mut w = p.scratch();
        let nyq = p.nyquist();
        let mut grid: Vec<f64> = (0..2000)
            .map(|i| 0.1 * (nyq / 0.1f64).powf(i as f64 / 1999.0))
            .collect();
        for m in p.modes() {
            grid.extend((0..50).map(|i| m.omega_n * (0.98 + 0.0008 * i as f64)));
        }
        for omega in grid.into_iter().filter(|w| *w <= nyq) {
            let (y, f) = p.continuous_lu(omega, &mut w);
            let (ym, fm) = p.continuous(omega, &mut w);
            let lu = [y[0][0], y[0][1], y[1][0], y[1][1], f[0], f[1]];
            let md = [ym[0][0], ym[0][1], ym[1][0], ym[1][1], fm[0], fm[1]];
            let scale = lu.iter().map(|v| v.norm()).fold(0.0, f64::max);
            let tol = if omega > 20.0 * std::f64::consts::PI {
                1e-10
            } else {
                1e-7
            };
            for (a, b) in lu.iter().zip(&md) {
                assert!(
                    (a - b).norm() <= tol * scale,
                    "at {omega} rad/s: LU {a}, modal {b}"
                );
            }
        }
    }

    /// The ZOH-exact `X_aa^d` matches the continuous `X_aa = Y_aa/s` at low
    /// frequency, where the hold's half-sample delay is negligible.
    #[test]
    fn discrete_term_agrees_with_continuous_at_low_frequency() {
        let p = excalibur();
        let mut w = p.scratch();
        let omega = 2.0 * std::f64::consts::PI * 0.5;
        let pt = p.at(omega, &mut w);
        let cont = pt.y[1][1] / pt.s * pt.hold;
        let rel = (pt.xaa_d - cont).norm() / cont.norm();
        assert!(rel < 1e-3, "X_aa^d {} vs {} ({rel:e})", pt.xaa_d, cont);
    }
}
