//! A counterexample search on the exact sampled-data loop, independent of
//! the two-port analysis that proves a design.
//!
//! For one termination — a passive lumped hand at the handle and one of the
//! board's passive VEs — the whole interface is a linear discrete system:
//! the device and the hand, continuous, discretised exactly under the
//! zero-order hold; the control crate's own laws (their z-forms) on the
//! sampled encoder and load-cell signals. It is stable iff the spectral
//! radius of its one-tick transition matrix is below 1. [`verify`]
//! maximises that radius over the terminations' parameters: a sweep of
//! hand resonances from 1 Hz to well past Nyquist and of VE stiffnesses and
//! masses, then Nelder-Mead from the worst starts, in log space. It proves
//! nothing when it finds nothing; what it finds is a real instability.

use crate::design::{admittance_coupling_tf, impedance_coupling_tf, regulator_tf};
use crate::linalg::balance;
use crate::plant::{augmented, zoh};
use crate::rational::{add, delayed, from_tf, mul, realise, reduced, scale, Rational};
use crate::twoport::HumanBound;
use crate::DeviceModel;
use nalgebra::DMatrix;
use serde::Serialize;
use std::f64::consts::PI;
use twoport_control::ve::{VeTransfer, VirtualEnvironment};
use twoport_control::Position;

/// The gains under test (SI: N/m, N s/m, kg).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Gains {
    /// Impedance display: coupling `Z_cI = b + kTz/(z - 1)`.
    Impedance {
        /// Coupling stiffness (N/m).
        k_npm: f64,
        /// Coupling damping (N s/m).
        b_nspm: f64,
    },
    /// Admittance display: regulator `K_p`, coupling mass and damper.
    Admittance {
        /// Regulator stiffness (N/m).
        kp_npm: f64,
        /// Regulator damping (N s/m).
        bp_nspm: f64,
        /// Coupling mass (kg).
        m_kg: f64,
        /// Coupling damping (N s/m).
        b_nspm: f64,
    },
}

/// One of the board's passive VEs.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Ve {
    /// The bilateral constraint (`v_e = 0`).
    Constraint,
    /// A free cursor mass (backward Euler).
    Cursor {
        /// Mass (kg).
        mass_kg: f64,
    },
    /// A spring-damper to an anchor (backward Euler).
    Spring {
        /// Stiffness (N/m).
        stiffness_npm: f64,
        /// Damping (N s/m).
        damping_nspm: f64,
    },
    /// The lossless trapezoidal spring-damper.
    TrapezoidalSpring {
        /// Stiffness (N/m).
        stiffness_npm: f64,
        /// Damping (N s/m).
        damping_nspm: f64,
    },
}

/// A passive lumped hand: a mass with a spring and a damper from it to
/// ground. Without a grasp the mass is held rigidly at the handle; with one
/// (the paper's Fig. 3, when a human bound is set) it hangs from the handle
/// through the bound's spring and damper, so the hand's impedance is the
/// bound `Z_max` in series with the mass-spring-damper.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Hand {
    /// Mass (kg).
    pub mass_kg: f64,
    /// Spring to ground (N/m).
    pub stiffness_npm: f64,
    /// Damper to ground (N s/m).
    pub damping_nspm: f64,
    /// The grasp in series, `Z_max = b + k/s`, or none.
    pub grasp: Option<HumanBound>,
}

/// A hand and a VE.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Termination {
    /// At the handle.
    pub hand: Hand,
    /// At the VE port.
    pub ve: Ve,
}

/// The loop's one-tick growth for one termination.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Radius {
    /// Spectral radius of the closed loop's transition matrix.
    pub spectral_radius: f64,
    /// The dominant eigenvalue's frequency, `|arg λ| / (2π T)` (Hz).
    pub frequency_hz: f64,
    /// The largest eigenvalue modulus among the oscillating modes (above
    /// 0.1 Hz) and any mode outside the unit circle: what the search
    /// climbs, since the slow real modes of free motion (within 1e-5 of
    /// `z = 1` for a light cursor) would hide every resonance otherwise.
    #[serde(skip)]
    pub score: f64,
    /// Whether a mode grows by more than its numerical error: an
    /// oscillating mode past `1 + OSCILLATING_MARGIN`, a slow one past
    /// `1 + UNSTABLE_MARGIN`.
    pub unstable: bool,
}

