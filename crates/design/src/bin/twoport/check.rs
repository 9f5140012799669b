//! `twoport check`: given gains against the sound and the paper's
//! inequality, and their margin to the boundary.

use crate::args::*;
use crate::session::*;
use crate::synthesis::*;
use serde_json::{json, Value};
use twoport_design::design;

pub(crate) fn check_json(c: &design::Check) -> Value {
    let p = &c.paper;
    let binding = if c.sampled_binds() {
        "sampled-data"
    } else {
        "both"
    };
    json!({"absolutely_stable": c.absolutely_stable, "min_margin": c.min_margin,
        "worst_frequency_hz": c.worst_frequency_hz, "binding_bound": binding,
        "paper_absolutely_stable": p.absolutely_stable, "paper_min_margin": p.min_margin,
        "paper_worst_frequency_hz": p.worst_frequency_hz})
}

pub(crate) fn print_check(c: &design::Check) {
    let verdict = |ok| {
        if ok {
            "absolutely stable (proven)"
        } else {
            "NOT proven absolutely stable"
        }
    };
    println!(
        "  {}: least margin {:.4} at {:.2} Hz (sampled-data analysis)",
        verdict(c.absolutely_stable),
        c.min_margin,
        c.worst_frequency_hz
    );
    let p = &c.paper;
    if c.sampled_binds() {
        println!(
            "  the paper's approximation (aliasing at the handle neglected) would say {}: margin {:.4} at {:.2} Hz",
            verdict(p.absolutely_stable),
            p.min_margin,
            p.worst_frequency_hz
        );
    }
}

/// The gain margin line of `check`: how far inside (or past) the boundary
/// `boundary` at the same damping the gains are.
pub(crate) fn print_gain_margin(margin: Option<f64>, boundary: Option<String>) {
    match (margin, boundary) {
        (Some(g), Some(b)) if g >= 0.0 => println!(
            "  gain margin {:.2}%: the boundary at this damping is {b}",
            100.0 * g
        ),
        (Some(g), Some(b)) => println!(
            "  {:.2}% past the boundary at this damping, {b}",
            -100.0 * g
        ),
        _ => println!("  nothing is proven at this damping"),
    }
}

pub(crate) fn check(d: &Display<ImpedanceGains, AdmittanceGains>) -> Result<(), String> {
    match d {
        Display::Impedance(g) => {
            let s = Session::open(&g.common)?;
            let (k, b) = (gain("k", g.k)?, gain("b", g.b)?);
            let (c, pose) = s
                .worst_check(|p| design::check_impedance(&p.analysis, k, b, s.human))
                .ok_or_else(|| {
                    format!("--k {k} --b {b}: not a valid coupling (k T + b must be > 0)")
                })?;
            let mut v = check_json(&c);
            v["display"] = json!("impedance");
            if s.poses.len() > 1 {
                v["worst_pose"] = json!(pose);
            }
            // How far below the boundary at this damping: 1 - k/k_max.
            let boundary = impedance_design(&s, Some(b))?.map(|(k, _)| k);
            let gain_margin = boundary.map(|kb| 1.0 - k / kb);
            v["boundary_k_c"] = json!(boundary);
            v["gain_margin"] = json!(gain_margin);
            s.emit(v, || {
                s.header("Impedance");
                println!("  coupling k_c = {k} N/m, b_c = {b} N s/m");
                print_check(&c);
                print_gain_margin(gain_margin, boundary.map(|k| Limit::Stiffness.text(k)));
            });
        }
        Display::Admittance(g) => {
            let s = Session::open(&g.common)?;
            s.force_sensor()?;
            let kp = (gain("kp", g.kp)?, gain("bp", g.bp)?);
            let mb = (g.m, gain("b", g.b)?);
            if !(g.m.is_finite() && g.m > 0.0) {
                return Err(format!("--m {}: must be a finite mass > 0 kg", g.m));
            }
            let (c, pose) = s
                .worst_check(|p| design::check_admittance(&p.plant, &p.analysis, kp, mb, s.human))
                .ok_or("--b must be > 0 for the admittance coupling")?;
            let mut v = check_json(&c);
            v["display"] = json!("admittance");
            if s.poses.len() > 1 {
                v["worst_pose"] = json!(pose);
            }
            v["regulator_pole_radius"] = json!(c.regulator_pole_radius);
            // How far above the boundary at this damping: 1 - m_min/m.
            let k = design::regulator_tf(kp.0, kp.1, s.period()).map_err(|e| e.to_string())?;
            let bounds = s.admittance_bounds(&k, false);
            let boundary = admittance_design_on(&s, &bounds, c.regulator_pole_radius, Some(mb.1))?
                .map(|(m, _)| m);
            let gain_margin = boundary.map(|m| 1.0 - m / mb.0);
            v["boundary_m_c"] = json!(boundary);
            v["gain_margin"] = json!(gain_margin);
            s.emit(v, || {
                s.header("Admittance");
                println!("  regulator k_p = {} N/m, b_p = {} N s/m; coupling m_c = {} kg, b_c = {} N s/m", kp.0, kp.1, mb.0, mb.1);
                println!("  regulated device pole radius {:.4}", c.regulator_pole_radius);
                print_check(&c);
                print_gain_margin(gain_margin, boundary.map(|m| Limit::Mass.text(m)));
            });
        }
    }
    Ok(())
}
