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

use crate::network::HumanBound;
use crate::DeviceModel;
use serde::Serialize;
use twoport_control::Gains;

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
    /// A lossless mass (the control crate's `LosslessCursor`: the force
    /// integrated by the trapezoidal rule): passive, its admittance
    /// imaginary on the unit circle, the edge of the passive masses, which
    /// the delay cases need.
    LosslessMass {
        /// Mass (kg).
        mass_kg: f64,
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
/// bound `Z_max` in series with the mass-spring-damper. Further masses may
/// hang from the first, each on its own spring and damper: a hand with several
/// resonances.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Hand {
    /// Mass (kg).
    pub mass_kg: f64,
    /// Spring to ground (N/m).
    pub stiffness_npm: f64,
    /// Damper to ground (N s/m).
    pub damping_nspm: f64,
    /// The grasp in series, `Z_max = b + k/s`, or none.
    pub grasp: Option<HumanBound>,
    /// Masses hanging from the first, each on a spring and a damper of
    /// its own (none: a hand with one resonance). Lossless, they give the
    /// hand any reactance at any finite set of frequencies (Foster's
    /// theorem), which the constructive search needs.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub hanging: Vec<Resonator>,
}

impl Hand {
    /// The least mass behind a grasp (kg): the grasp's own coordinate
    /// needs one for the mass matrix to be regular. None without a grasp.
    pub(crate) fn least_mass_kg(grasp: Option<HumanBound>) -> f64 {
        if grasp.is_some() {
            1e-6
        } else {
            0.0
        }
    }

    /// No hand on the handle.
    pub const OFF: Hand = Hand {
        mass_kg: 0.0,
        stiffness_npm: 0.0,
        damping_nspm: 0.0,
        grasp: None,
        hanging: Vec::new(),
    };
}

/// A mass on a spring and a damper in parallel.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Resonator {
    /// Mass (kg).
    pub mass_kg: f64,
    /// Spring (N/m).
    pub stiffness_npm: f64,
    /// Damper (N s/m).
    pub damping_nspm: f64,
}

/// A hand and a VE.
#[derive(Clone, Debug, PartialEq, Serialize)]
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
#[derive(Clone, Debug, PartialEq, Serialize)]
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
    /// A lossless hand and VE built to put a pole on the unit circle,
    /// where the constructive search finds one (see [`construct`]):
    /// proof that the gains are at or past the edge, independent of the
    /// search.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub constructed: Option<Constructed>,
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

mod closed_loop;
mod construct;
mod foster;
mod host;
mod search;
mod simplex;
mod teleop;
mod teleop_proof;

pub(crate) use simplex::maximise as simplex_maximise;

use closed_loop::{closed_loop, judge};
pub use construct::{construct, Constructed};
pub use host::{host_radius, monodromy, verify_host, HostVerdict};
pub use search::{verify, verify_near};
pub use teleop::{
    four_channel_tf, teleop_closed_loop, teleop_radius, verify_four_channel, verify_law,
    verify_teleop, TeleopLaw, TeleopTermination, TeleopVerdict, Teleoperator, WaveGains,
    MAX_DELAY_TICKS,
};
pub use teleop_proof::verify_teleop_near_proof;

/// The closed loop's spectral radius for one termination.
pub fn radius(
    model: &DeviceModel,
    period_s: f64,
    gains: &Gains,
    term: &Termination,
) -> Result<Radius, crate::Error> {
    let a = closed_loop(model, period_s, gains, term).map_err(|why| crate::Error::Verify {
        model: model.name.clone(),
        why,
    })?;
    Ok(judge(&a, period_s))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The board's impedance gains (f32, as the laws are built) for `k`
    /// (N/m) and `b` (N s/m).
    fn imp(k: f64, b: f64) -> Gains {
        twoport_control::ImpedanceGains::new(k as f32, b as f32).into()
    }
    use nalgebra::DMatrix;
    use std::f64::consts::PI;

    fn rigid() -> DeviceModel {
        crate::model::rigid_for_tests(1.0, 20.0)
    }

    fn hands_off(ve: Ve) -> Termination {
        Termination {
            hand: Hand::OFF,
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
            radius(&rigid(), t, &imp(k, 0.0), &hands_off(Ve::Constraint))
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
                        hanging: Vec::new(),
                    },
                    ve,
                };
                let g = imp(k, 20.0);
                let a = closed_loop(&model, 1e-3, &g, &term).unwrap();
                let osc = |m: &DMatrix<f64>| {
                    crate::linalg::eigenvalues(m)
                        .unwrap()
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

    /// A second hand mass on a spring far stiffer than anything in the
    /// loop moves with the first: the loop is the one-mass hand's with the
    /// masses summed, with and without the grasp.
    #[test]
    fn a_rigidly_held_second_mass_adds_to_the_first() {
        let model = crate::model::shipped_for_tests().remove(0);
        for grasp in [None, Some(HumanBound::PAPER)] {
            let hand = |mass_kg, hanging: Option<Resonator>| Hand {
                mass_kg,
                stiffness_npm: 2e4,
                damping_nspm: 1.0,
                grasp,
                hanging: hanging.into_iter().collect(),
            };
            let ve = Ve::Cursor { mass_kg: 0.2 };
            let rho = |hand| {
                let r = radius(
                    &model,
                    1e-3,
                    &imp(40_000.0, 20.0),
                    &Termination { hand, ve },
                );
                r.unwrap().spectral_radius
            };
            let one = rho(hand(0.3, None));
            let two = rho(hand(
                0.1,
                Some(Resonator {
                    mass_kg: 0.2,
                    stiffness_npm: 1e12,
                    damping_nspm: 0.0,
                }),
            ));
            assert!((one - two).abs() < 1e-6, "{grasp:?}: {one} vs {two}");
            // And a soft one does not.
            let soft = rho(hand(
                0.1,
                Some(Resonator {
                    mass_kg: 0.2,
                    stiffness_npm: 1e3,
                    damping_nspm: 0.0,
                }),
            ));
            assert!((one - soft).abs() > 1e-5, "{grasp:?}: {one} vs {soft}");
        }
    }

    /// The constructed termination puts a pole on the unit circle where a
    /// lossless hand violates the inequality (the rigid device at the
    /// paper's 40,000 N/m, near Nyquist, from the search's worst hand),
    /// and finds none at the design.
    #[test]
    fn construct_puts_a_pole_on_the_circle() {
        let g = twoport_control::ImpedanceGains::new(40_000.0, 10.0);
        let v = verify(&rigid(), 1e-3, &g.into(), None).unwrap();
        let seeds = [v.termination.hand];
        let freqs = [v.frequency_hz, 499.0, 450.0];
        let c = construct(&rigid(), 1e-3, g.into(), None, &freqs, &seeds).expect("a termination");
        assert!((c.spectral_radius - 1.0).abs() < 1e-6, "{c:?}");
        assert_eq!(c.termination.hand.damping_nspm, 0.0);
        let at = twoport_control::ImpedanceGains::new(19_900.0, 10.0);
        assert_eq!(
            construct(&rigid(), 1e-3, at.into(), None, &freqs, &seeds),
            None
        );
    }

    /// The counterexample: at 40,000 N/m and 10 N s/m a passive
    /// hand (a small mass on a stiff spring, resonant near Nyquist) makes the
    /// rigid device unstable, though the paper's bound calls it proven.
    #[test]
    fn finds_the_rigid_counterexample() {
        let v = verify(&rigid(), 1e-3, &imp(40_000.0, 10.0), None).unwrap();
        assert!(v.unstable, "{v:?}");
        assert!(v.frequency_hz > 300.0, "{v:?}");
    }
}
