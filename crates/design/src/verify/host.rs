//! The independent check of a host VE's two-rate loop: the exact periodic
//! loop, stepped tick by tick over one host period, and a search of hands
//! for the one that makes it grow fastest.
//!
//! One tick, at phase `j` of the host's period: the board's coupling law
//! (its z-form, realised) on the encoder and the VE point; the VE point the
//! mean of the host's held positions `d` to `d + N - 1` ticks back (the
//! board's ramp); the device and the hand under the zero-order hold; at
//! phase 0 the host's body stepped by its own recursion with this tick's
//! force. The loop is linear, so the `N` ticks of one host period compose
//! into one matrix (the monodromy matrix), whose spectral radius below 1
//! is stability. Nothing here uses the frequency-domain proof.

use super::closed_loop::{judge, sampled};
use super::{Hand, Radius};
use crate::analysis::impedance_coupling_tf;
use crate::host_ve::HostLoop;
use crate::linalg::balance;
use crate::network::HumanBound;
use crate::rational::{from_tf, mul, realise, reduced, scale};
use crate::DeviceModel;
use nalgebra::DMatrix;
use serde::Serialize;
use std::f64::consts::PI;

/// What the search of hands found against a host loop.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct HostVerdict {
    /// Whether the worst hand makes the loop grow (past the numerical
    /// margins of [`Radius::unstable`]).
    pub unstable: bool,
    /// The worst spectral radius over one host period.
    pub spectral_radius: f64,
    /// Its growth rate (1/s; negative decays).
    pub growth_per_s: f64,
    /// The hand that gave it.
    pub hand: Hand,
    /// Loops evaluated.
    pub evaluations: usize,
}

/// The one-host-period transition matrix of the two-rate loop with `hand`,
/// balanced.
pub fn monodromy(
    model: &DeviceModel,
    period_s: f64,
    (k, b): (f64, f64),
    hand: &Hand,
    host: &HostLoop,
) -> Result<DMatrix<f64>, String> {
    let plant = sampled(model, hand, period_s)?;
    let (nc, dc) = from_tf(&impedance_coupling_tf(k, b, period_s).map_err(|e| e.to_string())?);
    // f = Z_cI (1 - z^-1)/T (x_a - x_e).
    let (num, den) = reduced(scale(&mul(&nc, &[1.0, -1.0]), 1.0 / period_s), dc);
    let law = realise(&num, &den).map_err(|e| e.to_string())?;
    let n_ve = host.ve_period_ticks as usize;
    let d = host.delay_ticks as usize;
    let held = d + n_ve - 1;
    let late = model.lag(period_s).ticks as usize;
    let np = plant.ad.nrows();
    let nl = law.a.nrows();
    // [plant | law | body x, v | held positions τ[k-1..] | forces f[k-1..]]
    let (at_law, at_body) = (np, np + nl);
    let at_held = at_body + 2;
    let at_late = at_held + held;
    let dim = at_late + late;
    let body = host.body;
    let (m, bb, kb) = (
        f64::from(body.mass_kg()),
        f64::from(body.damping_nspm()),
        f64::from(body.stiffness_npm()),
    );
    let t_h = period_s * n_ve as f64;
    let a_h = t_h / m;
    let tick = |s: &[f64], phase: usize| -> Vec<f64> {
        let mut o = vec![0.0; dim];
        let xa: f64 = (0..np).map(|i| plant.c_xa[i] * s[i]).sum();
        let xe: f64 = (0..n_ve).map(|i| s[at_held + d - 1 + i]).sum::<f64>() / n_ve as f64;
        let e = xa - xe;
        let f: f64 = (0..nl).map(|i| law.c[i] * s[at_law + i]).sum::<f64>() + law.d * e;
        for i in 0..nl {
            o[at_law + i] =
                (0..nl).map(|j| law.a[(i, j)] * s[at_law + j]).sum::<f64>() + law.b[i] * e;
        }
        let u = if late == 0 { f } else { s[at_late + late - 1] };
        if late > 0 {
            o[at_late] = f;
            o[at_late + 1..at_late + late].copy_from_slice(&s[at_late..at_late + late - 1]);
        }
        for (i, x) in o.iter_mut().enumerate().take(np) {
            *x = (0..np).map(|j| plant.ad[(i, j)] * s[j]).sum::<f64>() + plant.bd[i] * u;
        }
        let (mut xb, mut vb) = (s[at_body], s[at_body + 1]);
        if phase == 0 {
            vb = (vb + a_h * (f - kb * xb)) / (1.0 + a_h * bb);
            xb += t_h * vb;
        }
        o[at_body] = xb;
        o[at_body + 1] = vb;
        o[at_held] = xb;
        o[at_held + 1..at_held + held].copy_from_slice(&s[at_held..at_held + held - 1]);
        o
    };
    let mut a = DMatrix::<f64>::zeros(dim, dim);
    for c in 0..dim {
        let mut s = vec![0.0; dim];
        s[c] = 1.0;
        for phase in 0..n_ve {
            s = tick(&s, phase);
        }
        for (r, v) in s.iter().enumerate() {
            a[(r, c)] = *v;
        }
    }
    if a.iter().any(|v| !v.is_finite()) {
        return Err("the two-rate loop is not finite".into());
    }
    let w = balance(&a);
    Ok(DMatrix::from_fn(dim, dim, |i, j| a[(i, j)] * w[j] / w[i]))
}

