//! `twoport check`: given gains against the sound and the paper's
//! inequality, and their margin to the boundary.

use crate::args::*;
use crate::run::*;

pub(crate) fn check(g: &Display<ImpedanceGains, AdmittanceGains>) -> Result<(), String> {
    let (common, r) = match g {
        Display::Impedance(g) => (&g.common, designer(&g.common)?.check_impedance(g.k, g.b)),
        Display::Admittance(g) => (
            &g.common,
            designer(&g.common)?.check_admittance((g.kp, g.bp), g.m, g.b),
        ),
    };
    emit(common, &r.map_err(|e| e.to_string())?)
}
