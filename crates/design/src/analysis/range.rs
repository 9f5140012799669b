//! The impedance range the human can feel (eqs 32, 33).

use super::check::admittance_laws;
use super::{impedance_coupling_tf, Analysis};
use crate::network::{admittance_display, impedance_display};
use num_complex::Complex64;

/// The impedance range (eqs 32, 33) at each grid point: `(Z_min, Z_max)`
/// (N s/m), the impedances the human feels with the VE port shorted
/// (free motion) and open (rigid constraint).
pub fn impedance_range_impedance(
    a: &Analysis,
    k: f64,
    b: f64,
) -> Option<Vec<(Complex64, Complex64)>> {
    let tf = impedance_coupling_tf(k, b, a.period_s).ok()?;
    Some(
        a.points
            .iter()
            .map(|p| {
                let y = impedance_display(p, None);
                let zmin = y[0][0].inv();
                let zmax = (y[0][0] - y[0][1] * y[1][0] / (y[1][1] + tf.eval(p.z).inv())).inv();
                (zmin, zmax)
            })
            .collect(),
    )
}

/// The admittance display's impedance range: `(Z_min, Z_max)` (N s/m).
pub fn impedance_range_admittance(
    a: &Analysis,
    (kp, bp): (f64, f64),
    (m, b): (f64, f64),
) -> Option<Vec<(Complex64, Complex64)>> {
    let (k, zc) = admittance_laws(a, (kp, bp), (m, b))?;
    Some(
        a.points
            .iter()
            .map(|p| {
                let g = admittance_display(p, &k, None);
                let zmax = g[0][0].inv();
                let zmin = (g[0][0] - g[0][1] * g[1][0] / (g[1][1] + zc.eval(p.z))).inv();
                (zmin, zmax)
            })
            .collect(),
    )
}
