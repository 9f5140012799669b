//! The teleoperator's proof: absolute stability of the sampled loop of a
//! master, a slave and the law between them, for every passive operator
//! at the master's handle (within the human bound, if given) and every
//! passive environment at the slave's.
//!
//! Each device's sensors, with any passive termination, are
//! [`HandForms`]: the encoder `-x = (X_0 - α w) F` and the load cell
//! `f = (F_0 - φ w - η) F` per held force `F`, with `w` and `η` in disks
//! (aliases at both handles included). The law's forms `L(z)` close the
//! loop through both devices; with `M` the two forces' map onto
//! themselves, a pole at `z` needs `det(I - M) = 0`:
//!
//! `det = (1 - m_1)(1 - s_2) - s_1 m_2`,
//!
//! `m_r` (the master's sensors' share of force `r`) affine in the master's
//! `w` and `η`, `s_r` in the slave's. With `w = c + r ζ` over the unit
//! disk, the determinant without the `η`s is bilinear,
//! `A + B ζ_m + C ζ_s + D ζ_m ζ_s`, and it has no zero on the bidisk iff
//! `|A| > |B|` and the Möbius image `(C + D ζ_m)/(A + B ζ_m)` of the unit
//! disk lies inside it: exact, since a sum of disks is a disk. The `η`s
//! (only a law that reads a load cell sees them) enter the determinant
//! linearly, one side's with coefficients affine in the other side's
//! `ζ`, so the test becomes `max |Q/P| + Σ ρ max |R/P| + k/min |P| < 1`,
//! each a Möbius image's far point, taken in both orders (master's or
//! slave's `ζ` first), the better kept.
//! [`teleop_slack`] is that margin at each point; it is positive where no
//! termination puts a pole at `z = e^{jωT}`.
//!
//! With the slack positive at every frequency and the loop stable with
//! both ends let go (its exact transition matrix, [`check_teleop`]), a
//! deformation of any passive operator and environment to let go moves
//! no pole across the unit circle: the teleoperator is stable for all of
//! them.

use super::{grid, least, Analysis, GridSpec};
use crate::network::HumanBound;
use crate::sampled::{hand_forms, HandForms};
use crate::verify::{teleop_radius, Hand, TeleopTermination, Teleoperator};
use crate::{DeviceModel, Error, Plant};
use num_complex::Complex64;
use std::f64::consts::PI;
use twoport_control::teleop::TeleopTransfer;

/// A master and a slave evaluated on one frequency grid (the union of
/// both devices' grids), ready for teleoperator proofs.
#[derive(Clone, Debug)]
pub struct TeleopAnalysis {
    master: (DeviceModel, Analysis),
    slave: (DeviceModel, Analysis),
}

impl TeleopAnalysis {
    /// Both devices at their (shared) period on `spec`'s grids, merged.
    pub fn new(master: &DeviceModel, slave: &DeviceModel, spec: GridSpec) -> Result<Self, Error> {
        if master.period_s != slave.period_s {
            return Err(Error::PeriodsDiffer {
                first: (master.name.clone(), master.period_s),
                other: (slave.name.clone(), slave.period_s),
            });
        }
        let plants = [
            Plant::new(master, master.period_s)?,
            Plant::new(slave, slave.period_s)?,
        ];
        let mut omegas: Vec<f64> = plants.iter().flat_map(|p| grid(p, spec)).collect();
        omegas.sort_by(f64::total_cmp);
        omegas.dedup_by(|a, b| (*a - *b).abs() <= 1e-12 * b.abs());
        Ok(TeleopAnalysis {
            master: (master.clone(), Analysis::on(&plants[0], &omegas)),
            slave: (slave.clone(), Analysis::on(&plants[1], &omegas)),
        })
    }

    /// [`new`](Self::new) on the default grid.
    pub fn of(master: &DeviceModel, slave: &DeviceModel) -> Result<Self, Error> {
        Self::new(master, slave, GridSpec::DEFAULT)
    }

    /// The master's model.
    pub fn master(&self) -> &DeviceModel {
        &self.master.0
    }

    /// The slave's model.
    pub fn slave(&self) -> &DeviceModel {
        &self.slave.0
    }

    /// Both devices' responses at each grid point.
    pub(super) fn points(&self) -> (&[crate::PlantPoint], &[crate::PlantPoint]) {
        (&self.master.1.points, &self.slave.1.points)
    }

