//! `twoport design`: the boundary coupling of either display, the
//! recommended gain inside it, and what binds.

use crate::args::*;
use crate::session::*;
use serde_json::{json, Value};
use twoport_design::design;

/// What a design limits: the impedance display's coupling stiffness (more
/// is bolder) or the admittance display's coupling mass (less is).
#[derive(Clone, Copy)]
pub(crate) enum Limit {
    Stiffness,
    Mass,
}

impl Limit {
    /// `x` as published, with its unit: a stiffness rounded down (N/m), a
    /// mass up to the gram (kg), never past its proof.
    pub(crate) fn text(self, x: f64) -> String {
        match self {
            Limit::Stiffness => format!("{:.0} N/m", x.floor()),
            Limit::Mass => format!("{:.3} kg", (x * 1e3).ceil() / 1e3),
        }
    }

    /// The gain `margin` (a fraction) inside the boundary `x`.
    pub(crate) fn inside(self, x: f64, margin: f64) -> f64 {
        match self {
            Limit::Stiffness => x * (1.0 - margin),
            Limit::Mass => x / (1.0 - margin),
        }
    }
}

/// The text lines of a design `r` (limit, damping): the boundary, at the
/// asked damping (`fixed_b`) or the best pair, and the recommended gain
/// `margin` inside it; `v`'s message where there is none.
pub(crate) fn print_design(
    limit: Limit,
    r: Option<(f64, f64)>,
    fixed_b: bool,
    margin: f64,
    v: &Value,
) {
    let (name, most, side) = match limit {
        Limit::Stiffness => ("k_c", "greatest", "below"),
        Limit::Mass => ("m_c", "least", "above"),
    };
    match r {
        Some((x, b)) if fixed_b => println!(
            "  {most} {name} at b_c = {b} N s/m: {} (the boundary)",
            limit.text(x)
        ),
        Some((x, b)) => println!(
            "  best coupling: {name} = {}, b_c = {b:.1} N s/m (the boundary)",
            limit.text(x)
        ),
        None => println!("  infeasible: {}", v["message"].as_str().unwrap_or("")),
    }
    if let Some((x, _)) = r {
        println!(
            "  recommended: {name} = {}, {:.0}% {side} the boundary",
            limit.text(limit.inside(x, margin)),
            100.0 * margin
        );
    }
}

pub(crate) fn impedance_design_on(
    s: &Session,
    bounds: &[Vec<f64>],
    b: Option<f64>,
) -> Result<Option<(f64, f64)>, String> {
    let poses = s.with(bounds);
    Ok(match b {
        Some(b) => design::max_stiffness_poses(&poses, gain("b", b)?).map(|k| (k, b)),
        None => design::best_impedance_poses(&poses),
    })
}

/// The admittance design on `bounds` for a regulator whose regulated
/// device has pole radius `radius`: none where that is unstable.
pub(crate) fn admittance_design_on(
    s: &Session,
    bounds: &[Vec<f64>],
    radius: f64,
    b: Option<f64>,
) -> Result<Option<(f64, f64)>, String> {
    let poses = s.with(bounds);
    Ok(if radius >= 1.0 {
        None
    } else {
        match b {
            Some(b) => design::min_mass_poses(&poses, gain("b", b)?).map(|m| (m, b)),
            None => design::best_admittance_poses(&poses),
        }
    })
}

pub(crate) fn impedance_design(s: &Session, b: Option<f64>) -> Result<Option<(f64, f64)>, String> {
    impedance_design_on(s, &s.impedance_bounds(false), b)
}

/// Where a design binds: the pose (when there are several) and frequency.
pub(crate) fn binding_pose(v: &mut Value, s: &Session, c: Option<(design::Check, &str)>) {
    if let Some((c, name)) = c {
        v["binding_frequency_hz"] = json!(c.worst_frequency_hz);
        if s.poses.len() > 1 {
            v["binding_pose"] = json!(name);
        }
    }
}

pub(crate) fn binding_pose_text(v: &Value) -> Option<String> {
    let f = v["binding_frequency_hz"].as_f64()?;
    Some(match v["binding_pose"].as_str() {
        Some(p) => format!("  binds at {f:.2} Hz in pose {p}"),
        None => format!("  binds at {f:.2} Hz"),
    })
}

/// The sound design `r` and the paper's `paper` as `(limit, b_c)` into `v`
/// (`key` and `paper_key`, with `b_c`), and which of the two binds.
pub(crate) fn designs(
    v: &mut Value,
    key: &str,
    r: Option<(f64, f64)>,
    paper: Option<(f64, f64)>,
    more_is_bolder: bool,
) {
    if let Some((l, b)) = paper {
        v[format!("paper_{key}")] = json!(l);
        v["paper_b_c"] = json!(b);
    }
    if let Some((l, b)) = r {
        v[key] = json!(l);
        v["b_c"] = json!(b);
    }
    binding(v, r.map(|r| r.0), paper.map(|p| p.0), more_is_bolder);
}

/// Which bound set a design, and by how much the paper's approximation
/// (aliasing at the handle port neglected) would have claimed more. `sound`
/// and `paper` are the designed limits; `more_is_bolder` says whether a
/// larger limit claims more (a stiffness) or less (a mass).
pub(crate) fn binding(v: &mut Value, sound: Option<f64>, paper: Option<f64>, more_is_bolder: bool) {
    let (text, by) = match (sound, paper) {
        (Some(s), Some(p)) => {
            let by = if more_is_bolder {
                (p - s) / p
            } else {
                (s - p) / p
            };
            if by > 1e-5 {
                ("sampled-data", by)
            } else {
                ("both", by.max(0.0))
            }
        }
        (None, Some(_)) => ("sampled-data", 1.0),
        _ => ("both", 0.0),
    };
    v["binding_bound"] = json!(text);
    v["aliasing_effect"] = json!(by);
}

