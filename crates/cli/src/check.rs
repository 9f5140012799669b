//! `twoport check`: given gains against the sound and the paper's
//! inequality, and their margin to the boundary.

use crate::args::*;
use crate::run::*;
use twoport_design::DeviceAxis;

pub(crate) fn check(
    g: &Display<ImpedanceGains, AdmittanceGains>,
    axis: Option<&DeviceAxis>,
) -> Reported {
    let r = match g {
        Display::Impedance(g) => {
            let (k, b) = (gain("k", g.k)?, gain("b", g.b)?);
            designer(&g.common, axis)?.check_impedance(k, b)
        }
        Display::Admittance(g) => {
            let kp = (gain("kp", g.kp)?, gain("bp", g.bp)?);
            let b = gain("b", g.b)?;
            if !(g.m.is_finite() && g.m > 0.0) {
                return Err(format!("--m {}: must be a finite mass > 0 kg", g.m));
            }
            designer(&g.common, axis)?.check_admittance(kp, g.m, b)
        }
    };
    reported(r.map_err(|e| e.to_string())?)
}
