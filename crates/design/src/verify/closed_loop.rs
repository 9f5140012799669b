//! The exact discrete closed loop of one termination: the device and hand
//! under the zero-order hold, the control crate's laws on the sampled
//! signals, and the VE; its transition matrix and what its eigenvalues say.

use super::{Gains, Hand, Radius, Termination, Ve, OSCILLATING_MARGIN, UNSTABLE_MARGIN};
use crate::analysis::{admittance_coupling_tf, impedance_coupling_tf, regulator_tf};
use crate::linalg::balance;
use crate::plant::{augmented, padded, DelayedHold};
use crate::rational::{add, delayed, from_tf, mul, realise, reduced, scale, Rational};
use crate::DeviceModel;
use nalgebra::DMatrix;
use std::f64::consts::PI;
use twoport_control::ve::{VeTransfer, VirtualEnvironment};
use twoport_control::Position;

impl Ve {
    /// The VE's admittance `V/F` as `(num, den)`, from the board's own law.
    pub(super) fn admittance(&self, t: f64) -> Result<Rational, String> {
        let p = Position::ZERO;
        let t32 = t as f32;
        let e = |e: twoport_control::ParamError| e.to_string();
        let tf = match *self {
            Ve::Constraint => return Ok((vec![0.0], vec![1.0])),
            Ve::LosslessMass { mass_kg } => VirtualEnvironment::<f32>::tf(
                &twoport_control::ve::LosslessCursor::new(mass_kg as f32, t32, p).map_err(e)?,
            ),
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
            } => VirtualEnvironment::<f32>::tf(&twoport_control::ve::TrapezoidalSpring::from(
                twoport_control::ve::Spring::new(k as f32, b as f32, p, t32, p).map_err(e)?,
            )),
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
/// (m) and the measured force `f_m` (N). With a latency inside the tick the
/// hold is delayed by it, and the last state is the previous tick's force.
pub(super) struct Sampled {
    pub(super) ad: DMatrix<f64>,
    pub(super) bd: Vec<f64>,
    pub(super) c_xa: Vec<f64>,
    c_fm: Vec<f64>,
}

impl Sampled {
    /// The measured force's output row.
    pub(super) fn c_fm(&self) -> &[f64] {
        &self.c_fm
    }
}

pub(super) fn sampled(model: &DeviceModel, hand: &Hand, t: f64) -> Result<Sampled, String> {
    let n = model.dof();
    let grasp = hand.grasp;
    let ny = n + usize::from(grasp.is_some());
    let nq = ny + hand.hanging.len();
    let (mut m, mut d, mut k) = (
        DMatrix::<f64>::zeros(nq, nq),
        DMatrix::<f64>::zeros(nq, nq),
        DMatrix::<f64>::zeros(nq, nq),
    );
    m.view_mut((0, 0), (n, n)).copy_from(&model.m);
    d.view_mut((0, 0), (n, n)).copy_from(&model.d);
    k.view_mut((0, 0), (n, n)).copy_from(&model.k);
    // The hand acts through f_h's column of G on the handle x_h = C_v[0] q.
    let mut gh = vec![0.0; nq];
    let mut ch = vec![0.0; nq];
    for i in 0..n {
        (gh[i], ch[i]) = (model.g[(i, 0)], model.c_v[(0, i)]);
    }
    // Where the hand's mass sits: at the handle, or on the grasp's own
    // coordinate.
    let (mut gp, mut cp) = (gh.clone(), ch.clone());
    if grasp.is_some() {
        (gp, cp) = (vec![0.0; nq], vec![0.0; nq]);
        (gp[n], cp[n]) = (1.0, 1.0);
    }
    // A spring or damper `c` between two points (forces through `g_*`,
    // positions `c_*`): `c (g_1 - g_2)(c_1 - c_2)^T`.
    let link = |mat: &mut DMatrix<f64>, c: f64, one: (&[f64], &[f64]), two: (&[f64], &[f64])| {
        for i in 0..nq {
            for j in 0..nq {
                mat[(i, j)] += c * (one.0[i] - two.0[i]) * (one.1[j] - two.1[j]);
            }
        }
    };
    let none = vec![0.0; nq];
    let (hm, hk, hb) = (hand.mass_kg, hand.stiffness_npm, hand.damping_nspm);
    if let Some(g) = grasp {
        m[(n, n)] = hm;
        link(&mut k, g.stiffness_npm, (&gh, &ch), (&gp, &cp));
        link(&mut d, g.damping_nspm, (&gh, &ch), (&gp, &cp));
    } else {
        link(&mut m, hm, (&gp, &cp), (&none, &none));
    }
    link(&mut k, hk, (&gp, &cp), (&none, &none));
    link(&mut d, hb, (&gp, &cp), (&none, &none));
    for (i, r) in hand.hanging.iter().enumerate() {
        let mut unit = vec![0.0; nq];
        unit[ny + i] = 1.0;
        m[(ny + i, ny + i)] = r.mass_kg;
        link(&mut k, r.stiffness_npm, (&gp, &cp), (&unit, &unit));
        link(&mut d, r.damping_nspm, (&gp, &cp), (&unit, &unit));
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
    // The force held from `τ` after the sample, the previous tick's before
    // it: the state gains that force where the model has a latency.
    let hold = DelayedHold::new(&a, &b.column(0).into_owned(), t, model.lag(t).fraction)?;
    let na = hold.ad.nrows();
    let mut c_xa = vec![0.0; na];
    for (j, c) in c_xa.iter_mut().take(n).enumerate() {
        // C_v's second row gives -v_a.
        *c = -model.c_v[(1, j)];
    }
    let mut c_fm = vec![0.0; na];
    c_fm[2 * nq] = 1.0;
    let (ad, bd) = hold.latched();
    let (c_xa, c_fm) = (padded(&c_xa, ad.nrows()), padded(&c_fm, ad.nrows()));
    Ok(Sampled { ad, bd, c_xa, c_fm })
}

/// The device with the hand, from the actuator force to the sampled
/// actuator position and measured force, at `z`: `(P_x, P_f)` with
/// `P_x(z) = c_xa (zI - A_d)^-1 b_d` (m/N) and `P_f` the same through
/// `c_fm` (N/N).
pub(super) fn actuator_response(
    model: &DeviceModel,
    hand: &Hand,
    t: f64,
    z: num_complex::Complex64,
) -> Result<(num_complex::Complex64, num_complex::Complex64), String> {
    use num_complex::Complex64;
    let p = sampled(model, hand, t)?;
    let n = p.ad.nrows();
    let a = DMatrix::from_fn(n, n, |i, j| {
        let d = if i == j { z } else { Complex64::new(0.0, 0.0) };
        d - p.ad[(i, j)]
    });
    let b = DMatrix::from_fn(n, 1, |i, _| Complex64::new(p.bd[i], 0.0));
    let x = a
        .lu()
        .solve(&b)
        .ok_or("z is a pole of the sampled device")?;
    let through = |c: &[f64]| (0..n).map(|i| x[(i, 0)] * c[i]).sum();
    Ok((through(&p.c_xa), through(&p.c_fm)))
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
        Gains::Impedance(g) => {
            let (k, b) = (g.k_npm.into(), g.b_nspm.into());
            let (nc, dc) = from_tf(&impedance_coupling_tf(k, b, t).map_err(e)?);
            // f = Z_cI/(1 + Z_cI Y_e) v_c, v_c = (1 - z^-1)/T x_a.
            let num = delayed(&scale(&mul(&mul(&nc, &dy), &[1.0, -1.0]), 1.0 / t), delay);
            let den = add(&mul(&dc, &dy), &mul(&nc, &ny));
            (reduced(num, den), (vec![0.0], vec![1.0]))
        }
        Gains::Admittance(g) => {
            let (kp, bp) = (g.kp_npm.into(), g.bp_nspm.into());
            let (m, b) = (g.m_kg.into(), g.b_nspm.into());
            let (nk, dk) = from_tf(&regulator_tf(kp, bp, t).map_err(e)?);
            let (na, da) = from_tf(&admittance_coupling_tf(m, b, t).map_err(e)?);
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

/// The closed loop's one-tick transition matrix for one termination,
/// balanced.
pub(super) fn closed_loop(
    model: &DeviceModel,
    period_s: f64,
    gains: &Gains,
    term: &Termination,
) -> Result<DMatrix<f64>, String> {
    let plant = sampled(model, &term.hand, period_s)?;
    let delay = model.lag(period_s).ticks as usize;
    let ((nx, dx), (nf, df)) = controller(gains, &term.ve, period_s, delay)?;
    let realised = |n: &[f64], d: &[f64]| realise(n, d).map_err(|e| e.to_string());
    let (hx, hf) = (realised(&nx, &dx)?, realised(&nf, &df)?);
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
pub(super) fn judge(a: &DMatrix<f64>, period_s: f64) -> Radius {
    let (mut rho, mut arg, mut score) = (0.0, 0.0, 0.0f64);
    let mut unstable = false;
    let slow = 2.0 * PI * 0.1 * period_s;
    let Some(poles) = crate::linalg::eigenvalues(a) else {
        // Where the QR iteration does not settle, the radius still follows
        // from the powers of the matrix (its frequency does not: 0 says
        // unknown); where a number is not finite, nothing is proven.
        let rho = crate::linalg::spectral_radius_gelfand(a).unwrap_or(f64::INFINITY);
        return Radius {
            spectral_radius: rho,
            frequency_hz: 0.0,
            score: rho,
            unstable: rho > 1.0 + UNSTABLE_MARGIN,
        };
    };
    for l in &poles {
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
