//! Absolute-stability checks of given gains: the sound bound's margin,
//! the paper's approximate one beside it, and Llewellyn's criteria.

use super::{
    admittance_coupling_tf, dc_margin, impedance_coupling_tf, least, regulator_tf, Analysis,
};
use crate::network::{
    admittance_display, impedance_display, llewellyn_margin, with_admittance_coupling,
    with_impedance_coupling, HumanBound,
};
use crate::Plant;
use num_complex::Complex64;
use std::f64::consts::PI;
use twoport_control::ZTransfer;

/// Result of an absolute-stability check.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Check {
    /// Whether the sound (sampled-data) design inequality holds at every
    /// grid frequency (and, for the admittance display, the regulated
    /// device is stable): absolutely stable for every passive hand and VE.
    pub absolutely_stable: bool,
    /// The smallest relative slack of the sound design inequality over the
    /// grid (see [`relative_margin`]): >= 0 is absolutely stable.
    pub min_margin: f64,
    /// Where it occurs (Hz).
    pub worst_frequency_hz: f64,
    /// For the admittance display: the largest pole radius of the regulated
    /// device (< 1 is stable); 0 for the impedance display.
    pub regulator_pole_radius: f64,
    /// The same check on the paper's approximation (aliasing at the handle
    /// port neglected), for comparison.
    pub paper: PaperCheck,
}

impl Check {
    /// Whether the sampled-data analysis decides differently from the
    /// paper's approximation: another verdict, or a margin smaller by more
    /// than 1e-6.
    pub fn sampled_binds(&self) -> bool {
        self.absolutely_stable != self.paper.absolutely_stable
            || self.paper.min_margin - self.min_margin > 1e-6
    }
}

/// The paper's approximate check beside the sound one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PaperCheck {
    /// Whether the paper's inequality holds everywhere.
    pub absolutely_stable: bool,
    /// Its least relative slack.
    pub min_margin: f64,
    /// Where (Hz).
    pub worst_frequency_hz: f64,
}

/// The relative slack `(c - β) / (|c| + |β|)` of a design inequality
/// `c >= β` (`c` the coupling's term, `β` the bound): +1 far inside, 0 on the
/// bound, negative where it is violated, -1 where `β` is infinite. Its sign
/// is that of Llewellyn's `η - 1` at the same frequency (the inequality is
/// `η >= 1` multiplied by `2 Re p11 > 0`), but unlike `η - 1` it does not
/// vanish at DC, where every coupling makes the rigid device a lossless link.
pub fn relative_margin(c: f64, bound: f64) -> f64 {
    if bound == f64::INFINITY || c.is_nan() || bound.is_nan() {
        return -1.0;
    }
    let den = c.abs() + bound.abs();
    if den == 0.0 {
        0.0
    } else {
        (c - bound) / den
    }
}

/// The least relative slack of `lhs(z) >= bound` over the grid (and
/// between its points, see [`least`]), and where (Hz).
fn worst(a: &Analysis, bound: &[f64], lhs: impl Fn(Complex64) -> f64) -> (f64, f64) {
    let dc = (dc_margin(a, bound, &lhs), 0.0);
    let m: Vec<f64> = a
        .points
        .iter()
        .zip(bound)
        .map(|(pt, b)| relative_margin(lhs(pt.z), *b))
        .collect();
    let (g, w) = least(&a.points, &m);
    if g < dc.0 {
        (g, w / (2.0 * PI))
    } else {
        dc
    }
}

fn paper_check((m, f): (f64, f64), extra: bool) -> PaperCheck {
    PaperCheck {
        absolutely_stable: m >= 0.0 && extra,
        min_margin: m,
        worst_frequency_hz: f,
    }
}

/// Absolute-stability check of the impedance display with coupling `(k, b)`.
pub fn check_impedance(a: &Analysis, k: f64, b: f64, human: Option<HumanBound>) -> Option<Check> {
    let tf = impedance_coupling_tf(k, b, a.period_s).ok()?;
    let lhs = |z: Complex64| tf.eval(z).inv().re;
    let (m, f) = worst(a, &a.impedance_bound(human), lhs);
    Some(Check {
        absolutely_stable: m >= 0.0,
        min_margin: m,
        worst_frequency_hz: f,
        regulator_pole_radius: 0.0,
        paper: paper_check(worst(a, &a.paper_impedance_bound(human), lhs), true),
    })
}

/// Absolute-stability check of the admittance display with regulator
/// `(kp, bp)` and coupling `(m, b)`.
pub fn check_admittance(
    plant: &Plant,
    a: &Analysis,
    (kp, bp): (f64, f64),
    (m, b): (f64, f64),
    human: Option<HumanBound>,
) -> Option<Check> {
    let (k, zc) = admittance_laws(a, (kp, bp), (m, b))?;
    let radius = plant.regulated_pole_radius(&k);
    let lhs = |z: Complex64| zc.eval(z).re;
    let (mg, f) = worst(a, &a.admittance_bound(&k, human), lhs);
    Some(Check {
        absolutely_stable: mg >= 0.0 && radius < 1.0,
        min_margin: mg,
        worst_frequency_hz: f,
        regulator_pole_radius: radius,
        paper: paper_check(
            worst(a, &a.paper_admittance_bound(&k, human), lhs),
            radius < 1.0,
        ),
    })
}

/// Llewellyn's `η - 1` of the full interface at every grid point (for
/// plots and cross-checks), impedance display.
pub fn llewellyn_impedance(
    a: &Analysis,
    k: f64,
    b: f64,
    human: Option<HumanBound>,
) -> Option<Vec<f64>> {
    let tf = impedance_coupling_tf(k, b, a.period_s).ok()?;
    Some(
        a.points
            .iter()
            .map(|p| {
                llewellyn_margin(&with_impedance_coupling(
                    &impedance_display(p, human),
                    tf.eval(p.z),
                ))
            })
            .collect(),
    )
}

/// The admittance display's regulator and coupling z-forms, as the board
/// would run them.
pub(super) fn admittance_laws(
    a: &Analysis,
    (kp, bp): (f64, f64),
    (m, b): (f64, f64),
) -> Option<(ZTransfer, ZTransfer)> {
    Some((
        regulator_tf(kp, bp, a.period_s).ok()?,
        admittance_coupling_tf(m, b, a.period_s).ok()?,
    ))
}

/// Llewellyn's `η - 1` of the full interface at every grid point,
/// admittance display.
pub fn llewellyn_admittance(
    a: &Analysis,
    (kp, bp): (f64, f64),
    (m, b): (f64, f64),
    human: Option<HumanBound>,
) -> Option<Vec<f64>> {
    let (k, zc) = admittance_laws(a, (kp, bp), (m, b))?;
    Some(
        a.points
            .iter()
            .map(|p| {
                llewellyn_margin(&with_admittance_coupling(
                    &admittance_display(p, &k, human),
                    zc.eval(p.z),
                ))
            })
            .collect(),
    )
}