impl Radius {
    /// The dominant mode's growth rate `ln ρ / T` (1/s): positive grows
    /// (by e in `1/rate` seconds), negative decays.
    pub fn growth_per_s(&self, period_s: f64) -> f64 {
        self.spectral_radius.ln() / period_s
    }
}

/// What the search found.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Verdict {
    /// Whether the worst termination makes the loop unstable: a mode grows
    /// by more than its numerical error (see [`Radius::unstable`]).
    pub unstable: bool,
    /// The worst spectral radius found.
    pub spectral_radius: f64,
    /// Its growth rate `ln ρ / T` (1/s; negative decays).
    pub growth_per_s: f64,
    /// Its frequency (Hz).
    pub frequency_hz: f64,
    /// The termination that gave it.
    pub termination: Termination,
    /// Closed loops evaluated.
    pub evaluations: usize,
}

/// A slow mode (below 0.1 Hz) this far above 1 counts as unstable: free
/// translation (a cursor VE with no hand) leaves an eigenvalue at exactly
/// 1, a double one with some VEs, which rounding splits by the square root
/// of the working precision's error and may put a few 1e-9 above it.
pub const UNSTABLE_MARGIN: f64 = 1e-6;

/// An oscillating mode this far above 1 counts as unstable. The loop's
/// transition matrix is balanced and its oscillating eigenvalues are
/// simple, so their moduli carry errors of order `n ε ‖A‖ κ`, about 1e-13
/// for these loops (measured: a radius computed from the matrix and from
/// its transpose agree to 1e-12 on every shipped device); 1e-10 keeps a
/// factor of 100 above that and still reports a mode that grows by e in
/// 10^7 ticks (about 3 hours at 1 kHz).
pub const OSCILLATING_MARGIN: f64 = 1e-10;

impl Ve {
    /// The VE's admittance `V/F` as `(num, den)`, from the board's own law.
    fn admittance(&self, t: f64) -> Result<Rational, String> {
        let p = Position::ZERO;
        let t32 = t as f32;
        let e = |e: twoport_control::ParamError| e.to_string();
        let tf = match *self {
            Ve::Constraint => return Ok((vec![0.0], vec![1.0])),
            Ve::Cursor { mass_kg } => VirtualEnvironment::<f32>::tf(
                &twoport_control::ve::CursorMass::new(mass_kg as f32, t32, p).map_err(e)?,
            ),
            Ve::Spring {
                stiffness_npm: k,
                damping_nspm: b,
            } => VirtualEnvironment::<f32>::tf(
                &twoport_control::ve::Spring::new(k as f32, b as f32, p, t32, p).map_err(e)?,
            ),
            Ve::TrapezoidalSpring {
                stiffness_npm: k,
                damping_nspm: b,
            } => VirtualEnvironment::<f32>::tf(
                &twoport_control::ve::TrapezoidalSpring::new(k as f32, b as f32, p, t32, p)
                    .map_err(e)?,
            ),
        };
        Ok(match tf {
            VeTransfer::Admittance(y) => from_tf(&y),
            VeTransfer::Impedance(z) => {
                let (n, d) = from_tf(&z);
                (d, n)
            }
        })
    }
}

/// The device with the hand, discretised under the ZOH from the actuator
/// force: `(A_d, b_d, c_xa, c_fm)` with outputs the actuator position `x_a`
/// (m) and the measured force `f_m` (N).
struct Sampled {
    ad: DMatrix<f64>,
    bd: Vec<f64>,
    c_xa: Vec<f64>,
    c_fm: Vec<f64>,
}

