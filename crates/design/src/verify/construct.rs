//! A constructive search: at a frequency where the exact loop with a real
//! hand leaves room for it, build the passive hand and the passive VE
//! whose loop has a pole on the unit circle there.
//!
//! With the hand fixed, the loop has a pole at `z` exactly when the VE's
//! immittance there is `S(z)`: on the impedance display its admittance
//! `S = z^-d P_x (1 - z^-1)/T - 1/Z_cI`; on the admittance display its
//! impedance `S = -z^-d K_p I P_f / (1 - z^-d K_p P_x) - Z_cA`, with
//! `I = T/(1 - z^-1)`. `P_x` and `P_f` are the sampled device-and-hand
//! from the actuator force to the encoder and the load cell (the pole
//! condition of the loop `closed_loop` builds). A passive VE can take that
//! value iff `Re S >= 0`. Lossless hands (a mass, or a mass on a
//! spring, behind the grasp where there is one) are searched for one with
//! `Re S > 0`; scaled toward zero, a hand lets go, and the free device
//! gives `Re S < 0`, so a scale between gives the root `Re S = 0`. There
//! the VE is lossless too: a lossless
//! mass or a lossless spring, whose admittance on the unit circle is
//! imaginary. Both exist on the board, so the termination is realisable,
//! and the loop it closes has a pole at `e^{jωT}`.
//!
//! The search sees each hand exactly, aliases and all, so where it finds
//! nothing though the sound bound fails, the failure lies in the aliases
//! the bound lets vary independently: the bound is conservative there.

use super::closed_loop::actuator_response;
use super::foster::WorstAliases;
use super::{radius, Hand, Radius, Resonator, Termination, Ve};
use crate::analysis::{admittance_coupling_tf, impedance_coupling_tf, regulator_tf};
use crate::network::HumanBound;
use crate::{DeviceModel, Plant};
use num_complex::Complex64;
use serde::Serialize;
use std::f64::consts::PI;
use twoport_control::Gains;

/// A termination built to put a pole on the unit circle.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Constructed {
    /// The frequency of the pole (Hz).
    pub frequency_hz: f64,
    /// The hand and VE.
    pub termination: Termination,
    /// The loop's radius with them (1 up to rounding, or more).
    pub spectral_radius: f64,
}

/// The constructive search's setting.
struct Setting<'a> {
    model: &'a DeviceModel,
    t: f64,
    gains: Gains,
    grasp: Option<HumanBound>,
    /// The whole ticks of the model's delay (the latency inside the tick
    /// is in the sampled device).
    delay: usize,
    /// The device's continuous terms, for the proof's worst hand (the
    /// impedance display's only), built the first time a sweep leaves
    /// `Re S` short.
    plant: std::cell::OnceCell<Option<Plant>>,
}

