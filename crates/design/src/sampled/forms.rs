//! One device's sampled sensors with any passive hand at its handle, as
//! disks: what a loop closed through the device's encoder and load cell
//! (a teleoperator's, at either end) can see.
//!
//! Per held actuator force `F` (the paper's sign), the board reads the
//! encoder `-x = (X_aa^d - α w) F` and the load cell
//! `f = (F_ma^d - φ w - η) F`. The hand's base band and the aliases'
//! share of the encoder are folded into one `w` (a sum of disks is a
//! disk), exact; `η` is what the aliases leave in the load cell, in a
//! disk of its own (the same `w_k` as in `w`, taken as free: a superset,
//! so sound). See the admittance display's Möbius bound, which is built
//! on the same forms.

use super::admittance::{alias_disks, alias_reach, Base};
use super::AliasCache;
use crate::network::HumanBound;
use crate::{Plant, PlantPoint};
use num_complex::Complex64;

/// A closed disk in the complex plane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Disk {
    /// Its centre.
    pub centre: Complex64,
    /// Its radius (≥ 0).
    pub radius: f64,
}

/// One device's sampled sensors at one frequency, every passive hand at
/// its handle (see the module docs). The held force reaches the device
/// `delay` after the law computes it (its own whole ticks, `z^-d`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HandForms {
    /// `X_aa^d` (m/N): the encoder's `-x` per held force, the handle free.
    pub x0: Complex64,
    /// `F_ma^d` (N/N): the load cell per held force, the handle free.
    pub f0: Complex64,
    /// `α`: how the hand `w` takes from the encoder.
    pub alpha: Complex64,
    /// `φ`: how the hand `w` takes from the load cell.
    pub phi: Complex64,
    /// Where `w` lies.
    pub w: Disk,
    /// Where `η` lies.
    pub eta: Disk,
    /// The device's whole-tick delay, `z^-d`.
    pub delay: Complex64,
}

/// The [`HandForms`] of point `i` (`p`) of `plant` with the human bound
/// `human` at the handle (none: every passive termination); `None` where
/// the handle is lossless at `ω`, or an alias sum is unbounded.
pub fn hand_forms(
    plant: &Plant,
    (i, p): (usize, &PlantPoint),
    human: Option<HumanBound>,
    cache: &AliasCache,
) -> Option<HandForms> {
    let base = Base::at(p, human)?;
    let reach = alias_reach(plant, (i, p), human, cache)?;
    let disks = alias_disks(plant, (i, p), human, cache, (base, &reach));
    let one = Complex64::new(1.0, 0.0);
    let q = (one - p.z.inv()) / p.period_s;
    let forms = HandForms {
        x0: p.xaa_d,
        f0: p.fma_d,
        alpha: q * base.a0,
        phi: q * base.f0,
        w: Disk {
            centre: base.r0 + disks.a_centre / base.a0,
            radius: base.r0 + disks.a_radius / base.a0.norm(),
        },
        eta: Disk {
            centre: q * disks.b_centre,
            radius: q.norm() * disks.b_radius,
        },
        delay: p.delay,
    };
    let finite = [forms.x0, forms.f0, forms.alpha, forms.phi, forms.w.centre]
        .iter()
        .all(|c| c.re.is_finite() && c.im.is_finite())
        && forms.w.radius.is_finite()
        && forms.eta.radius.is_finite();
    finite.then_some(forms)
}