fn sampled(model: &DeviceModel, hand: &Hand, t: f64) -> Result<Sampled, String> {
    let n = model.dof();
    let grasp = hand.grasp;
    let nq = n + usize::from(grasp.is_some());
    let (mut m, mut d, mut k) = (
        DMatrix::<f64>::zeros(nq, nq),
        DMatrix::<f64>::zeros(nq, nq),
        DMatrix::<f64>::zeros(nq, nq),
    );
    m.view_mut((0, 0), (n, n)).copy_from(&model.m);
    d.view_mut((0, 0), (n, n)).copy_from(&model.d);
    k.view_mut((0, 0), (n, n)).copy_from(&model.k);
    // The hand acts through f_h's column of G on the handle x_h = C_v[0] q.
    let gh: Vec<f64> = (0..n).map(|i| model.g[(i, 0)]).collect();
    let ch: Vec<f64> = (0..n).map(|j| model.c_v[(0, j)]).collect();
    let (hm, hk, hb) = (hand.mass_kg, hand.stiffness_npm, hand.damping_nspm);
    match grasp {
        None => {
            for i in 0..n {
                for j in 0..n {
                    let gc = gh[i] * ch[j];
                    m[(i, j)] += hm * gc;
                    k[(i, j)] += hk * gc;
                    d[(i, j)] += hb * gc;
                }
            }
        }
        Some(g) => {
            let y = n;
            let (kg, bg) = (g.stiffness_npm, g.damping_nspm);
            m[(y, y)] = hm;
            for (mat, c, ground) in [(&mut k, kg, hk), (&mut d, bg, hb)] {
                for i in 0..n {
                    for j in 0..n {
                        mat[(i, j)] += c * gh[i] * ch[j];
                    }
                    mat[(i, y)] -= c * gh[i];
                    mat[(y, i)] -= c * ch[i];
                }
                mat[(y, y)] += c + ground;
            }
        }
    }
    let minv = m
        .clone()
        .try_inverse()
        .ok_or("the device with the hand has a singular mass matrix")?;
    let mut ga = DMatrix::<f64>::zeros(nq, 1);
    let mut c_f = DMatrix::<f64>::zeros(1, nq);
    for i in 0..n {
        ga[(i, 0)] = model.g[(i, 1)];
        c_f[(0, i)] = model.c_f[(0, i)];
    }
    let (a, b) = augmented(
        &(&minv * &k),
        &(&minv * &d),
        &(&minv * &ga),
        &c_f,
        model.load_cell_pole_rad_s,
    );
    let (ad, bd) = zoh(&a, &b, t)?;
    let na = ad.nrows();
    let bd = bd.column(0).iter().copied().collect();
    let mut c_xa = vec![0.0; na];
    for (j, c) in c_xa.iter_mut().take(n).enumerate() {
        // C_v's second row gives -v_a.
        *c = -model.c_v[(1, j)];
    }
    let mut c_fm = vec![0.0; na];
    c_fm[2 * nq] = 1.0;
    Ok(Sampled { ad, bd, c_xa, c_fm })
}

/// The controller as two SISO parts, `f_a = H_x(z) x_a + H_f(z) f_m`.
fn controller(
    gains: &Gains,
    ve: &Ve,
    t: f64,
    delay: usize,
) -> Result<(Rational, Rational), String> {
    let e = |e: twoport_control::ParamError| e.to_string();
    let (ny, dy) = ve.admittance(t)?;
    Ok(match *gains {
        Gains::Impedance { k_npm, b_nspm } => {
            let (nc, dc) = from_tf(&impedance_coupling_tf(k_npm, b_nspm, t).map_err(e)?);
            // f = Z_cI/(1 + Z_cI Y_e) v_c, v_c = (1 - z^-1)/T x_a.
            let num = delayed(&scale(&mul(&mul(&nc, &dy), &[1.0, -1.0]), 1.0 / t), delay);
            let den = add(&mul(&dc, &dy), &mul(&nc, &ny));
            (reduced(num, den), (vec![0.0], vec![1.0]))
        }
        Gains::Admittance {
            kp_npm,
            bp_nspm,
            m_kg,
            b_nspm,
        } => {
            let (nk, dk) = from_tf(&regulator_tf(kp_npm, bp_nspm, t).map_err(e)?);
            let (na, da) = from_tf(&admittance_coupling_tf(m_kg, b_nspm, t).map_err(e)?);
            // v_c = f_m/(Z_cA + Z_e), x_d = T/(1 - z^-1) v_c,
            // f_a = K_p (x_a - x_d).
            let hx = (delayed(&nk, delay), dk.clone());
            let num = delayed(&scale(&mul(&mul(&nk, &ny), &da), -t), delay);
            let den = mul(
                &mul(&dk, &[1.0, -1.0]),
                &add(&mul(&dy, &da), &mul(&na, &ny)),
            );
            (hx, reduced(num, den))
        }
    })
}

/// The closed loop's spectral radius for one termination.
pub fn radius(
    model: &DeviceModel,
    period_s: f64,
    gains: &Gains,
    term: &Termination,
    delay_samples: usize,
) -> Result<Radius, String> {
    let a = closed_loop(model, period_s, gains, term, delay_samples)?;
    Ok(judge(&a, period_s))
}