impl Setting<'_> {
    /// The lossless hand of mass `m` (kg) on a spring `k` (N/m) to ground,
    /// behind the grasp where there is one (which then needs a mass).
    fn hand(&self, (m, k): (f64, f64)) -> Hand {
        Hand {
            mass_kg: m.max(Hand::least_mass_kg(self.grasp)),
            stiffness_npm: k,
            damping_nspm: 0.0,
            grasp: self.grasp,
            hanging: Vec::new(),
        }
    }

    /// `S(e^{jωT})` with `hand`: the VE's immittance that closes a pole
    /// there (its admittance on the impedance display, its impedance on
    /// the admittance display).
    fn s(&self, hand: &Hand, w: f64) -> Option<Complex64> {
        let z = Complex64::from_polar(1.0, w * self.t);
        let (px, pf) = actuator_response(self.model, hand, self.t, z).ok()?;
        let lag = z.powi(-(self.delay as i32));
        let one = Complex64::new(1.0, 0.0);
        match self.gains {
            Gains::Impedance(g) => {
                let zc = impedance_coupling_tf(g.k_npm.into(), g.b_nspm.into(), self.t)
                    .ok()?
                    .eval(z);
                Some(lag * px * (one - z.inv()) / self.t - zc.inv())
            }
            Gains::Admittance(g) => {
                let k = regulator_tf(g.kp_npm.into(), g.bp_nspm.into(), self.t)
                    .ok()?
                    .eval(z);
                let za = admittance_coupling_tf(g.m_kg.into(), g.b_nspm.into(), self.t)
                    .ok()?
                    .eval(z);
                let integrate = self.t / (one - z.inv());
                Some(-lag * k * integrate * pf / (one - lag * k * px) - za)
            }
        }
    }

    /// The lossless hand at `w` with the greatest `Re S`, and `Re S`:
    /// `seeds` (the search's worst hands, their damping removed), a sweep
    /// of masses, springs, and masses on springs resonant across the
    /// band, where their resonance folds onto `w`, and at multiples of the
    /// sample rate (where a hand's sampled poles meet on the real axis),
    /// and on the impedance display the hands that take the proof's worst
    /// value at the aliases of `w` that matter most ([`alias_hands`]).
    fn worst_hand(&self, w: f64, seeds: &[(f64, f64)]) -> Option<(Hand, f64)> {
        let ws = 2.0 * PI / self.t;
        let mut resonances: Vec<f64> = (0..40)
            .map(|i| 2.0 * PI * (2.0 * ws / PI).powf(i as f64 / 39.0))
            .collect();
        for j in [
            0.0, 1.0, 2.0, 3.0, 5.0, 8.0, 13.0, 20.0, 32.0, 50.0, 80.0, 128.0,
        ] {
            resonances.extend(
                [w + j * ws, j * ws - w, (j + 1.0) * ws]
                    .iter()
                    .filter(|r| **r > 0.0),
            );
        }
        let mut pairs: Vec<(f64, f64)> = seeds.to_vec();
        for i in 0..15 {
            let m = 10f64.powf(-5.0 + i as f64 / 2.0);
            pairs.push((m, 0.0));
            pairs.extend(resonances.iter().map(|r| (m, m * r * r)));
        }
        if self.grasp.is_none() {
            pairs.extend((0..23).map(|i| (0.0, 10f64.powf(i as f64 / 2.0))));
        }
        let best = pairs
            .into_iter()
            .map(|h| self.hand(h))
            .filter_map(|h| self.s(&h, w).map(|s| (h, s.re)))
            .max_by(|a, b| a.1.total_cmp(&b.1));
        if best.as_ref().is_some_and(|b| b.1 > 0.0) {
            return best;
        }
        let impedance = matches!(self.gains, Gains::Impedance(_));
        let plant = self
            .plant
            .get_or_init(|| impedance.then(|| Plant::new(self.model, self.t).ok())?);
        let Some(plant) = plant else {
            return best;
        };
        // More aliases taken, until enough are: the deficit falls about
        // by half with each doubling where the gains' tail is long, so
        // the ladder stops where what is left to gain cannot cover it
        // (each rung costs a discretisation with a mass per alias).
        let aliases = WorstAliases::at(plant, self.t, self.grasp, self.delay, w);
        let mut best = best;
        let mut last: Option<f64> = None;
        for count in [1, 2, 4, 8, 16, 32, 64, 128, 256] {
            let Some(h) = aliases.hand(count) else {
                continue;
            };
            let Some(s) = self.s(&h, w) else { continue };
            if best.as_ref().is_none_or(|b| s.re > b.1) {
                best = Some((h, s.re));
            }
            if s.re > 0.0 || last.is_some_and(|l| -s.re > 2.0 * (s.re - l)) {
                break;
            }
            last = Some(s.re);
        }
        best
    }
}

/// Build a passive hand and VE that put a pole of the loop on the unit
/// circle, at the frequency (of `frequencies_hz`)
/// where a lossless hand (of the sweep, or one of the `seeds`' masses and
/// springs) violates the design inequality most; `None` where none does
/// at any of them.
pub fn construct(
    model: &DeviceModel,
    period_s: f64,
    gains: Gains,
    human: Option<HumanBound>,
    frequencies_hz: &[f64],
    seeds: &[Hand],
) -> Option<Constructed> {
    let seeds: Vec<(f64, f64)> = seeds
        .iter()
        .filter(|h| h.hanging.is_empty())
        .map(|h| (h.mass_kg, h.stiffness_npm))
        .collect();
    let set = Setting {
        model,
        t: period_s,
        gains,
        grasp: human,
        delay: model.lag(period_s).ticks as usize,
        plant: std::cell::OnceCell::new(),
    };
    // At Nyquist a real hand's two nearest aliases are one frequency, so
    // a frequency just below it, where a hand resonant at Nyquist parts
    // them, is tried too.
    let nyquist_hz = 0.5 / period_s;
    let mut frequencies_hz = frequencies_hz.to_vec();
    if frequencies_hz.iter().any(|f| *f > 0.999 * nyquist_hz) {
        frequencies_hz.extend([0.998, 0.99].map(|x| x * nyquist_hz));
    }
    let mut candidates: Vec<(f64, Hand, f64)> = frequencies_hz
        .iter()
        .map(|f| 2.0 * PI * f)
        .filter_map(|w| set.worst_hand(w, &seeds).map(|(h, r)| (w, h, r)))
        .filter(|(_, _, r)| *r > 0.0)
        .collect();
    candidates.sort_by(|a, b| b.2.total_cmp(&a.2));
    // The worst violation first; where no root can be had there, the next.
    candidates
        .into_iter()
        .find_map(|(w, hand, _)| set.pole_on_circle(w, hand))
}

