//! What the encoder's quantum and the actuator's Coulomb friction allow at
//! given gains: the force the quantisation adds, the stiffness friction
//! still holds, and a bound on any limit cycle beyond it.
//!
//! The argument is an energy balance over one period of a limit cycle.
//! The board's law acts on the quantised position `x + e`, so its force is
//! the law on the true motion plus the law on the error sequence `e`. On
//! a position-and-damping law `k x + b (1 - z^-1)/T x`, that error force
//! stays within `F_q = k Δ/2 + |b| Δ/T` of its mean (the quantisation
//! error spans one quantum `Δ`; its first difference spans two halves).
//! Over a period a constant force does no work, so the error force puts
//! in at most `F_q` per metre the actuator travels, and Coulomb friction
//! `f_c` takes out exactly `f_c` per metre. On a rigid device of damping
//! `b_d` under Colgate's condition, the rest of the loop (device, law,
//! passive hand and VE) takes out at least `δ ∫v²`, `δ = b_d - k T/2 - |b|`
//! the damping beyond the condition's. So a cycle needs
//! `(F_q - f_c) ∫|v| >= δ ∫v²`:
//!
//! - with `F_q <= f_c` there is none: friction holds the device still.
//!   With `b = 0` this is Abbott & Okamura's `k <= 2 f_c / Δ` (2005),
//!   which they derive for the passivity of the quantised virtual wall;
//! - otherwise the cycle's RMS velocity is at most `(F_q - f_c)/δ`
//!   (Cauchy-Schwarz on the two integrals over the period).
//!
//! On a flexible device, with a delay, or on the admittance display (whose
//! regulator carries `k` and `b`), the same balance holds only where the
//! rest of the loop is passive at the actuator; the friction limit is then
//! an estimate, and no velocity bound is given.

use serde::Serialize;
use std::fmt;

/// The quantisation's limit cycles at one pair of gains.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct LimitCycle {
    /// The encoder's quantum `Δ` (m).
    pub encoder_quantum_m: f64,
    /// The actuator's Coulomb friction `f_c` (N).
    pub coulomb_friction_n: f64,
    /// The stiffness on the quantised position `k` (N/m).
    pub stiffness_npm: f64,
    /// The damping on the quantised position's first difference `b`
    /// (N s/m).
    pub damping_nspm: f64,
    /// `F_q = k Δ/2 + |b| Δ/T`: how far the quantisation moves the force
    /// from its mean (N).
    pub quantum_force_n: f64,
    /// The damping's part of it, `|b| Δ/T` (N).
    pub damping_share_n: f64,
    /// The stiffest `k` friction holds at this damping,
    /// `2 (f_c - |b| Δ/T)/Δ` (N/m); none where the damping's share alone
    /// passes `f_c`.
    pub held_to_npm: Option<f64>,
    /// Whether friction holds the device: `F_q <= f_c`.
    pub held: bool,
    /// Where it does not, on a rigid device inside Colgate's condition:
    /// the largest RMS velocity of a limit cycle (m/s).
    pub velocity_rms_bound_mps: Option<f64>,
    /// Whether the result is proven (a rigid device, no delay, the
    /// impedance display) rather than an estimate.
    pub proven: bool,
}

/// The device facts the balance needs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Friction {
    /// Encoder quantum `Δ` (m), > 0.
    pub encoder_quantum_m: f64,
    /// Coulomb friction `f_c` (N), >= 0.
    pub coulomb_friction_n: f64,
    /// The device's damping where it is one rigid body (N s/m), else none.
    pub rigid_damping_nspm: Option<f64>,
}

impl LimitCycle {
    /// The balance for a law `k x + b (1 - z^-1)/T x` on the quantised
    /// position at period `period_s`; `impedance` says whether it is the
    /// impedance display's coupling on an undelayed loop (the proven case
    /// on a rigid device).
    pub fn new(
        friction: &Friction,
        stiffness_npm: f64,
        damping_nspm: f64,
        period_s: f64,
        impedance: bool,
    ) -> Self {
        let (q, fc) = (friction.encoder_quantum_m, friction.coulomb_friction_n);
        let damping_share = damping_nspm.abs() * q / period_s;
        let quantum_force_n = stiffness_npm * q / 2.0 + damping_share;
        let held_to_npm = (damping_share <= fc).then(|| 2.0 * (fc - damping_share) / q);
        let held = quantum_force_n <= fc;
        let excess = friction
            .rigid_damping_nspm
            .filter(|_| impedance)
            .map(|b| b - stiffness_npm * period_s / 2.0 - damping_nspm.abs());
        let proven = excess.is_some_and(|d| d > 0.0);
        let velocity_rms_bound_mps = match excess {
            Some(d) if d > 0.0 && !held => Some((quantum_force_n - fc) / d),
            _ => None,
        };
        LimitCycle {
            encoder_quantum_m: q,
            coulomb_friction_n: fc,
            stiffness_npm,
            damping_nspm,
            quantum_force_n,
            damping_share_n: damping_share,
            held_to_npm,
            held,
            velocity_rms_bound_mps,
            proven,
        }
    }
}

