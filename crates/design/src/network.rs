//! The haptic-interface two-ports (docs/two-port.md), their design bounds
//! and Llewellyn's absolute-stability criteria.

use crate::PlantPoint;
use num_complex::Complex64;
use twoport_control::ZTransfer;

/// The human operator's bound `Z_max(s) = b + k/s` (N s/m), or none.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct HumanBound {
    /// Damping (N s/m).
    pub damping_nspm: f64,
    /// Stiffness (N/m).
    pub stiffness_npm: f64,
}

impl HumanBound {
    /// The paper's `Z_max = 300 + 1000/s` (section IV-C-3).
    pub const PAPER: HumanBound = HumanBound {
        damping_nspm: 300.0,
        stiffness_npm: 1000.0,
    };

    /// `1/Z_max(s)` (m/(N s)).
    pub fn admittance(&self, s: Complex64) -> Complex64 {
        (self.damping_nspm + self.stiffness_npm / s).inv()
    }
}

/// A two-port immittance matrix `[[p11, p12], [p21, p22]]` at one frequency.
pub type Matrix2 = [[Complex64; 2]; 2];

/// `Y_hh`, with the human bound folded in as `Y_hh + 1/Z_max`.
fn y_hh(p: &PlantPoint, human: Option<HumanBound>) -> Complex64 {
    p.y[0][0] + human.map_or(Complex64::new(0.0, 0.0), |h| h.admittance(p.s))
}

/// The impedance display's hybrid form without the coupling (section 3):
/// `[[Y_hh, Y_hc], [Y_ch*, Y_cc*]]`. A measurement-to-actuation delay
/// `z^-d` delays everything the coupling force drives (the second column);
/// a latency inside the tick delays the held force (`Y_cc*`'s sampled
/// term includes it).
pub fn impedance_display(p: &PlantPoint, human: Option<HumanBound>) -> Matrix2 {
    [
        [y_hh(p, human), p.y[0][1] * p.hold * p.latency() * p.delay],
        [
            p.hold * p.y[1][0],
            p.delay * (Complex64::new(1.0, 0.0) - p.z.inv()) / p.period_s * p.xaa_d,
        ],
    ]
}

/// The admittance display's alternate hybrid form without the coupling
/// (section 4), for the position regulator `K_p` (the control crate's law):
/// `[[G_hh, G_hc], [G_ch*, G_cc*]]`.
pub fn admittance_display(p: &PlantPoint, kp: &ZTransfer, human: Option<HumanBound>) -> Matrix2 {
    let one = Complex64::new(1.0, 0.0);
    // A measurement-to-actuation delay acts as part of the regulator.
    let k = kp.eval(p.z) * p.delay;
    let den = one + p.xaa_d * k;
    let x_ah = p.y[1][0] / p.s;
    let integ = p.period_s / (one - p.z.inv());
    // The held force's way to the handle, the latency inside the tick on it.
    let held = p.y[0][1] * p.hold * p.latency();
    [
        [
            y_hh(p, human) - held * k * x_ah / den,
            held * k / den * integ,
        ],
        [p.f[0] - p.fma_d * k * x_ah / den, p.fma_d * k / den * integ],
    ]
}

/// The right side of a design inequality: `(|p12 p21| + Re(p12 p21)) /
/// (2 Re p11) - Re p22`. The coupling term must reach it at every
/// frequency: `Re(1/Z_cI)` for the impedance display (eq 25 as corrected),
/// `Re Z_cA` for the admittance display (eq 28). Infinite where
/// `Re p11 <= 0` (no coupling helps).
pub fn design_bound(p: &Matrix2) -> f64 {
    let prod = p[0][1] * p[1][0];
    let re11 = p[0][0].re;
    if re11 <= 0.0 {
        return f64::INFINITY;
    }
    (prod.norm() + prod.re) / (2.0 * re11) - p[1][1].re
}

/// Llewellyn's criteria at one frequency, as a margin: `η - 1` where
/// `η = (2 Re p11 Re p22 - Re(p12 p21)) / |p12 p21|`, so the two-port is
/// absolutely stable there iff the margin is >= 0 (with `Re p11`,
/// `Re p22 >= 0`; a negative real part gives `-∞`). A two-port with no
/// coupling between its ports (`p12 p21 = 0`) has margin `+∞`.
pub fn llewellyn_margin(p: &Matrix2) -> f64 {
    let (r11, r22) = (p[0][0].re, p[1][1].re);
    if r11 < 0.0 || r22 < 0.0 || r11.is_nan() || r22.is_nan() {
        return f64::NEG_INFINITY;
    }
    let prod = p[0][1] * p[1][0];
    let mag = prod.norm();
    if mag == 0.0 {
        return f64::INFINITY;
    }
    (2.0 * r11 * r22 - prod.re) / mag - 1.0
}

/// The full impedance-display interface `[[Y_hh, Y_hc], [Y_ch, Y_cc + 1/Z_cI]]`.
pub fn with_impedance_coupling(y: &Matrix2, zc: Complex64) -> Matrix2 {
    [y[0], [y[1][0], y[1][1] + zc.inv()]]
}

