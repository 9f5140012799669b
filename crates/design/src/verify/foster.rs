//! The hand the impedance display's proof fears, made real: at one
//! frequency, the value a passive hand would take at each alias to make
//! the loop least stable, realised as one lossless hand that takes those
//! values at the aliases that matter most.
//!
//! With the coupling `Z_cI`, the loop has a pole at `z = e^{jθ}` for some
//! passive VE iff `Re S >= 0` there (see [`super::construct`]), and `S`
//! is a sum over the aliases `ω_k = (θ + 2πk)/T` of the device loaded by
//! the hand at `ω_k`: the hand enters alias `k` only through
//! `w_k = 1/(Y_hh(jω_k) + y_g + y_k)`, with `y_g` the grasp's admittance
//! (0 without a human bound) and `y_k` the admittance of the hand behind
//! it. Its share of `S` is `Re(β_k w_k)`, and over every passive `y_k`,
//! `w_k` fills a disk through 0 of diameter `1/Re(Y_hh + y_g)`, whose
//! best point for the loop's instability is on its rim: a lossless hand,
//! `y_k = 1/(j X_k)`. The proof lets every alias take its own best point;
//! a lossless hand can take any reactances at any finite set of
//! frequencies (Foster), so this hand takes them at the aliases that
//! gain most, with one mass hanging on a spring just off each.

use super::{Hand, Resonator};
use crate::network::HumanBound;
use crate::Plant;
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64;
use std::f64::consts::PI;

/// How far out the aliases are searched for the ones that gain most.
const ALIASES: i32 = 256;

/// One alias's target: the hand's reactance there and what it gains.
struct Target {
    /// `|ω_k|` (rad/s).
    omega: f64,
    /// The reactance behind the grasp at `|ω_k|` (N s/m), `X` of
    /// `Z = jX`.
    reactance: f64,
    /// What taking it adds to `Re S` over a free handle.
    gain: f64,
}

/// The best lossless hand's reactance at each alias of `w` (rad/s) on
/// the impedance display, the greatest gains first; `c0` is
/// `z^{-d}(1 - z^{-1})/T²`, the factor the sampled position takes into
/// `S`.
fn targets(plant: &Plant, t: f64, grasp: Option<HumanBound>, w: f64, c0: Complex64) -> Vec<Target> {
    let mut work = plant.scratch();
    let ws = 2.0 * PI / t;
    // The latency inside the tick turns the held force at each alias by
    // that alias's own angle.
    let tau = plant.lag().fraction * t;
    let one = Complex64::new(1.0, 0.0);
    let mut out: Vec<Target> = (-ALIASES..=ALIASES)
        .filter_map(|k| {
            let omega = w + ws * f64::from(k);
            if omega == 0.0 {
                return None;
            }
            let mut h = plant.hand_terms(omega.abs(), &mut work);
            if omega < 0.0 {
                h = h.map(|v| v.conj());
            }
            let [yhh, yha, yah, _] = h;
            let s = Complex64::new(0.0, omega);
            let yg = grasp.map_or(Complex64::new(0.0, 0.0), |g| g.admittance(s));
            let r = (yhh + yg).re;
            let hold = (one - Complex64::from_polar(1.0, -omega * t)) / s;
            let latency = Complex64::from_polar(1.0, -omega * tau);
            let beta = c0 * latency * hold / s * yah * yha;
            let gain = (beta.re + beta.norm()) / (2.0 * r);
            if !(r > 0.0 && gain.is_finite() && gain > 0.0) {
                return None;
            }
            // The rim's best point, and the hand behind the grasp there.
            let best = (one + Complex64::from_polar(1.0, -beta.arg())) / (2.0 * r);
            let behind = best.inv() - yhh - yg;
            let reactance = -1.0 / behind.im;
            reactance.is_finite().then_some(Target {
                omega: omega.abs(),
                reactance: reactance * omega.signum(),
                gain,
            })
        })
        .collect();
    out.sort_by(|a, b| b.gain.total_cmp(&a.gain));
    out
}

