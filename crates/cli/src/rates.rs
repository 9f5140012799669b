//! `twoport rates`: what the servo rate buys. Each device's proven
//! impedance coupling at each servo rate, as a table and a log-log figure.
//!
//! With the VE on the host, the board solves its VE point against the
//! host's surfaces at the servo rate, and each piece of that law (free, or
//! stopped at a surface) is passive; so the coupling proven at the servo
//! rate is the one that holds, whatever the host's rate (see
//! docs/host.md).

use crate::args::RatesArgs;
use serde_json::{json, Value};
use std::path::Path;
use twoport_design::linkage::{workspace_design, workspace_poses, LinkageFile, DESIGN_GRID};
use twoport_design::network::HumanBound;
use twoport_design::plot::{self, Curve, Figure, BLUE, GREY, INK, RED};
use twoport_design::{Designer, DeviceModel};

/// One device's proven couplings, one per rate.
struct Row {
    name: String,
    /// At each rate: the best pair (k N/m, b N s/m), and k at the first
    /// rate's best damping (a linkage: its one k, at b = 0).
    at: Vec<((f64, f64), f64)>,
}

/// The best impedance pair of `model` at `period_s`, or at damping `b`.
fn pair(model: &DeviceModel, period_s: f64, b: Option<f64>) -> Result<(f64, f64), String> {
    let d = Designer::new(vec![model.clone()], Some(period_s), Some(HumanBound::PAPER))
        .map_err(|e| e.to_string())?;
    d.design_impedance(b, 0.0)
        .map_err(|e| e.to_string())?
        .coupling
        .ok_or_else(|| format!("{}: no coupling proven at T = {period_s} s", model.name))
}

fn model_row(path: &Path, rates: &[f64]) -> Result<Row, String> {
    let model = DeviceModel::load(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut at = Vec::new();
    let mut first_b = None;
    for r in rates {
        let best = pair(&model, 1.0 / r, None)?;
        let b0 = *first_b.get_or_insert(best.1);
        let (k_same, _) = pair(&model, 1.0 / r, Some(b0))?;
        at.push((best, k_same));
    }
    Ok(Row {
        name: model.name,
        at,
    })
}

fn linkage_row(path: &Path, rates: &[f64], grasp: f64) -> Result<Row, String> {
    let mut file = LinkageFile::load(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut at = Vec::new();
    for r in rates {
        file.period_s = 1.0 / r;
        let poses = workspace_poses(&file, DESIGN_GRID);
        let d = workspace_design(&file, &poses, 0.0, grasp).map_err(|e| e.to_string())?;
        at.push(((d.k_c_npm, 0.0), d.k_c_npm));
    }
    Ok(Row {
        name: format!("{} (grasp >= {grasp} N s/m)", file.name),
        at,
    })
}

pub(crate) fn rates(a: &RatesArgs) -> Result<(), String> {
    let rates = a.rates()?;
    let grasp = a.grasp()?;
    let mut rows = Vec::new();
    for m in &a.model {
        rows.push(model_row(m, &rates)?);
    }
    for l in &a.linkage {
        rows.push(linkage_row(l, &rates, grasp)?);
    }
    if let Some(out) = &a.plot {
        plot::render(&figure(&rows, &rates), out).map_err(|e| e.to_string())?;
    }
    if a.json {
        println!("{}", to_json(&rows, &rates));
        return Ok(());
    }
    println!("{}", table(&rows, &rates));
    if let Some(out) = &a.plot {
        println!("wrote {}", out.display());
    }
    Ok(())
}

fn to_json(rows: &[Row], rates: &[f64]) -> Value {
    json!({
        "rates_hz": rates,
        "devices": rows.iter().map(|r| json!({
            "name": r.name,
            "k_npm": r.at.iter().map(|a| a.0 .0).collect::<Vec<_>>(),
            "b_nspm": r.at.iter().map(|a| a.0 .1).collect::<Vec<_>>(),
            "k_at_first_b_npm": r.at.iter().map(|a| a.1).collect::<Vec<_>>(),
        })).collect::<Vec<_>>(),
    })
}

fn table(rows: &[Row], rates: &[f64]) -> String {
    let mut s = String::from("proven impedance coupling k (N/m) at b (N s/m), per servo rate\n");
    for r in rows {
        s += &format!("\n{}\n", r.name);
        for (rate, ((k, b), k_same)) in rates.iter().zip(&r.at) {
            s += &format!(
                "  {:>6.0} Hz: {:>12.0} N/m at {:>7.1} N s/m; {:>12.0} N/m at the first rate's damping\n",
                rate, k, b, k_same
            );
        }
    }
    s
}

fn figure(rows: &[Row], rates: &[f64]) -> Figure {
    let colors = [BLUE, RED, INK, GREY];
    let mut curves = Vec::new();
    for (i, r) in rows.iter().enumerate() {
        let color = colors[i % colors.len()];
        let linkage = r.at.iter().all(|a| a.0 .1 == 0.0);
        curves.push(Curve {
            label: r.name.clone(),
            width: 2,
            dashed: linkage,
            color,
            points: rates.iter().zip(&r.at).map(|(f, a)| (*f, a.0 .0)).collect(),
        });
        if !linkage {
            curves.push(Curve {
                label: format!("{}, at the first rate's damping", r.name),
                width: 1,
                dashed: true,
                color,
                points: rates.iter().zip(&r.at).map(|(f, a)| (*f, a.1)).collect(),
            });
        }
    }
    Figure {
        title: "What the servo rate buys: the proven coupling stiffness".into(),
        x_label: "servo rate (Hz)".into(),
        legend: plot::LegendAt::UpperLeft,
        y_label: "k_c  (N/m)".into(),
        curves,
    }
}
