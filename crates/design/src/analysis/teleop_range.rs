//! What the operator feels through a teleoperator (its transmitted
//! impedance, the teleoperator's Z-width): the impedance at the master's
//! handle with the slave in free space and against a rigid wall, from
//! the devices' hybrid forms at the base band (the paper's eqs 32 and 33
//! for a coupling, aliasing neglected, as there).

use super::teleop::TeleopAnalysis;
use crate::network::impedance_display;
use crate::PlantPoint;
use num_complex::Complex64;
use twoport_control::teleop::TeleopTransfer;

/// One device at one frequency: its handle and its sensors, per handle
/// force `f` and held law force `F` (the paper's sign).
struct Side {
    /// Handle velocity: `Y_hh f + Y_hc F`.
    yhh: Complex64,
    yhc: Complex64,
    /// The sampled coupling-port velocity (minus the law's): `Y_ch f +
    /// Y_cc F`.
    ych: Complex64,
    ycc: Complex64,
    /// The load cell: `F_h f + F_a F`.
    fh: Complex64,
    fa: Complex64,
}

impl Side {
    fn at(p: &PlantPoint) -> Side {
        let y = impedance_display(p, None);
        Side {
            yhh: y[0][0],
            yhc: y[0][1],
            ych: y[1][0],
            ycc: y[1][1],
            fh: p.f[0],
            fa: p.fma_d * p.delay,
        }
    }
}

/// The impedance the operator feels at the master's handle (N s/m),
/// the slave's handle free (`rigid` false) or held still (true), at one
/// frequency: the two law forces solved from the law and both devices.
fn felt(m: &Side, s: &Side, l: &[[Complex64; 4]; 2], rigid: bool) -> Complex64 {
    // Unit operator force. The slave's handle force is 0 (free) or what
    // holds its handle still: f_s = -Y_hc F_s / Y_hh.
    let env = if rigid {
        -s.yhc / s.yhh
    } else {
        Complex64::new(0.0, 0.0)
    };
    // Each side's encoder velocity (the law's, minus the port's) and load
    // cell as `a + b F_own`.
    let (um0, um1) = (-m.ych, -m.ycc);
    let (lm0, lm1) = (m.fh, m.fa);
    let (us1, ls1) = (-(s.ych * env + s.ycc), s.fh * env + s.fa);
    // F_r = L_r0 u_m + L_r1 u_s + L_r2 l_s + L_r3 l_m: linear in (F_m, F_s).
    let row = |r: usize| {
        let c = l[r][0] * um0 + l[r][3] * lm0;
        let cm = l[r][0] * um1 + l[r][3] * lm1;
        let cs = l[r][1] * us1 + l[r][2] * ls1;
        (c, cm, cs)
    };
    let one = Complex64::new(1.0, 0.0);
    let ((c0, m0, s0), (c1, m1, s1)) = (row(0), row(1));
    // [1 - m0, -s0; -m1, 1 - s1] [F_m; F_s] = [c0; c1].
    let det = (one - m0) * (one - s1) - s0 * m1;
    let f_m = (c0 * (one - s1) + s0 * c1) / det;
    (m.yhh + m.yhc * f_m).inv()
}

/// The transmitted impedance at each grid point: `(ω, Z_free, Z_rigid)`
/// (rad/s, N s/m), the slave in free space and against a rigid wall.
pub fn teleop_range(ta: &TeleopAnalysis, law: &TeleopTransfer) -> Vec<(f64, Complex64, Complex64)> {
    let (mp, sp) = ta.points();
    mp.iter()
        .zip(sp)
        .map(|(pm, ps)| {
            let (m, s) = (Side::at(pm), Side::at(ps));
            let l = law.eval(pm.z);
            (pm.omega, felt(&m, &s, &l, false), felt(&m, &s, &l, true))
        })
        .collect()
}

/// What the operator feels at the lowest grid frequency: through free
/// space the mass (kg) and damping (N s/m), `Z_free ≈ b + m s`; against
/// a rigid wall the stiffness (N/m), `Z_rigid ≈ k/s`.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Felt {
    /// Through free space: the mass felt (kg).
    pub free_mass_kg: f64,
    /// Through free space: the damping felt (N s/m).
    pub free_damping_nspm: f64,
    /// Against a rigid wall: the stiffness felt (N/m).
    pub wall_stiffness_npm: f64,
}

/// [`Felt`] from the range's lowest point.
pub fn felt_at_low_frequency(range: &[(f64, Complex64, Complex64)]) -> Option<Felt> {
    let (w, free, rigid) = *range.first()?;
    Some(Felt {
        free_mass_kg: free.im / w,
        free_damping_nspm: free.re,
        wall_stiffness_npm: -rigid.im * w,
    })
}
