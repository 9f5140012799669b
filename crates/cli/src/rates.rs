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

use crate::args::{HostArgs, Latency, RatesArgs};
use serde::Serialize;
use std::fmt;
use std::path::{Path, PathBuf};
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

fn model_row(
    path: &Path,
    rates: &[f64],
    host: Option<&HostArgs>,
    latency: Option<Latency>,
) -> Result<Row, String> {
    let mut model = DeviceModel::load(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut at = Vec::new();
    let mut first_b = None;
    let mut with_host = host.map(|_| Vec::new());
    for r in rates {
        if let Some(l) = latency {
            model.latency_s = l.seconds(1.0 / r);
        }
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

fn linkage_row(
    path: &Path,
    rates: &[f64],
    grasp: f64,
    latency: Option<Latency>,
) -> Result<Row, String> {
    let mut file = LinkageFile::load(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut at = Vec::new();
    // (The workspace's least damping does not depend on the rate.)
    let damping = least_damping(&file).map_err(|e| format!("{}: {e}", path.display()))?;
    for r in rates {
        file.period_s = 1.0 / r;
        if let Some(l) = latency {
            file.latency_s = l.seconds(1.0 / r);
        }
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

pub(crate) fn rates(a: &RatesArgs) -> Result<RatesReport, String> {
    let rates = a.rates()?;
    let grasp = a.grasp()?;
    let host = a.host.get()?;
    if let Some(h) = &host {
        for r in &rates {
            h.ticks(*r)?;
        }
    }
    if let Some(l) = a.latency {
        let s = l.seconds(1.0 / rates[0]);
        if s > twoport_design::model::MAX_LATENCY_S {
            return Err(format!(
                "--latency {s} s: at most {} s",
                twoport_design::model::MAX_LATENCY_S
            ));
        }
    }
    let mut rows = Vec::new();
    for m in &a.model {
        rows.push(model_row(m, &rates, host.as_ref(), a.latency)?);
    }
    for l in &a.linkage {
        rows.push(linkage_row(l, &rates, grasp, a.latency)?);
    }
    if let Some(out) = &a.plot {
        plot::render(&figure(&rows, &rates), out).map_err(|e| e.to_string())?;
    }
    Ok(RatesReport {
        latency_s: a
            .latency
            .map(|l| rates.iter().map(|r| l.seconds(1.0 / r)).collect()),
        host: host.map(|h| HostBody {
            mass_kg: h.body.0,
            damping_nspm: h.body.1,
            ve_rate_hz: h.ve_rate_hz,
            delay_s: h.delay_s,
        }),
        devices: rows
            .into_iter()
            .map(|r| DeviceRates {
                name: r.name,
                k_npm: r.at.iter().map(|a| a.0 .0).collect(),
                b_nspm: r.at.iter().map(|a| a.0 .1).collect(),
                k_at_first_b_npm: r.at.iter().map(|a| a.1).collect(),
                with_host_body: r.host.map(|h| {
                    h.into_iter()
                        .map(|p| p.map(|(k_npm, b_nspm)| Pair { k_npm, b_nspm }))
                        .collect()
                }),
            })
            .collect(),
        rates_hz: rates,
        figure: a.plot.clone(),
    })
}

/// Each device's proven coupling at each servo rate.
#[derive(Serialize)]
pub(crate) struct RatesReport {
    rates_hz: Vec<f64>,
    /// The latency from sampling to the force each rate is proven with (s).
    #[serde(skip_serializing_if = "Option::is_none")]
    latency_s: Option<Vec<f64>>,

    /// The body the host moves, where one is given.
    #[serde(skip_serializing_if = "Option::is_none")]
    host: Option<HostBody>,
    devices: Vec<DeviceRates>,
    /// The figure written, if one was asked for.
    #[serde(skip_serializing_if = "Option::is_none")]
    figure: Option<PathBuf>,
}

/// A body the host moves with the handle, and its link.
#[derive(Serialize)]
struct HostBody {
    mass_kg: f64,
    damping_nspm: f64,
    ve_rate_hz: f64,
    /// From the tick the host reads to the tick that takes its answer.
    delay_s: f64,
}

/// One device's couplings, one per rate.
#[derive(Serialize)]
struct DeviceRates {
    name: String,
    /// The best pair at each rate (a linkage: its one k, at b = 0).
    k_npm: Vec<f64>,
    b_nspm: Vec<f64>,
    /// k at the first rate's best damping.
    k_at_first_b_npm: Vec<f64>,
    /// The best pair proven against the host's body (None: none is).
    #[serde(skip_serializing_if = "Option::is_none")]
    with_host_body: Option<Vec<Option<Pair>>>,
}

/// A coupling: stiffness and damping.
#[derive(Clone, Copy, Serialize)]
struct Pair {
    k_npm: f64,
    b_nspm: f64,
}

impl fmt::Display for RatesReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "proven impedance coupling k (N/m) at b (N s/m), per servo rate"
        )?;
        if let Some(l) = &self.latency_s {
            let us: Vec<String> = l.iter().map(|s| format!("{:.3}", s * 1e6)).collect();
            write!(
                f,
                "\nwith a latency from sampling to the force of {} us (the rates in order)",
                us.join(", ")
            )?;
        }
        if let Some(h) = &self.host {
            write!(
                f,
                "\nwith a host body of {} kg and {} N s/m at {} Hz, {} s from read to answer",
                h.mass_kg, h.damping_nspm, h.ve_rate_hz, h.delay_s
            )?;
        }
        for d in &self.devices {
            write!(f, "\n\n{}", d.name)?;
            for (i, rate) in self.rates_hz.iter().enumerate() {
                write!(
                    f,
                    "\n  {:>6.0} Hz: {:>12.0} N/m at {:>7.1} N s/m; {:>12.0} N/m at the first rate's damping",
                    rate, d.k_npm[i], d.b_nspm[i], d.k_at_first_b_npm[i]
                )?;
                match d.with_host_body.as_ref().map(|h| h[i]) {
                    Some(Some(p)) => write!(
                        f,
                        "; with the host body {:>9.0} N/m at {:>6.1} N s/m",
                        p.k_npm, p.b_nspm
                    )?,
                    Some(None) => write!(f, "; none proven with the host body")?,
                    None => {}
                }
            }
        }
        if let Some(out) = &self.figure {
            write!(f, "\n\nwrote {}", out.display())?;
        }
        Ok(())
    }
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