/// The closed loop's one-tick transition matrix for one termination,
/// balanced.
fn closed_loop(
    model: &DeviceModel,
    period_s: f64,
    gains: &Gains,
    term: &Termination,
    delay_samples: usize,
) -> Result<DMatrix<f64>, String> {
    let plant = sampled(model, &term.hand, period_s)?;
    let ((nx, dx), (nf, df)) = controller(gains, &term.ve, period_s, delay_samples)?;
    let (hx, hf) = (realise(&nx, &dx)?, realise(&nf, &df)?);
    let np = plant.ad.nrows();
    let (n1, n2) = (hx.a.nrows(), hf.a.nrows());
    let n = np + n1 + n2;
    let mut a = DMatrix::<f64>::zeros(n, n);
    // u = c1 s1 + c2 s2 + (d1 c_xa + d2 c_fm) x
    let feed: Vec<f64> = (0..np)
        .map(|j| hx.d * plant.c_xa[j] + hf.d * plant.c_fm[j])
        .collect();
    for i in 0..np {
        for j in 0..np {
            a[(i, j)] = plant.ad[(i, j)] + plant.bd[i] * feed[j];
        }
        for j in 0..n1 {
            a[(i, np + j)] = plant.bd[i] * hx.c[j];
        }
        for j in 0..n2 {
            a[(i, np + n1 + j)] = plant.bd[i] * hf.c[j];
        }
    }
    for (off, h, c) in [(np, &hx, &plant.c_xa), (np + n1, &hf, &plant.c_fm)] {
        let m = h.a.nrows();
        for i in 0..m {
            for j in 0..np {
                a[(off + i, j)] = h.b[i] * c[j];
            }
            for j in 0..m {
                a[(off + i, off + j)] = h.a[(i, j)];
            }
        }
    }
    if a.iter().any(|v| !v.is_finite()) {
        return Err("the closed loop is not finite".into());
    }
    // Balanced first: a light hand's node and the load-cell filter make the
    // entries span many orders of magnitude, which costs the eigenvalues
    // near z = 1 (free motion) digits enough to push them past 1.
    let d = balance(&a);
    Ok(DMatrix::from_fn(n, n, |i, j| a[(i, j)] * d[j] / d[i]))
}

/// The radius, and whether a mode grows, of the transition matrix `a`.
fn judge(a: &DMatrix<f64>, period_s: f64) -> Radius {
    let (mut rho, mut arg, mut score) = (0.0, 0.0, 0.0f64);
    let mut unstable = false;
    let slow = 2.0 * PI * 0.1 * period_s;
    for l in a.complex_eigenvalues().iter() {
        let th = l.im.atan2(l.re).abs();
        if l.norm() > rho {
            (rho, arg) = (l.norm(), th);
        }
        if th > slow || l.norm() > 1.0 + UNSTABLE_MARGIN {
            score = score.max(l.norm());
        }
        let margin = if th > slow {
            OSCILLATING_MARGIN
        } else {
            UNSTABLE_MARGIN
        };
        unstable |= l.norm() > 1.0 + margin;
    }
    Radius {
        spectral_radius: rho,
        frequency_hz: arg / (2.0 * PI * period_s),
        score,
        unstable,
    }
}

/// Which VE family a search point belongs to, and its log10 parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
enum VeKind {
    Constraint,
    Cursor,
    Spring,
    Trapezoidal,
}

impl VeKind {
    fn dims(self) -> usize {
        match self {
            VeKind::Constraint => 0,
            VeKind::Cursor => 1,
            VeKind::Spring | VeKind::Trapezoidal => 2,
        }
    }

    fn build(self, p: &[f64]) -> Ve {
        let x = |i: usize| 10f64.powf(p[i]);
        match self {
            VeKind::Constraint => Ve::Constraint,
            VeKind::Cursor => Ve::Cursor { mass_kg: x(0) },
            VeKind::Spring => Ve::Spring {
                stiffness_npm: x(0),
                damping_nspm: x(1),
            },
            VeKind::Trapezoidal => Ve::TrapezoidalSpring {
                stiffness_npm: x(0),
                damping_nspm: x(1),
            },
        }
    }