    /// The grid's angular frequencies (rad/s).
    pub fn omegas(&self) -> impl Iterator<Item = f64> + '_ {
        self.master.1.points.iter().map(|p| p.omega)
    }

    /// Refuse a law that reads a load cell a device does not have.
    fn sensors_for(&self, law: &TeleopTransfer) -> Result<(), Error> {
        let reads = |col: usize| law.z.iter().any(|row| !row[col].num.is_zero());
        for (col, (model, side)) in [
            (3, (&self.master.0, "master")),
            (2, (&self.slave.0, "slave")),
        ] {
            if reads(col) && !model.force_sensor {
                return Err(Error::Teleop(format!(
                    "the law reads the {side}'s load cell, but {} has none (no C_f): \
                     turn its force channels off",
                    model.name
                )));
            }
        }
        Ok(())
    }
}

/// One device's share of the two forces, `centre + zeta ζ + ε` with
/// `|ζ| <= 1` and `|ε| <= eps`: from its sensors' [`HandForms`] and the
/// law's coefficients on its encoder's velocity (`lx`, per row) and its
/// load cell (`lf`).
#[derive(Clone, Copy, Debug)]
struct Share {
    centre: [Complex64; 2],
    zeta: [Complex64; 2],
    eps: [f64; 2],
}

fn share(h: &HandForms, q: Complex64, lx: [Complex64; 2], lf: [Complex64; 2]) -> Share {
    let d = h.delay;
    let x = h.x0 - h.alpha * h.w.centre;
    let f = h.f0 - h.phi * h.w.centre - h.eta.centre;
    let row = |r: usize| {
        (
            d * (-lx[r] * q * x + lf[r] * f),
            d * (lx[r] * q * h.alpha - lf[r] * h.phi) * h.w.radius,
            (d * lf[r]).norm() * h.eta.radius,
        )
    };
    let (r0, r1) = (row(0), row(1));
    Share {
        centre: [r0.0, r1.0],
        zeta: [r0.1, r1.1],
        eps: [r0.2, r1.2],
    }
}

/// The Möbius image of the unit disk under `ζ -> (c + d ζ)/(a + b ζ)`,
/// for `|a| > |b|`: the disk of centre `(c ā - d b̄)/(|a|² - |b|²)` and
/// radius `|c b - d a|/(|a|² - |b|²)`.
fn mobius_image(a: Complex64, b: Complex64, c: Complex64, d: Complex64) -> (Complex64, f64) {
    let den = a.norm_sqr() - b.norm_sqr();
    (
        (c * a.conj() - d * b.conj()) / den,
        (c * b - d * a).norm() / den,
    )
}

/// `max |(c + d ζ)/(a + b ζ)|` over `|ζ| <= 1`, for `|a| > |b|`: the
/// far edge of the [`mobius_image`].
fn max_ratio(a: Complex64, b: Complex64, c: Complex64, d: Complex64) -> f64 {
    let (centre, radius) = mobius_image(a, b, c, d);
    centre.norm() + radius
}

/// The determinant without the load cells' share,
/// `A + B ζ_m + C ζ_s + D ζ_m ζ_s`: `[A, B, C, D]`.
fn bilinear(m: &Share, s: &Share) -> [Complex64; 4] {
    let one = Complex64::new(1.0, 0.0);
    // α = m_1, γ = m_2 (the master's); β = s_1, δ = s_2 (the slave's).
    let (ac, a1, gc, g1) = (m.centre[0], m.zeta[0], m.centre[1], m.zeta[1]);
    let (bc, b1, dc, d1) = (s.centre[0], s.zeta[0], s.centre[1], s.zeta[1]);
    [
        (one - ac) * (one - dc) - bc * gc,
        -a1 * (one - dc) - bc * g1,
        -(one - ac) * d1 - b1 * gc,
        a1 * d1 - b1 * g1,
    ]
}

/// The margin with one side's `ζ` first (`first`, whose `P = a + b ζ`
/// and `Q = c + d ζ`) and the other's solved for. The load cells'
/// share enters the determinant linearly: the other side's `ε`s with
/// coefficients affine in this side's `ζ` (`(ρ, r_0, r_1)`: `ρ |r_0 + r_1
/// ζ|`), this side's with coefficients in the other's `ζ`, bounded by
/// constants (`k`). What must hold over the disk is
/// `|P| > |Q| + Σ ρ |R| + k`; divided by `|P|`, each ratio's largest
/// modulus is its Möbius image's far point, and a sum's largest is at
/// most the sum of theirs.
fn ordered_slack(
    [a, b, c, d]: [Complex64; 4],
    affine: &[(f64, Complex64, Complex64)],
    k: f64,
) -> f64 {
    let den = a.norm_sqr() - b.norm_sqr();
    let p_min = a.norm() - b.norm();
    if p_min <= k || den <= 0.0 {
        return f64::NEG_INFINITY;
    }
    let far = |c: Complex64, d: Complex64| max_ratio(a, b, c, d);
    let perturbed: f64 = affine.iter().map(|(rho, r0, r1)| rho * far(*r0, *r1)).sum();
    1.0 - k / p_min - far(c, d) - perturbed
}