/// The full admittance-display interface `[[G_hh, G_hc], [G_ch, G_cc + Z_cA]]`.
pub fn with_admittance_coupling(g: &Matrix2, zc: Complex64) -> Matrix2 {
    [g[0], [g[1][0], g[1][1] + zc]]
}

/// The four immittance forms of a two-port (paper section II), by which port
/// variables are the inputs: port 1 `(f_1, v_1)`, port 2 `(f_2, v_2)` with
/// the paper's signs (`f_e*`, `-v_e*` at the VE port).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Immittance {
    /// Impedance: velocities in, forces out.
    Z,
    /// Admittance: forces in, velocities out.
    Y,
    /// Hybrid: `v_1`, `f_2` in; `f_1`, `v_2` out.
    H,
    /// Alternate hybrid: `f_1`, `v_2` in; `v_1`, `f_2` out.
    G,
}

impl Immittance {
    /// Whether port `k` (0 or 1) takes its velocity as the input.
    fn velocity_in(self, k: usize) -> bool {
        match (self, k) {
            (Immittance::Z, _) | (Immittance::H, 0) | (Immittance::G, 1) => true,
            (Immittance::Y, _) | (Immittance::H, 1) | (Immittance::G, 0) => false,
            _ => unreachable!("a two-port has ports 0 and 1"),
        }
    }
}

/// Swap the input and output of port `k` (a principal pivot on `p[k][k]`);
/// `None` where that entry is zero (the target form does not exist).
fn pivot(p: &Matrix2, k: usize) -> Option<Matrix2> {
    let o = 1 - k;
    let piv = p[k][k];
    if piv.norm() == 0.0 || !piv.norm().is_finite() {
        return None;
    }
    let inv = piv.inv();
    let mut q = *p;
    q[k][k] = inv;
    q[k][o] = -p[k][o] * inv;
    q[o][k] = p[o][k] * inv;
    q[o][o] = p[o][o] - p[o][k] * p[k][o] * inv;
    Some(q)
}

/// Convert a two-port matrix from one immittance form to another; `None`
/// where the target form does not exist.
pub fn convert(p: &Matrix2, from: Immittance, to: Immittance) -> Option<Matrix2> {
    let mut q = *p;
    for k in 0..2 {
        if from.velocity_in(k) != to.velocity_in(k) {
            q = pivot(&q, k)?;
        }
    }
    Some(q)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn c(re: f64, im: f64) -> Complex64 {
        Complex64::new(re, im)
    }

    fn sample(seed: u64) -> Matrix2 {
        let mut x = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
        let mut r = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x % 2001) as f64 / 1000.0 - 1.0
        };
        [
            [c(r() + 1.5, r()), c(r(), r())],
            [c(r(), r()), c(r() + 1.5, r())],
        ]
    }

    fn close(a: &Matrix2, b: &Matrix2) -> bool {
        (0..4).all(|i| (a[i / 2][i % 2] - b[i / 2][i % 2]).norm() < 1e-9)
    }

    #[test]
    fn conversions_match_the_textbook_formulas() {
        let z = sample(1);
        let det = z[0][0] * z[1][1] - z[0][1] * z[1][0];
        let y = convert(&z, Immittance::Z, Immittance::Y).unwrap();
        let want_y = [
            [z[1][1] / det, -z[0][1] / det],
            [-z[1][0] / det, z[0][0] / det],
        ];
        assert!(close(&y, &want_y));
        let h = convert(&z, Immittance::Z, Immittance::H).unwrap();
        let want_h = [
            [det / z[1][1], z[0][1] / z[1][1]],
            [-z[1][0] / z[1][1], z[1][1].inv()],
        ];
        assert!(close(&h, &want_h));
        let g = convert(&z, Immittance::Z, Immittance::G).unwrap();
        let want_g = [
            [z[0][0].inv(), -z[0][1] / z[0][0]],
            [z[1][0] / z[0][0], det / z[0][0]],
        ];
        assert!(close(&g, &want_g));
    }

    /// Every form converts to every other and back, and Llewellyn's `η` is
    /// the same in all four (absolute stability does not depend on the form).
    #[test]
    fn round_trips_and_eta_invariance() {
        let forms = [Immittance::Z, Immittance::Y, Immittance::H, Immittance::G];
        for seed in 1..200 {
            let z = sample(seed);
            let eta = llewellyn_margin(&z);
            for &a in &forms {
                let pa = convert(&z, Immittance::Z, a).unwrap();
                for &b in &forms {
                    let pb = convert(&pa, a, b).unwrap();
                    assert!(
                        close(&convert(&pb, b, a).unwrap(), &pa),
                        "{a:?} -> {b:?} -> {a:?}"
                    );
                }
                if eta.is_finite() && llewellyn_margin(&pa).is_finite() {
                    assert!(
                        (llewellyn_margin(&pa) - eta).abs() < 1e-7 * eta.abs().max(1.0),
                        "seed {seed} {a:?}"
                    );
                } else {
                    assert_eq!(
                        llewellyn_margin(&pa) >= 0.0,
                        eta >= 0.0,
                        "seed {seed} {a:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn a_missing_form_is_none() {
        let z = [[c(0.0, 0.0), c(1.0, 0.0)], [c(1.0, 0.0), c(2.0, 0.0)]];
        assert!(convert(&z, Immittance::Z, Immittance::G).is_none());
    }
}
