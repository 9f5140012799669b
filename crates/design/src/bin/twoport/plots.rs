//! `twoport zrange` and `twoport plot`: the impedance range and the
//! paper's figures.

use crate::args::*;
use crate::run::*;
use serde_json::json;
use std::f64::consts::PI;
use twoport_design::analysis::{self, Analysis};
use twoport_design::network::HumanBound;
use twoport_design::{figures, plot};

pub(crate) fn zrange(d: &Display<ZrangeImpedance, ZrangeAdmittance>) -> Result<(), String> {
    let (common, points) = match d {
        Display::Impedance(z) => (&z.gains.common, z.points),
        Display::Admittance(z) => (&z.gains.common, z.points),
    };
    if points < 2 {
        return Err(format!("--points {points}: need at least 2"));
    }
    let s = designer(common)?;
    let pose = single(&s, "zrange")?;
    let nyq = pose.plant.nyquist();
    let lo = 2.0 * PI * 0.1;
    let omegas = analysis::log_grid(lo, nyq, points);
    let a = Analysis::on(&pose.plant, &omegas);
    let range = match d {
        Display::Impedance(z) => {
            let (k, b) = (gain("k", z.gains.k)?, gain("b", z.gains.b)?);
            analysis::impedance_range_impedance(&a, k, b)
        }
        Display::Admittance(z) => {
            let g = &z.gains;
            analysis::impedance_range_admittance(
                &a,
                (gain("kp", g.kp)?, gain("bp", g.bp)?),
                (g.m, gain("b", g.b)?),
            )
        }
    }
    .ok_or("the gains do not make a valid coupling")?;
    let freq: Vec<f64> = omegas.iter().map(|w| w / (2.0 * PI)).collect();
    let pair = |c: num_complex::Complex64| [c.re, c.im];
    let v = json!({
        "freq_hz": freq,
        "z_min": range.iter().map(|r| pair(r.0)).collect::<Vec<_>>(),
        "z_max": range.iter().map(|r| pair(r.1)).collect::<Vec<_>>(),
    });
    let mut text = format!(
        "{:>12} {:>14} {:>14}",
        "freq (Hz)", "|Z_min| N s/m", "|Z_max| N s/m"
    );
    for (f, r) in freq.iter().zip(&range) {
        text += &format!("\n{f:>12.3} {:>14.4e} {:>14.4e}", r.0.norm(), r.1.norm());
    }
    emit(common, &Printed(v, text))
}

pub(crate) fn plot_fig(p: &PlotArgs) -> Result<(), String> {
    let s = designer(&p.common)?;
    let a = &single(&s, "plot")?.analysis;
    let t = s.period_s();
    let bi = a.impedance_bound(Some(HumanBound::PAPER));
    let (k, b) = analysis::max_stiffness(a, &bi, gain("b-impedance", p.b_impedance)?)
        .map(|k| (k, p.b_impedance))
        .ok_or("no impedance coupling meets the bound at --b-impedance")?;
    let kp = analysis::regulator_tf(k, b, t).map_err(|e| e.to_string())?;
    let ba = a.admittance_bound(&kp, Some(HumanBound::PAPER));
    let m = analysis::min_mass(a, &ba, gain("b-admittance", p.b_admittance)?)
        .ok_or("no admittance coupling meets the bound at --b-admittance")?;
    let fig = match p.figure {
        Fig::Fig8 => figures::fig8(a, k, b),
        Fig::Fig9 => figures::fig9(a, (k, b), (m, p.b_admittance)),
        Fig::Fig10 => figures::fig10(a, (k, b), (k, b), (m, p.b_admittance)),
    }
    .map_err(|e| e.to_string())?;
    plot::render(&fig, &p.out).map_err(|e| e.to_string())?;
    let v = json!({"out": p.out, "k_c": k, "b_c": b, "m_c": m, "b_cA": p.b_admittance});
    let text = format!(
        "wrote {} (k_c = {k:.0} N/m, b_c = {b} N s/m, m_c = {m:.3} kg, b_cA = {} N s/m)",
        p.out.display(),
        p.b_admittance
    );
    emit(&p.common, &Printed(v, text))
}