/// The proof's margin at one point (see the module docs): positive where
/// no termination closes a pole there.
fn point_slack(m: &Share, s: &Share) -> f64 {
    let one = Complex64::new(1.0, 0.0);
    let [a, b, c, d] = bilinear(m, s);
    let (ac, a1, gc, g1) = (m.centre[0], m.zeta[0], m.centre[1], m.zeta[1]);
    let (bc, b1, dc, d1) = (s.centre[0], s.zeta[0], s.centre[1], s.zeta[1]);
    let (ra, rg, rb, rd) = (m.eps[0], m.eps[1], s.eps[0], s.eps[1]);
    // det = (1 - α)(1 - δ) - β γ: ε_α's coefficient is -(1 - δ), ε_δ's
    // -(1 - α), ε_β's -γ, ε_γ's -β; the products ε_α ε_δ and ε_β ε_γ.
    let cross = ra * rd + rb * rg;
    let master_first = ordered_slack(
        [a, b, c, d],
        &[(rb, gc, g1), (rd, one - ac, -a1)],
        ra * ((one - dc).norm() + d1.norm()) + rg * (bc.norm() + b1.norm()) + cross,
    );
    let slave_first = ordered_slack(
        [a, c, b, d],
        &[(ra, one - dc, -d1), (rg, bc, b1)],
        rb * (gc.norm() + g1.norm()) + rd * ((one - ac).norm() + a1.norm()) + cross,
    );
    let slack = master_first.max(slave_first);
    if slack.is_nan() {
        f64::NEG_INFINITY
    } else {
        slack
    }
}

/// Where the bilinear determinant vanishes over the two unit disks, if it
/// does: the master's `ζ` that maximises `|Q/P|` (order master first),
/// and the slave's that zeroes it. The image's far point is the centre
/// pushed out by the radius; the Möbius map is inverted there.
fn zeroing(m: &Share, s: &Share) -> Option<(Complex64, Complex64)> {
    let one = Complex64::new(1.0, 0.0);
    let [a, b, c, d] = bilinear(m, s);
    if a.norm_sqr() <= b.norm_sqr() {
        return None;
    }
    let (centre, radius) = mobius_image(a, b, c, d);
    let u = if centre.norm() > 0.0 {
        centre * (1.0 + radius / centre.norm())
    } else {
        Complex64::new(radius, 0.0)
    };
    if u.norm() < 1.0 {
        return None;
    }
    // u = (c + d ζ)/(a + b ζ) at ζ = (c - a u)/(b u - d); P + Q ζ_s = 0.
    let zm = (c - a * u) / (b * u - d);
    let zs = -one / u;
    (zm.is_finite() && zs.is_finite()).then_some((zm, zs))
}

/// The hands' admittances (m/s per N, at `ω`) that close a pole at grid
/// point `i`, where the proof fails there, from its own worst point: each
/// device's `w` realised at the base band alone, `Y = 1/w - Y_hh` (its
/// real part held at 0 or above). `None` where no termination of the
/// disks zeroes the determinant (the load cells' share alone broke the
/// proof), or for the human bound (a hand behind the grasp).
pub fn closing_hands(
    ta: &TeleopAnalysis,
    law: &TeleopTransfer,
    i: usize,
) -> Option<[Complex64; 2]> {
    let [(hm, m), (hs, s)] = shares(ta, law, None, i)?;
    let (zm, zs) = zeroing(&m, &s)?;
    let (pm, ps) = (&ta.master.1.points[i], &ta.slave.1.points[i]);
    let hand = |h: &HandForms, z: Complex64, yhh: Complex64| {
        let y = 1.0 / (h.w.centre + h.w.radius * z) - yhh;
        Complex64::new(y.re.max(0.0), y.im)
    };
    Some([hand(&hm, zm, pm.y[0][0]), hand(&hs, zs, ps.y[0][0])])
}