pub(crate) fn binding_text(v: &Value, what: &str, paper: &str, unit: &str) -> String {
    let by = 100.0 * v["aliasing_effect"].as_f64().unwrap_or(0.0);
    match v[paper].as_f64() {
        Some(p) if v["binding_bound"] == "sampled-data" => format!(
            "  the sampled-data analysis binds: the paper's approximation (aliasing at the handle neglected) gives {p:.4} {unit}; the proven {what} is {by:.1}% {}", if unit == "kg" { "higher" } else { "lower" }
        ),
        Some(_) => format!("  the paper's approximation gives the same {what} (aliasing moves it by {by:.4}%)"),
        None => "  the paper's approximation finds no design either".into(),
    }
}

pub(crate) fn design_impedance(a: &DesignImpedance) -> Result<(), String> {
    let margin = a.margin.fraction()?;
    let s = Session::open(&a.common)?;
    let r = impedance_design(&s, a.b)?;
    let paper = impedance_design_on(&s, &s.impedance_bounds(true), a.b)?;
    let mut v = json!({"display": "impedance", "feasible": r.is_some(), "period_s": s.period(), "human_model": s.human.is_some()});
    designs(&mut v, "k_c", r, paper, true);
    match r {
        Some((k, b)) => {
            let c = s.worst_check(|p| design::check_impedance(&p.analysis, k, b, s.human));
            binding_pose(&mut v, &s, c);
            v["margin"] = json!(margin);
            v["recommended_k_c"] = json!(Limit::Stiffness.inside(k, margin));
        }
        None => {
            let what = ("stiffness", "m/(N s)", design::K_RANGE, "N/m");
            v["message"] = json!(infeasible(&s, &s.impedance_bounds(false), what, a.b));
        }
    }
    s.emit(v.clone(), || {
        s.header("Impedance");
        print_design(Limit::Stiffness, r, a.b.is_some(), margin, &v);
        if let Some(t) = binding_pose_text(&v) {
            println!("{t}");
        }
        println!("{}", binding_text(&v, "stiffness", "paper_k_c", "N/m"));
    });
    Ok(())
}

/// Why no coupling `what` (its bound's unit, its search range and unit)
/// meets `bounds`: the limit toward DC, or the range searched.
pub(crate) fn infeasible(
    s: &Session,
    bounds: &[Vec<f64>],
    (what, bound_unit, (lo, hi), unit): (&str, &str, (f64, f64), &str),
    b: Option<f64>,
) -> String {
    let at = b
        .map(|b| format!(" at b_c = {b} N s/m"))
        .unwrap_or_default();
    match s
        .with(bounds)
        .iter()
        .find_map(|(a, b)| design::low_frequency_obstacle(a, b))
    {
        Some(limit) => format!(
            "no finite coupling {what} is absolutely stable: toward DC the bound stays positive (its limit is {limit:.4e} {bound_unit}), while the coupling's real part goes to zero as the frequency does"
        ),
        None => format!("no coupling {what} from {lo} to {hi} {unit} meets the bound{at}"),
    }
}

pub(crate) fn design_admittance(a: &DesignAdmittance) -> Result<(), String> {
    let margin = a.margin.fraction()?;
    let s = Session::open(&a.common)?;
    s.force_sensor()?;
    let (kp, bp) = match (a.kp, a.bp) {
        (Some(kp), Some(bp)) => (gain("kp", kp)?, gain("bp", bp)?),
        _ => impedance_design(&s, None)?
            .ok_or("no impedance design exists to take K_p from (eq 30); give --kp and --bp")?,
    };
    let k = design::regulator_tf(kp, bp, s.period()).map_err(|e| e.to_string())?;
    let radius = s.regulated_pole_radius(&k);
    let r = admittance_design_on(&s, &s.admittance_bounds(&k, false), radius, a.b)?;
    let paper = admittance_design_on(&s, &s.admittance_bounds(&k, true), radius, a.b)?;
    let mut v = json!({"display": "admittance", "feasible": r.is_some(), "kp": kp, "bp": bp,
        "period_s": s.period(), "human_model": s.human.is_some(), "regulator_pole_radius": radius});
    designs(&mut v, "m_c", r, paper, false);
    match r {
        Some((m, b)) => {
            let c = s.worst_check(|p| {
                design::check_admittance(&p.plant, &p.analysis, (kp, bp), (m, b), s.human)
            });
            binding_pose(&mut v, &s, c);
            v["margin"] = json!(margin);
            v["recommended_m_c"] = json!(Limit::Mass.inside(m, margin));
        }
        None if radius >= 1.0 => {
            v["message"] = json!(format!(
                "the regulator k_p = {kp}, b_p = {bp} does not stabilise the device (pole radius {radius:.4})"
            ))
        }
        None => {
            let what = ("mass", "N s/m", design::M_RANGE, "kg");
            v["message"] = json!(infeasible(&s, &s.admittance_bounds(&k, false), what, a.b));
        }
    }
    s.emit(v.clone(), || {
        s.header("Admittance");
        println!(
            "  position regulator K_p = {kp:.0} + {bp:.1} (1 - 1/z)/T (pole radius {radius:.4})"
        );
        print_design(Limit::Mass, r, a.b.is_some(), margin, &v);
        if let Some(t) = binding_pose_text(&v) {
            println!("{t}");
        }
        println!("{}", binding_text(&v, "mass", "paper_m_c", "kg"));
    });
    Ok(())
}
