//! `twoport rates`: what the servo rate buys. Each device's proven
//! impedance coupling at each servo rate, as a table and a log-log figure.
//!
//! With the VE on the host, the board solves its VE point against the
//! host's surfaces at the servo rate, and each piece of that law (free, or
//! stopped at a surface) is passive; so the coupling proven at the servo
//! rate is the one that holds against still surfaces, whatever the host's
//! rate. A body the host moves with the handle closes a loop through the
//! host's rate and the link's delay: with `--host-body`, each lumped
//! device's row also gives the stiffest coupling proven against it (see
//! docs/host.md).

use crate::args::{HostArgs, RatesArgs};
use serde_json::{json, Value};
use std::path::Path;
use twoport_design::host_ve::{host_best_pair, HostLoop};
use twoport_design::linkage::{certified_design_from, least_damping, LinkageFile};
use twoport_design::network::HumanBound;
use twoport_design::plot::{self, Curve, Figure, BLUE, GREY, INK, RED};
use twoport_design::{Designer, DeviceModel, Plant};

/// One device's proven couplings, one per rate.
struct Row {
    name: String,
    /// At each rate: the best pair (k N/m, b N s/m), and k at the first
    /// rate's best damping (a linkage: its one k, at b = 0).
    at: Vec<((f64, f64), f64)>,
    /// With a host body: at each rate, the best pair (k N/m, b N s/m)
    /// proven against it too (None: none is).
    host: Option<Vec<Option<(f64, f64)>>>,
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

/// The best pair proven against the host's body at servo rate `rate`
/// (Hz), with dampings up to the single-rate best pair's `b_max`.
fn host_pair(
    model: &DeviceModel,
    rate: f64,
    b_max: f64,
    host: &HostArgs,
) -> Result<Option<(f64, f64)>, String> {
    let (n, d) = host.ticks(rate)?;
    let t = 1.0 / rate;
    let plant = Plant::new(model, t).map_err(|e| format!("{}: {e}", model.name))?;
    let l = HostLoop::new(t, n, d, (host.body.0, host.body.1, 0.0)).map_err(|e| e.to_string())?;
    host_best_pair(&plant, Some(HumanBound::PAPER), &l, b_max).map_err(|e| e.to_string())
}

fn model_row(path: &Path, rates: &[f64], host: Option<&HostArgs>) -> Result<Row, String> {
    let model = DeviceModel::load(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut at = Vec::new();
    let mut first_b = None;
    let mut with_host = host.map(|_| Vec::new());
    for r in rates {
        let best = pair(&model, 1.0 / r, None)?;
        let b0 = *first_b.get_or_insert(best.1);
        let (k_same, _) = pair(&model, 1.0 / r, Some(b0))?;
        at.push((best, k_same));
        if let (Some(h), Some(v)) = (host, with_host.as_mut()) {
            v.push(host_pair(&model, *r, best.1, h)?);
        }
    }
    Ok(Row {
        name: model.name,
        at,
        host: with_host,
    })
}

fn linkage_row(path: &Path, rates: &[f64], grasp: f64) -> Result<Row, String> {
    let mut file = LinkageFile::load(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut at = Vec::new();
    // (The workspace's least damping does not depend on the rate.)
    let damping = least_damping(&file).map_err(|e| format!("{}: {e}", path.display()))?;
    for r in rates {
        file.period_s = 1.0 / r;
        let d =
            certified_design_from(&file, &damping, 0.0, grasp, None).map_err(|e| e.to_string())?;
        at.push(((d.k_c_npm, 0.0), d.k_c_npm));
    }
    Ok(Row {
        name: format!("{} (grasp >= {grasp} N s/m)", file.name),
        at,
        host: None,
    })
}

pub(crate) fn rates(a: &RatesArgs) -> Result<(), String> {
    let rates = a.rates()?;
    let grasp = a.grasp()?;
    let host = a.host.get()?;
    if let Some(h) = &host {
        for r in &rates {
            h.ticks(*r)?;
        }
    }
    let mut rows = Vec::new();
    for m in &a.model {
        rows.push(model_row(m, &rates, host.as_ref())?);
    }
    for l in &a.linkage {
        rows.push(linkage_row(l, &rates, grasp)?);
    }
    if let Some(out) = &a.plot {
        plot::render(&figure(&rows, &rates), out).map_err(|e| e.to_string())?;
    }
    if a.json {
        say!("{}\n", to_json(&rows, &rates));
        return Ok(());
    }
    say!("{}\n", table(&rows, &rates, host.as_ref()));
    if let Some(out) = &a.plot {
        say!("wrote {}\n", out.display());
    }
    Ok(())
}

fn to_json(rows: &[Row], rates: &[f64]) -> Value {
    json!({
        "rates_hz": rates,
        "devices": rows.iter().map(|r| {
            let mut o = json!({
                "name": r.name,
                "k_npm": r.at.iter().map(|a| a.0 .0).collect::<Vec<_>>(),
                "b_nspm": r.at.iter().map(|a| a.0 .1).collect::<Vec<_>>(),
                "k_at_first_b_npm": r.at.iter().map(|a| a.1).collect::<Vec<_>>(),
            });
            if let Some(h) = &r.host {
                o["with_host_body"] = json!(h.iter().map(|p| p.map(|(k, b)| json!({"k_npm": k, "b_nspm": b}))).collect::<Vec<_>>());
            }
            o
        }).collect::<Vec<_>>(),
    })
}

fn table(rows: &[Row], rates: &[f64], host: Option<&HostArgs>) -> String {
    let mut s = String::from("proven impedance coupling k (N/m) at b (N s/m), per servo rate\n");
    if let Some(h) = host {
        s += &format!(
            "with a host body of {} kg and {} N s/m at {} Hz, {} s from read to answer\n",
            h.body.0, h.body.1, h.ve_rate_hz, h.delay_s
        );
    }
    for r in rows {
        s += &format!("\n{}\n", r.name);
        for (i, (rate, ((k, b), k_same))) in rates.iter().zip(&r.at).enumerate() {
            s += &format!(
                "  {:>6.0} Hz: {:>12.0} N/m at {:>7.1} N s/m; {:>12.0} N/m at the first rate's damping",
                rate, k, b, k_same
            );
            match r.host.as_ref().map(|h| h[i]) {
                Some(Some((kh, bh))) => {
                    s += &format!("; with the host body {kh:>9.0} N/m at {bh:>6.1} N s/m")
                }
                Some(None) => s += "; none proven with the host body",
                None => {}
            }
            s += "\n";
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
        if let Some(h) = &r.host {
            curves.push(Curve {
                label: format!("{}, a body the host moves", r.name),
                width: 1,
                dashed: false,
                color,
                points: rates
                    .iter()
                    .zip(h)
                    .filter_map(|(f, p)| p.map(|(k, _)| (*f, k)))
                    .collect(),
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