/// Each device's forms at grid point `i` (the human bound on the
/// master's), and its share of the two forces through `law`; `None`
/// where a handle is lossless there or an alias sum unbounded.
fn shares(
    ta: &TeleopAnalysis,
    law: &TeleopTransfer,
    human: Option<HumanBound>,
    i: usize,
) -> Option<[(HandForms, Share); 2]> {
    let (ma, sa) = (&ta.master.1, &ta.slave.1);
    let (pm, ps) = (ma.points.get(i)?, sa.points.get(i)?);
    let hm = hand_forms(ma.plant(), (i, pm), human, ma.aliases())?;
    let hs = hand_forms(sa.plant(), (i, ps), None, sa.aliases())?;
    let l = law.eval(pm.z);
    let q = (Complex64::new(1.0, 0.0) - pm.z.inv()) / ma.period_s;
    Some([
        (hm, share(&hm, q, [l[0][0], l[1][0]], [l[0][3], l[1][3]])),
        (hs, share(&hs, q, [l[0][1], l[1][1]], [l[0][2], l[1][2]])),
    ])
}

/// The proof's margin at each grid point for the law `law` (its forms,
/// channel delay included), the human bound `human` at the master's
/// handle: positive where no passive operator and environment put a pole
/// at `e^{jωT}`; `-∞` where the proof cannot hold (a lossless handle, a
/// term unbounded).
pub fn teleop_slack(
    ta: &TeleopAnalysis,
    law: &TeleopTransfer,
    human: Option<HumanBound>,
) -> Result<Vec<f64>, Error> {
    ta.sensors_for(law)?;
    Ok(crate::par::map(ta.master.1.points.len(), |i| {
        shares(ta, law, human, i).map_or(f64::NEG_INFINITY, |[(_, m), (_, s)]| point_slack(&m, &s))
    }))
}

/// The proof's verdict on one teleoperator.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct TeleopCheck {
    /// Absolutely stable: the slack is positive at every frequency, down
    /// to DC, and the loop is stable with both ends let go.
    pub proven: bool,
    /// The least slack (between grid points too, see [`least`]); 1 is the
    /// most, below 0 some passive termination closes a pole.
    pub slack: f64,
    /// Where it is least (Hz).
    pub frequency_hz: f64,
    /// Whether the slack stays positive toward DC, below the grid: its
    /// limit from the two lowest points (the slack is even in `ω`).
    pub holds_toward_dc: bool,
    /// The spectral radius of the exact loop with both ends let go.
    pub let_go_radius: f64,
}

/// Whether the slack stays positive from the grid's lowest frequency
/// `ω_1` down to DC. The slack is even in `ω` (a conjugate frequency has
/// the conjugate disks), `s(ω) = s_0 + s_2 ω² + O(ω⁴)`, and Richardson's
/// step from `ω_1` and `2 ω_1` gives both. A limit clearly away from zero
/// decides alone; one within 1% of the samples is a slack that vanishes
/// as `ω²` (the rigid bodies' double pole at `z = 1`), and holds iff it
/// grows from DC. A law that reads a load cell meets the aliases' share
/// of it here: bounded apart from the hand's base band, it does not
/// vanish with the slack, and the limit falls below zero.
fn toward_dc(a: &Analysis, slack: &[f64]) -> bool {
    let Some(i2) = a.dc_pair else {
        return false;
    };
    let (s1, s2) = (slack[0], slack[i2]);
    let w2 = a.points[0].omega * a.points[0].omega;
    let (s0, c2) = ((4.0 * s1 - s2) / 3.0, (s2 - s1) / (3.0 * w2));
    if s0.abs() > 0.01 * s1.abs().max(s2.abs()) {
        s0 > 0.0
    } else {
        c2 > 0.0
    }
}

/// Prove the teleoperator `law` between `ta`'s devices (see the module
/// docs), the human bound `human` at the master's handle.
pub fn check_teleop(
    ta: &TeleopAnalysis,
    law: &TeleopTransfer,
    human: Option<HumanBound>,
) -> Result<TeleopCheck, Error> {
    let slack = teleop_slack(ta, law, human)?;
    let (least_slack, omega) = least(&ta.master.1.points, &slack);
    let t = Teleoperator {
        master: &ta.master.0,
        slave: &ta.slave.0,
        law: *law,
    };
    let ends = TeleopTermination {
        operator: Hand::OFF,
        environment: Hand::OFF,
    };
    let let_go = teleop_radius(&t, &ends).map_err(Error::Teleop)?;
    let holds_toward_dc = toward_dc(&ta.master.1, &slack);
    Ok(TeleopCheck {
        proven: least_slack > 0.0 && holds_toward_dc && !let_go.unstable,
        slack: least_slack,
        frequency_hz: omega / (2.0 * PI),
        holds_toward_dc,
        let_go_radius: let_go.spectral_radius,
    })
}

#[cfg(test)]
mod tests;
