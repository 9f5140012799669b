//! The search for the termination that makes given gains least stable:
//! a sweep of hands and VEs, then Nelder-Mead from the worst starts.

use super::{construct, radius, Gains, Hand, Radius, Resonator, Termination, Ve, Verdict};
use crate::network::HumanBound;
use crate::DeviceModel;
use nalgebra::DMatrix;
use std::f64::consts::PI;

/// Which VE family a search point belongs to, and its log10 parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
enum VeKind {
    Constraint,
    Cursor,
    LosslessMass,
    Spring,
    Trapezoidal,
}

impl VeKind {
    fn dims(self) -> usize {
        match self {
            VeKind::Constraint => 0,
            VeKind::Cursor | VeKind::LosslessMass => 1,
            VeKind::Spring | VeKind::Trapezoidal => 2,
        }
    }

    fn build(self, p: &[f64]) -> Ve {
        let x = |i: usize| 10f64.powf(p[i]);
        match self {
            VeKind::Constraint => Ve::Constraint,
            VeKind::Cursor => Ve::Cursor { mass_kg: x(0) },
            VeKind::LosslessMass => Ve::LosslessMass { mass_kg: x(0) },
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
            VeKind::Cursor | VeKind::LosslessMass => &[(-3.0, 3.0)],
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
    evaluations: usize,
    /// Whether the hand has a second resonance (three more parameters
    /// after the first's).
    two: bool,
}

impl Search<'_> {
    /// Where the VE's parameters start in a search point.
    fn ve_at(&self) -> usize {
        if self.two {
            6
        } else {
            3
        }
    }

    fn termination(&self, kind: VeKind, p: &[f64]) -> Termination {
        let x = |i: usize| 10f64.powf(p[i]);
        Termination {
            hand: Hand {
                mass_kg: x(0),
                stiffness_npm: x(1),
                damping_nspm: x(2),
                grasp: self.grasp,
                hanging: if self.two {
                    vec![Resonator {
                        mass_kg: x(3),
                        stiffness_npm: x(4),
                        damping_nspm: x(5),
                    }]
                } else {
                    Vec::new()
                },
            },
            ve: kind.build(&p[self.ve_at()..]),
        }
    }

    /// The radius at `p` (clamped to the bounds); 0 where the loop cannot
    /// be built (a VE the board would refuse).
    fn eval(&mut self, kind: VeKind, p: &mut [f64]) -> Radius {
        let second: &[(f64, f64)] = if self.two { &HAND_BOUNDS } else { &[] };
        let bounds = HAND_BOUNDS.iter().chain(second).chain(kind.bounds());
        for (x, (lo, hi)) in p.iter_mut().zip(bounds) {
            *x = x.clamp(*lo, *hi);
        }
        self.evaluations += 1;
        let term = self.termination(kind, p);
        radius(self.model, self.t, &self.gains, &term).unwrap_or(Radius {
            spectral_radius: 0.0,
            frequency_hz: 0.0,
            score: 0.0,
            unstable: false,
        })
    }

    /// Nelder-Mead on `-radius` from `start`.
    fn refine(&mut self, kind: VeKind, start: &[f64], iters: usize) -> (Vec<f64>, Radius) {
        let (ve_at, two) = (self.ve_at(), self.two);
        // (Small steps in the stiffnesses that tune a resonance.)
        let step = |i: usize| {
            let tuning = i == 1 || i == ve_at || (two && i == 4);
            if tuning {
                0.05
            } else {
                0.3
            }
        };
        super::simplex::maximise(start, step, iters, |p| self.eval(kind, p), |r| r.score)
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

/// A hand held off the handle, as `[log m, log k, log b]`.
const HELD_OFF: [f64; 3] = [-4.0, -1.0, -4.0];

/// Search for the termination that makes `gains` least stable on
/// `model` at `period_s`. With `human`, hands are the bound in series with
/// a passive mass-spring-damper (the paper's Fig. 3); without, any passive
/// mass-spring-damper held at the handle.
pub fn verify(
    model: &DeviceModel,
    period_s: f64,
    gains: &Gains,
    human: Option<HumanBound>,
) -> Result<Verdict, crate::Error> {
    verify_near(model, period_s, gains, human, &[])
}

/// [`verify`], first at `binding_hz`: the frequencies where the proof
/// binds at these gains (the designer's check knows them). Hands resonant
/// there and at their aliases join the sweep, and the constructive search
/// tries them before the frequencies the sweep found: a counterexample
/// just past a tight design sits at the design's own binding frequency,
/// where a sweep of resonances may never land.
pub fn verify_near(
    model: &DeviceModel,
    period_s: f64,
    gains: &Gains,
    human: Option<HumanBound>,
    binding_hz: &[f64],
) -> Result<Verdict, crate::Error> {
    if !(period_s.is_finite() && period_s > 0.0) {
        return Err(crate::Error::Verify {
            model: model.name.clone(),
            why: format!("period {period_s} s must be finite and > 0"),
        });
    }
    let mut s = Search {
        model,
        t: period_s,
        gains: *gains,
        grasp: human,
        evaluations: 0,
        two: false,
    };
    // Check the loop can be built at all (gains the board accepts).
    radius(
        model,
        period_s,
        gains,
        &s.termination(VeKind::Constraint, &HELD_OFF),
    )?;
    let freqs = band(period_s);
    let hands = hand_starts(model, period_s, human, &freqs, binding_hz);
    let ves = ve_starts(gains, freqs.iter().chain(binding_hz));
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
    let mut finals: Vec<(f64, VeKind, Vec<f64>, f64)> = Vec::new();
    for kind in [
        VeKind::Constraint,
        VeKind::Cursor,
        VeKind::LosslessMass,
        VeKind::Spring,
        VeKind::Trapezoidal,
    ] {
        for (_, _, p) in starts.iter().filter(|x| x.1 == kind).take(3) {
            let (q, r) = s.refine(kind, p, 60 * (3 + kind.dims()));
            finals.push((r.score, kind, q.clone(), r.frequency_hz));
            let better = |b: &Radius| r.score > b.score || (r.unstable && !b.unstable);
            if best.as_ref().is_none_or(|b| better(&b.2)) {
                best = Some((kind, q, r));
            }
        }
    }
    finals.sort_by(|a, b| b.0.total_cmp(&a.0));
    let (kind, p, r) = best.ok_or_else(|| crate::Error::Verify {
        model: model.name.clone(),
        why: "no termination could be built".into(),
    })?;
    // The worst one-resonance hands seed the constructive search below.
    let seeds: Vec<Hand> = finals
        .iter()
        .take(5)
        .map(|(_, kind, p, _)| s.termination(*kind, p).hand)
        .collect();
    // Then, where nothing was found, hands with two resonances.
    let mut best = (kind, p, r, false);
    if !r.unstable {
        if let Some((kind, q, r)) = two_resonances(&mut s, &finals, period_s) {
            best = (kind, q, r, true);
        }
    }
    let (kind, p, r, two) = best;
    s.two = two;
    // The constructive search, from the worst hands found and a sweep of
    // its own, at the frequencies they bind.
    let mut freqs: Vec<f64> = binding_hz.to_vec();
    freqs.extend(finals.iter().take(5).map(|f| f.3));
    freqs.push(r.frequency_hz);
    let constructed = construct(model, period_s, *gains, human, &freqs, &seeds);
    Ok(Verdict {
        constructed,
        unstable: r.unstable,
        growth_per_s: r.growth_per_s(period_s),
        spectral_radius: r.spectral_radius,
        frequency_hz: r.frequency_hz,
        termination: s.termination(kind, &p),
        evaluations: s.evaluations,
    })
}

/// `f` (Hz) and the frequencies the sample rate `fs` folds onto it, up to
/// twice the rate: where a hand's resonance meets the loop's at `f`.
fn aliases(f: f64, fs: f64) -> [f64; 4] {
    [f, fs - f, fs + f, 2.0 * fs - f]
}

/// 24 frequencies log-spaced from 1 Hz to twice the sample rate (Hz).
fn band(period_s: f64) -> Vec<f64> {
    let nyq_hz = 0.5 / period_s;
    (0..24)
        .map(|i| (4.0 * nyq_hz).powf(i as f64 / 23.0))
        .collect()
}

/// The hands the search starts from, as `[log m, log k, log b]`: one held
/// off, and resonances across `freqs` and exactly at multiples of
/// Nyquist, where the sampled poles of the hand's resonance meet on the
/// real axis (the narrowest and worst hands), and at the proof's
/// `binding_hz` and their aliases: there the spring is tuned to the
/// hand's mass plus the device's inertia at the handle.
fn hand_starts(
    model: &DeviceModel,
    period_s: f64,
    human: Option<HumanBound>,
    freqs: &[f64],
    binding_hz: &[f64],
) -> Vec<[f64; 3]> {
    let nyq_hz = 0.5 / period_s;
    let mut hands: Vec<[f64; 3]> = vec![HELD_OFF];
    let mut tuned: Vec<(f64, bool)> = freqs.iter().map(|f| (*f, false)).collect();
    tuned.extend((1..=8).map(|j| (j as f64 * nyq_hz, true)));
    // The binding frequencies and their aliases, tuned to the device's
    // inertia there as at Nyquist's multiples.
    let fs = 2.0 * nyq_hz;
    for f in binding_hz.iter().filter(|f| f.is_finite() && **f > 0.0) {
        for alias in aliases(*f, fs) {
            if alias > 0.0 {
                tuned.push((alias, true));
                tuned.push((alias, false));
            }
        }
    }
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
    hands
}

/// The VEs the search starts from: each family across its range, and
/// VEs tuned to resonate with the coupling across `freqs`, as the hands
/// are: a mass on the impedance display's spring, a spring on the
/// admittance display's mass (the narrow terminations a coarse sweep
/// steps over).
fn ve_starts<'a>(gains: &Gains, freqs: impl Iterator<Item = &'a f64>) -> Vec<(VeKind, Vec<f64>)> {
    let mut ves: Vec<(VeKind, Vec<f64>)> = vec![(VeKind::Constraint, vec![])];
    for m in [-2.0, -1.0, 0.0, 1.0] {
        ves.push((VeKind::Cursor, vec![m]));
        ves.push((VeKind::LosslessMass, vec![m]));
    }
    for i in 0..13 {
        let k = 2.0 + 0.5 * i as f64;
        ves.push((VeKind::Spring, vec![k, -2.0]));
        ves.push((VeKind::Trapezoidal, vec![k, -2.0]));
    }
    for f in freqs {
        let w2 = (2.0 * PI * f).powi(2);
        match gains {
            Gains::Impedance(g) => {
                let m = (g.k_npm as f64 / w2).log10();
                ves.push((VeKind::Cursor, vec![m]));
                ves.push((VeKind::LosslessMass, vec![m]));
            }
            Gains::Admittance(g) => {
                let k = (g.m_kg as f64 * w2).log10();
                ves.push((VeKind::Spring, vec![k, -4.0]));
                ves.push((VeKind::Trapezoidal, vec![k, -4.0]));
            }
        }
    }
    ves
}

/// Hands with two resonances: the best one-resonance terminations
/// (`finals`, worst first, each with its frequency) with a second mass
/// tuned to the loop's worst frequency or one of its aliases (where the
/// sound bound lets the hand take its worst value at two frequencies at
/// once), refined in all their parameters. Only a counterexample is
/// returned: a radius climbed toward 1 by a nearly lossless hand mode of
/// its own says nothing.
fn two_resonances(
    s: &mut Search<'_>,
    finals: &[(f64, VeKind, Vec<f64>, f64)],
    period_s: f64,
) -> Option<(VeKind, Vec<f64>, Radius)> {
    s.two = true;
    let fs = 1.0 / period_s;
    let mut starts: Vec<(f64, VeKind, Vec<f64>)> = Vec::new();
    for (_, kind, p, f) in finals.iter().take(3) {
        for f2 in aliases(*f, fs) {
            let w2 = (2.0 * PI * f2.max(0.1)).powi(2);
            for m in [-3.0, -2.0, -1.0] {
                let k = (10f64.powf(m) * w2).log10();
                let mut q: Vec<f64> = p[..3].iter().chain(&[m, k, -4.0]).copied().collect();
                q.extend_from_slice(&p[3..]);
                let r = s.eval(*kind, &mut q);
                starts.push((r.score, *kind, q));
            }
        }
    }
    starts.sort_by(|a, b| b.0.total_cmp(&a.0));
    starts.iter().take(2).find_map(|(_, kind, p)| {
        let (q, r) = s.refine(*kind, p, 60 * (6 + kind.dims()));
        r.unstable.then_some((*kind, q, r))
    })
}