    /// log10 bounds of each parameter.
    fn bounds(self) -> &'static [(f64, f64)] {
        match self {
            VeKind::Constraint => &[],
            VeKind::Cursor => &[(-3.0, 3.0)],
            VeKind::Spring | VeKind::Trapezoidal => &[(1.0, 9.0), (-4.0, 4.0)],
        }
    }
}

/// log10 bounds of the hand's mass (kg), stiffness (N/m), damping (N s/m).
const HAND_BOUNDS: [(f64, f64); 3] = [(-4.0, 2.0), (-1.0, 10.0), (-4.0, 4.0)];

struct Search<'a> {
    model: &'a DeviceModel,
    t: f64,
    gains: Gains,
    grasp: Option<HumanBound>,
    delay: usize,
    evaluations: usize,
}

impl Search<'_> {
    fn termination(&self, kind: VeKind, p: &[f64]) -> Termination {
        let x = |i: usize| 10f64.powf(p[i]);
        Termination {
            hand: Hand {
                mass_kg: x(0),
                stiffness_npm: x(1),
                damping_nspm: x(2),
                grasp: self.grasp,
            },
            ve: kind.build(&p[3..]),
        }
    }

    /// The radius at `p` (clamped to the bounds); 0 where the loop cannot
    /// be built (a VE the board would refuse).
    fn eval(&mut self, kind: VeKind, p: &mut [f64]) -> Radius {
        for (x, (lo, hi)) in p.iter_mut().zip(HAND_BOUNDS.iter().chain(kind.bounds())) {
            *x = x.clamp(*lo, *hi);
        }
        self.evaluations += 1;
        let term = self.termination(kind, p);
        radius(self.model, self.t, &self.gains, &term, self.delay).unwrap_or(Radius {
            spectral_radius: 0.0,
            frequency_hz: 0.0,
            score: 0.0,
            unstable: false,
        })
    }

    /// Nelder-Mead on `-radius` from `start`.
    fn refine(&mut self, kind: VeKind, start: &[f64], iters: usize) -> (Vec<f64>, Radius) {
        let dim = start.len();
        let mut simplex: Vec<(Vec<f64>, Radius)> = Vec::with_capacity(dim + 1);
        let mut s0 = start.to_vec();
        let r0 = self.eval(kind, &mut s0);
        simplex.push((s0, r0));
        for i in 0..dim {
            let mut p = start.to_vec();
            p[i] += if i == 1 || i == 3 { 0.05 } else { 0.3 };
            let r = self.eval(kind, &mut p);
            simplex.push((p, r));
        }
        let key = |r: &Radius| -r.score;
        for _ in 0..iters {
            simplex.sort_by(|a, b| key(&a.1).total_cmp(&key(&b.1)));
            let worst = simplex[dim].clone();
            let centroid: Vec<f64> = (0..dim)
                .map(|j| simplex[..dim].iter().map(|s| s.0[j]).sum::<f64>() / dim as f64)
                .collect();
            let at = |c: f64| -> Vec<f64> {
                (0..dim)
                    .map(|j| centroid[j] + c * (worst.0[j] - centroid[j]))
                    .collect()
            };
            let mut xr = at(-1.0);
            let rr = self.eval(kind, &mut xr);
            if key(&rr) < key(&simplex[0].1) {
                let mut xe = at(-2.0);
                let re = self.eval(kind, &mut xe);
                simplex[dim] = if key(&re) < key(&rr) {
                    (xe, re)
                } else {
                    (xr, rr)
                };
            } else if key(&rr) < key(&simplex[dim - 1].1) {
                simplex[dim] = (xr, rr);
            } else {
                let mut xc = at(0.5);
                let rc = self.eval(kind, &mut xc);
                if key(&rc) < key(&worst.1) {
                    simplex[dim] = (xc, rc);
                } else {
                    let best = simplex[0].0.clone();
                    for s in simplex.iter_mut().skip(1) {
                        let mut p: Vec<f64> =
                            s.0.iter().zip(&best).map(|(x, b)| 0.5 * (x + b)).collect();
                        let r = self.eval(kind, &mut p);
                        *s = (p, r);
                    }
                }
            }
        }
        simplex.sort_by(|a, b| key(&a.1).total_cmp(&key(&b.1)));
        simplex.swap_remove(0)
    }
}