impl Setting<'_> {
    /// The hand scaled, or the frequency `w` moved, to the root of
    /// `Re S`, and the lossless VE that closes a pole there.
    fn pole_on_circle(&self, w: f64, hand: Hand) -> Option<Constructed> {
        let period_s = self.t;
        // A root of Re S on a path from there to where Re S < 0: the hand
        // scaled toward zero (it lets go, and the open device with its
        // coupling is stable), or, where even the free hand violates it, the
        // frequency moved off the violation with the hand kept.
        let re = |scale: f64, w: f64| self.s(&scaled(&hand, scale), w).map(|s| s.re);
        let (scale, w) = if re(1e-12, w)? < 0.0 {
            let l = root(|l| re(l.exp(), w), (1e-12f64).ln(), 0.0)?;
            (l.exp(), w)
        } else {
            // Near `w` first, then anywhere in the band, nearest first.
            let near = (1..=60).map(|i| {
                w * (1.0 + 0.002 * f64::from(i / 2) * if i % 2 == 0 { 1.0 } else { -1.0 })
            });
            let nyquist = PI / period_s;
            let mut band: Vec<f64> = (0..=200)
                .map(|i| nyquist * 1e-4f64.powf(f64::from(i) / 200.0))
                .collect();
            band.sort_by(|a, b| (a / w).ln().abs().total_cmp(&(b / w).ln().abs()));
            let off = near
                .chain(band)
                .find(|&v| v > 0.0 && v * period_s <= PI && re(1.0, v).is_some_and(|r| r < 0.0))?;
            (1.0, root(|v| re(1.0, v), off, w)?)
        };
        let hand = scaled(&hand, scale);
        let s = self.s(&hand, w)?;
        let half = 0.5 * w * period_s;
        // The lossless VE of immittance j Im S, as an admittance j β: a
        // lossless mass below the real axis, a lossless spring above it.
        let beta = match self.gains {
            Gains::Impedance(_) => s.im,
            Gains::Admittance(_) => -1.0 / s.im,
        };
        let ve = if beta < 0.0 {
            Ve::LosslessMass {
                mass_kg: period_s / (2.0 * half.tan() * -beta),
            }
        } else {
            Ve::TrapezoidalSpring {
                stiffness_npm: 2.0 * half.tan() / (period_s * beta),
                damping_nspm: 0.0,
            }
        };
        let termination = Termination { hand, ve };
        let r: Radius = radius(self.model, period_s, &self.gains, &termination).ok()?;
        Some(Constructed {
            frequency_hz: w / (2.0 * PI),
            termination,
            spectral_radius: r.spectral_radius,
        })
    }
}

/// `hand` with every mass and spring scaled by `scale`: its impedance
/// scaled, its resonances kept (and its grasp, which is the bound's,
/// with the least mass behind it).
fn scaled(hand: &Hand, scale: f64) -> Hand {
    Hand {
        mass_kg: (hand.mass_kg * scale).max(Hand::least_mass_kg(hand.grasp)),
        stiffness_npm: hand.stiffness_npm * scale,
        damping_nspm: hand.damping_nspm * scale,
        grasp: hand.grasp,
        hanging: hand
            .hanging
            .iter()
            .map(|r| Resonator {
                mass_kg: r.mass_kg * scale,
                stiffness_npm: r.stiffness_npm * scale,
                damping_nspm: r.damping_nspm * scale,
            })
            .collect(),
    }
}

/// The root of `f` between `neg` (where `f < 0`) and `pos` (where
/// `f >= 0`), by false position with the Illinois rule (a bracket kept,
/// each end's value halved when the other end moved twice: a handful of
/// evaluations where bisection takes fifty, and a hand with a hundred
/// masses costs a discretisation each); `None` where `f` cannot be
/// evaluated.
fn root(f: impl Fn(f64) -> Option<f64>, mut neg: f64, mut pos: f64) -> Option<f64> {
    let (mut f_neg, mut f_pos) = (f(neg)?, f(pos)?);
    let mut side = 0i8;
    for _ in 0..200 {
        if (pos - neg).abs() <= 1e-15 * pos.abs().max(1.0) {
            break;
        }
        let mut x = (neg * f_pos - pos * f_neg) / (f_pos - f_neg);
        if !(x.is_finite() && x > neg.min(pos) && x < neg.max(pos)) {
            x = 0.5 * (neg + pos);
        }
        let fx = f(x)?;
        if fx >= 0.0 {
            (pos, f_pos) = (x, fx);
            if side == 1 {
                f_neg *= 0.5;
            }
            side = 1;
        } else {
            (neg, f_neg) = (x, fx);
            if side == -1 {
                f_pos *= 0.5;
            }
            side = -1;
        }
        if fx == 0.0 {
            break;
        }
    }
    Some(pos)
}