/// The two-rate loop's growth over one host period with `hand`.
pub fn host_radius(
    model: &DeviceModel,
    period_s: f64,
    coupling: (f64, f64),
    hand: &Hand,
    host: &HostLoop,
) -> Result<Radius, String> {
    let a = monodromy(model, period_s, coupling, hand, host)?;
    Ok(judge(&a, period_s * f64::from(host.ve_period_ticks)))
}

/// log10 bounds of the hand's mass (kg), stiffness (N/m), damping (N s/m).
const HAND_BOUNDS: [(f64, f64); 3] = [(-4.0, 2.0), (-1.0, 10.0), (-4.0, 4.0)];

/// Search hands (behind `human`'s grasp where given) for the one that
/// makes the coupling `(k, b)` against `host` grow fastest: a sweep of
/// resonances across the band and of heavy hands tuned to the coupling's
/// spring, then Nelder-Mead from the worst few.
pub fn verify_host(
    model: &DeviceModel,
    period_s: f64,
    (k, b): (f64, f64),
    human: Option<HumanBound>,
    host: &HostLoop,
) -> Result<HostVerdict, crate::Error> {
    let err = |why: String| crate::Error::Verify {
        model: model.name.clone(),
        why,
    };
    let hand = |p: &[f64]| Hand {
        mass_kg: 10f64.powf(p[0]),
        stiffness_npm: 10f64.powf(p[1]),
        damping_nspm: 10f64.powf(p[2]),
        grasp: human,
        hanging: Vec::new(),
    };
    let mut evaluations = 0;
    let mut eval = |p: &mut Vec<f64>| -> Radius {
        for (x, (lo, hi)) in p.iter_mut().zip(HAND_BOUNDS) {
            *x = x.clamp(lo, hi);
        }
        evaluations += 1;
        host_radius(model, period_s, (k, b), &hand(p), host).unwrap_or(Radius {
            spectral_radius: 0.0,
            frequency_hz: 0.0,
            score: 0.0,
            unstable: false,
        })
    };
    // The loop must be buildable at all.
    host_radius(model, period_s, (k, b), &hand(&[-4.0, -1.0, -4.0]), host).map_err(err)?;
    let nyq = 0.5 / period_s;
    let mut starts: Vec<Vec<f64>> = vec![vec![-4.0, -1.0, -4.0]];
    for i in 0..24 {
        let w = 2.0 * PI * (4.0 * nyq).powf(f64::from(i) / 23.0);
        for m in [-3.0, -2.0, -1.0, 0.0] {
            starts.push(vec![m, (10f64.powf(m) * w * w).log10(), -2.0]);
        }
        // A hand heavy enough to ring on the coupling's spring at w, held
        // by a weak spring: the resonance the host's delay feeds.
        let m = (k / (w * w)).log10();
        starts.push(vec![m, (0.01 * k).log10(), -2.0]);
    }
    let mut scored: Vec<(f64, Vec<f64>)> = starts
        .into_iter()
        .map(|mut p| {
            let r = eval(&mut p);
            (r.score, p)
        })
        .collect();
    scored.sort_by(|a, b| b.0.total_cmp(&a.0));
    let mut best: Option<(Vec<f64>, Radius)> = None;
    for (_, p) in scored.iter().take(4) {
        let step = |i: usize| if i == 1 { 0.05 } else { 0.3 };
        let (q, r) = super::simplex::maximise(p, step, 60, &mut eval, |r| r.score);
        if best.as_ref().is_none_or(|b| r.score > b.1.score) {
            best = Some((q, r));
        }
    }
    let (p, r) = best.expect("at least one start");
    let t_h = period_s * f64::from(host.ve_period_ticks);
    Ok(HostVerdict {
        unstable: r.unstable,
        spectral_radius: r.spectral_radius,
        growth_per_s: r.spectral_radius.ln() / t_h,
        hand: hand(&p),
        evaluations,
    })
}