/// A lossless hand of mass `mass_kg` with one mass hanging just off each
/// target frequency, solved so that its reactance is each target's
/// there: `X(ω) = m ω + Σ_j k_j ω/(Ω_j² - ω²)`, linear in the springs
/// once the resonances are placed. A resonance goes above its target
/// where the reactance must rise from the rest's, below where it must
/// fall, and is moved to the other side where its spring came out
/// negative.
fn realise(targets: &[Target], mass_kg: f64) -> Option<Vec<Resonator>> {
    let n = targets.len();
    // Each resonance within a tenth of the gap to its nearest neighbour.
    let room: Vec<f64> = targets
        .iter()
        .map(|a| {
            targets
                .iter()
                .filter(|b| !std::ptr::eq(a, *b))
                .map(|b| ((a.omega - b.omega) / a.omega).abs())
                .fold(1.0f64, f64::min)
                .min(1.0)
                * 0.1
        })
        .collect();
    let want = DVector::from_fn(n, |i, _| targets[i].reactance - mass_kg * targets[i].omega);
    let mut side: Vec<f64> = want.iter().map(|x| x.signum()).collect();
    for _ in 0..8 {
        let poles: Vec<f64> = (0..n)
            .map(|j| targets[j].omega * (1.0 + side[j] * room[j]))
            .collect();
        let a = DMatrix::from_fn(n, n, |i, j| {
            let w = targets[i].omega;
            w / (poles[j] * poles[j] - w * w)
        });
        let k = a.lu().solve(&want)?;
        let negative: Vec<usize> = (0..n).filter(|j| k[*j] <= 0.0).collect();
        if negative.is_empty() {
            return Some(
                (0..n)
                    .map(|j| Resonator {
                        mass_kg: k[j] / (poles[j] * poles[j]),
                        stiffness_npm: k[j],
                        damping_nspm: 0.0,
                    })
                    .collect(),
            );
        }
        for j in negative {
            side[j] = -side[j];
        }
    }
    None
}

/// The impedance display's worst value at each alias of one frequency,
/// each frequency once, the greatest gains first: what
/// [`hand`](Self::hand) realises, as many aliases at a time as asked.
pub(super) struct WorstAliases {
    targets: Vec<Target>,
    grasp: Option<HumanBound>,
}

impl WorstAliases {
    /// The aliases of `w` (rad/s) on `plant` at period `t` (s), with
    /// `delay` whole ticks and behind `grasp` where there is one.
    pub(super) fn at(
        plant: &Plant,
        t: f64,
        grasp: Option<HumanBound>,
        delay: usize,
        w: f64,
    ) -> Self {
        let z = Complex64::from_polar(1.0, w * t);
        let c0 = z.powi(-(delay as i32)) * (Complex64::new(1.0, 0.0) - z.inv()) / (t * t);
        // A frequency once: at Nyquist two aliases are one frequency.
        let mut distinct: Vec<Target> = Vec::new();
        for a in targets(plant, t, grasp, w, c0) {
            let new = distinct
                .iter()
                .all(|b| ((a.omega - b.omega) / a.omega).abs() > 1e-9);
            if new {
                distinct.push(a);
            }
        }
        WorstAliases {
            targets: distinct,
            grasp,
        }
    }

    /// The lossless hand that takes the worst value at the `count`
    /// aliases that gain most, behind the grasp; `None` where there are
    /// fewer or no hand can be realised.
    pub(super) fn hand(&self, count: usize) -> Option<Hand> {
        let targets = self.targets.get(..count)?;
        let mass_kg = Hand::least_mass_kg(self.grasp);
        Some(Hand {
            mass_kg,
            stiffness_npm: 0.0,
            damping_nspm: 0.0,
            grasp: self.grasp,
            hanging: realise(targets, mass_kg)?,
        })
    }
}