impl fmt::Display for LimitCycle {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let kind = if self.proven { "proven" } else { "estimate" };
        write!(
            f,
            "  quantisation ({} µm encoder, {} N friction): the force moves by {:.3} N",
            // Four decimals, without trailing zeros: a quantum read off a
            // record is 1 µm, not 0.9999999999992654.
            (self.encoder_quantum_m * 1e10).round() / 1e4,
            (self.coulomb_friction_n * 1e4).round() / 1e4,
            self.quantum_force_n
        )?;
        if self.held {
            write!(f, "; friction holds it, no limit cycle ({kind})")?;
        } else {
            write!(f, "; friction does not hold it")?;
            match self.velocity_rms_bound_mps {
                Some(v) => write!(f, ", a limit cycle stays under {:.3} m/s RMS", v)?,
                None => write!(f, " ({kind})")?,
            }
        }
        match self.held_to_npm {
            Some(k) => write!(
                f,
                "\n  friction holds stiffness up to {k:.0} N/m at this damping"
            ),
            None => write!(
                f,
                "\n  the damping's share alone ({:.3} N) passes the friction",
                self.damping_share_n
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rigid(q: f64, fc: f64, b: f64) -> Friction {
        Friction {
            encoder_quantum_m: q,
            coulomb_friction_n: fc,
            rigid_damping_nspm: Some(b),
        }
    }

    #[test]
    fn without_damping_friction_holds_abbott_and_okamuras_stiffness() {
        let f = rigid(1e-5, 0.2, 20.0);
        let lc = LimitCycle::new(&f, 1.0, 0.0, 1e-3, true);
        let k = lc.held_to_npm.unwrap();
        assert!((k - 2.0 * 0.2 / 1e-5).abs() < 1e-9 * k);
        assert!(LimitCycle::new(&f, 0.999 * k, 0.0, 1e-3, true).held);
        assert!(!LimitCycle::new(&f, 1.001 * k, 0.0, 1e-3, true).held);
    }

    #[test]
    fn damping_on_the_first_difference_lowers_what_friction_holds() {
        // 1 µm at 1 kHz is 1 mm/s a quantum: 90 N s/m adds 0.09 N.
        let f = rigid(1e-6, 0.1, 20.0);
        let lc = LimitCycle::new(&f, 51_000.0, 90.0, 1e-3, true);
        assert!((lc.quantum_force_n - (0.0255 + 0.09)).abs() < 1e-12);
        assert!((lc.held_to_npm.unwrap() - 20_000.0).abs() < 1e-6);
        assert!(!lc.held);
        let none = LimitCycle::new(&f, 0.0, 200.0, 1e-3, true);
        assert_eq!(none.held_to_npm, None);
    }

    #[test]
    fn the_velocity_bound_needs_a_rigid_device_inside_colgates_condition() {
        let f = rigid(1e-4, 0.1, 20.0);
        // δ = 20 - 30,000 × 0.0005 = 5 N s/m; F_q = 1.5 N.
        let lc = LimitCycle::new(&f, 30_000.0, 0.0, 1e-3, true);
        assert!(lc.proven);
        assert!((lc.velocity_rms_bound_mps.unwrap() - 1.4 / 5.0).abs() < 1e-12);
        // Past Colgate's condition there is no passive rest to lean on.
        let past = LimitCycle::new(&f, 41_000.0, 0.0, 1e-3, true);
        assert!(!past.proven && past.velocity_rms_bound_mps.is_none());
        // A flexible device: an estimate.
        let flex = Friction {
            rigid_damping_nspm: None,
            ..f
        };
        let lc = LimitCycle::new(&flex, 30_000.0, 0.0, 1e-3, true);
        assert!(!lc.proven && lc.velocity_rms_bound_mps.is_none());
    }
}
