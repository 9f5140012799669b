//! `twoport verify`: the counterexample search, over every pose.

use crate::args::*;
use crate::run::*;
use twoport_control::{AdmittanceGains as Adm, Gains, ImpedanceGains as Imp};

pub(crate) fn verify(d: &Display<ImpedanceGains, AdmittanceGains>) -> Result<(), String> {
    // The board's f32 gains: the laws are built from them either way.
    let (common, gains) = match d {
        Display::Impedance(g) => (
            &g.common,
            Gains::from(Imp::new(gain("k", g.k)? as f32, gain("b", g.b)? as f32)),
        ),
        Display::Admittance(g) => {
            if !(g.m.is_finite() && g.m > 0.0) {
                return Err(format!("--m {}: must be a finite mass > 0 kg", g.m));
            }
            (
                &g.common,
                Gains::from(Adm::new(
                    gain("kp", g.kp)? as f32,
                    gain("bp", g.bp)? as f32,
                    g.m as f32,
                    gain("b", g.b)? as f32,
                )),
            )
        }
    };
    let r = designer(common)?
        .verify(&gains)
        .map_err(|e| e.to_string())?;
    emit(common, &r)
}