/// The device's inertia seen at the handle at `ω` (kg):
/// `Im(1/Y_hh(jω))/ω`, 0 where it cannot be had.
fn handle_inertia(model: &DeviceModel, w: f64) -> f64 {
    use num_complex::Complex64;
    let n = model.dof();
    let s = Complex64::new(0.0, w);
    let a = DMatrix::from_fn(n, n, |i, j| {
        model.m[(i, j)] * s * s + model.d[(i, j)] * s + model.k[(i, j)]
    });
    let g = DMatrix::from_fn(n, 1, |i, _| Complex64::new(model.g[(i, 0)], 0.0));
    let Some(x) = a.lu().solve(&g) else {
        return 0.0;
    };
    let y: Complex64 = (0..n)
        .map(|j| model.c_v[(0, j)] * x[(j, 0)])
        .sum::<Complex64>()
        * s;
    let m = y.inv().im / w;
    if m.is_finite() && m > 0.0 {
        m
    } else {
        0.0
    }
}

/// Search for the termination that makes `gains` least stable on
/// `model` at `period_s`. With `human`, hands are the bound in series with
/// a passive mass-spring-damper (the paper's Fig. 3); without, any passive
/// mass-spring-damper held at the handle.
pub fn verify(
    model: &DeviceModel,
    period_s: f64,
    gains: &Gains,
    human: Option<HumanBound>,
    delay_samples: usize,
) -> Result<Verdict, String> {
    if !(period_s.is_finite() && period_s > 0.0) {
        return Err(format!("period {period_s} s must be finite and > 0"));
    }
    let mut s = Search {
        model,
        t: period_s,
        gains: *gains,
        grasp: human,
        delay: delay_samples,
        evaluations: 0,
    };
    // Check the loop can be built at all (gains the board accepts).
    let off = [-4.0, -1.0, -4.0];
    radius(
        model,
        period_s,
        gains,
        &s.termination(VeKind::Constraint, &off),
        delay_samples,
    )?;
    let nyq_hz = 0.5 / period_s;
    let freqs: Vec<f64> = (0..24)
        .map(|i| (4.0 * nyq_hz).powf(i as f64 / 23.0))
        .collect();
    let mut hands: Vec<[f64; 3]> = vec![off];
    // Resonances across the band, and exactly at multiples of Nyquist,
    // where the sampled poles of the hand's resonance meet on the real
    // axis (the narrowest and worst hands): there the spring is tuned to
    // the hand's mass plus the device's inertia at the handle.
    let mut tuned: Vec<(f64, bool)> = freqs.iter().map(|f| (*f, false)).collect();
    tuned.extend((1..=8).map(|j| (j as f64 * nyq_hz, true)));
    for (f, exact) in tuned {
        let w = 2.0 * PI * f;
        let inertia = if exact && human.is_none() {
            handle_inertia(model, w)
        } else {
            0.0
        };
        for m in [-3.0, -2.0, -1.0, 0.0] {
            let k = (10f64.powf(m) + inertia) * w * w;
            hands.push([m, k.log10(), -2.0]);
        }
    }
    let mut ves: Vec<(VeKind, Vec<f64>)> = vec![(VeKind::Constraint, vec![])];
    for m in [-2.0, -1.0, 0.0, 1.0] {
        ves.push((VeKind::Cursor, vec![m]));
    }
    for i in 0..13 {
        let k = 2.0 + 0.5 * i as f64;
        ves.push((VeKind::Spring, vec![k, -2.0]));
        ves.push((VeKind::Trapezoidal, vec![k, -2.0]));
    }
    let mut starts: Vec<(f64, VeKind, Vec<f64>)> = Vec::new();
    for h in &hands {
        for (kind, vp) in &ves {
            let mut p: Vec<f64> = h.iter().chain(vp).copied().collect();
            let r = s.eval(*kind, &mut p);
            starts.push((r.score, *kind, p));
        }
    }
    starts.sort_by(|a, b| b.0.total_cmp(&a.0));
    // Refine the best starts of each VE family.
    let mut best: Option<(VeKind, Vec<f64>, Radius)> = None;
    for kind in [
        VeKind::Constraint,
        VeKind::Cursor,
        VeKind::Spring,
        VeKind::Trapezoidal,
    ] {
        for (_, _, p) in starts.iter().filter(|x| x.1 == kind).take(3) {
            let (q, r) = s.refine(kind, p, 60 * (3 + kind.dims()));
            let better = |b: &Radius| r.score > b.score || (r.unstable && !b.unstable);
            if best.as_ref().is_none_or(|b| better(&b.2)) {
                best = Some((kind, q, r));
            }
        }
    }
    let (kind, p, r) = best.ok_or("no termination could be built")?;
    Ok(Verdict {
        unstable: r.unstable,
        growth_per_s: r.growth_per_s(period_s),
        spectral_radius: r.spectral_radius,
        frequency_hz: r.frequency_hz,
        termination: s.termination(kind, &p),
        evaluations: s.evaluations,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rigid() -> DeviceModel {
        crate::model::rigid_for_tests(1.0, 20.0)
    }

    fn hands_off(ve: Ve) -> Termination {
        Termination {
            hand: Hand {
                mass_kg: 0.0,
                stiffness_npm: 0.0,
                damping_nspm: 0.0,
                grasp: None,
            },
            ve,
        }
    }

    /// Colgate's virtual wall on a rigid device, hands off: the exact loop
    /// `m x'' + b x' = -f`, `f = K x + B (1 - z^-1)/T x` under the ZOH has
    /// the closed-form stability boundary `K* = (b²/m)(1 - e^-x)/(1 - (1 +
    /// x) e^-x)`, `x = bT/m`, at `B = 0`; the radius crosses 1 there.
    #[test]
    fn rigid_wall_boundary_is_the_closed_form() {
        let (m, b, t) = (1.0f64, 20.0f64, 1e-3f64);
        let x = b * t / m;
        let k_star = (b * b / m) * (1.0 - (-x).exp()) / (1.0 - (1.0 + x) * (-x).exp());
        let rho = |k: f64| {
            radius(
                &rigid(),
                t,
                &Gains::Impedance {
                    k_npm: k,
                    b_nspm: 0.0,
                },
                &hands_off(Ve::Constraint),
                0,
            )
            .unwrap()
            .spectral_radius
        };
        assert!(rho(0.999 * k_star) < 1.0, "{}", rho(0.999 * k_star));
        assert!(rho(1.001 * k_star) > 1.0, "{}", rho(1.001 * k_star));
    }

    /// The oscillating modes' numerical error is far below
    /// [`OSCILLATING_MARGIN`]: the matrix and its transpose, whose
    /// eigenvalues are the same but whose rounding is not, give radii that
    /// agree to 1e-12, on every shipped device, for terminations on both
    /// sides of its designs.
    #[test]
    fn oscillating_radii_are_accurate_far_below_the_margin() {
        for model in crate::model::shipped_for_tests() {
            for (k, hand_hz, ve) in [
                (20_000.0, 80.0, Ve::Constraint),
                (60_000.0, 500.0, Ve::Cursor { mass_kg: 0.1 }),
                (
                    40_000.0,
                    30.0,
                    Ve::TrapezoidalSpring {
                        stiffness_npm: 1e5,
                        damping_nspm: 0.01,
                    },
                ),
            ] {
                let w: f64 = 2.0 * PI * hand_hz;
                let term = Termination {
                    hand: Hand {
                        mass_kg: 0.05,
                        stiffness_npm: 0.05 * w * w,
                        damping_nspm: 0.01,
                        grasp: Some(HumanBound::PAPER),
                    },
                    ve,
                };
                let g = Gains::Impedance {
                    k_npm: k,
                    b_nspm: 20.0,
                };
                let a = closed_loop(&model, 1e-3, &g, &term, 0).unwrap();
                let osc = |m: &DMatrix<f64>| {
                    m.complex_eigenvalues()
                        .iter()
                        .filter(|l| l.im.abs() > 1e-3)
                        .map(|l| l.norm())
                        .fold(0.0, f64::max)
                };
                let (r, rt) = (osc(&a), osc(&a.transpose()));
                assert!((r - rt).abs() < 1e-12, "{}: {r} vs {rt}", model.name);
            }
        }
    }

    /// The counterexample: at 40,000 N/m and 10 N s/m a passive
    /// hand (a small mass on a stiff spring, resonant near Nyquist) makes the
    /// rigid device unstable, though the paper's bound calls it proven.
    #[test]
    fn finds_the_rigid_counterexample() {
        let v = verify(
            &rigid(),
            1e-3,
            &Gains::Impedance {
                k_npm: 40_000.0,
                b_nspm: 10.0,
            },
            None,
            0,
        )
        .unwrap();
        assert!(v.unstable, "{v:?}");
        assert!(v.frequency_hz > 300.0, "{v:?}");
    }
}
