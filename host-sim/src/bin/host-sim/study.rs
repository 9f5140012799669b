//! The studies: a sweep to a stability boundary, the paper's Table I,
//! the latency that explains a boundary, the passivity layer's scenes and
//! what accuracy costs.

use crate::run::SceneArgs;
use clap::Args;
use host_sim::study::{latency, passivity, sweep, table1};
use host_sim::Error;
use indicatif::{ProgressBar, ProgressStyle};
use serde_json::json;
use std::path::{Path, PathBuf};

#[derive(Args)]
pub(crate) struct PassivityArgs {
    /// The folder of the passivity scenes.
    #[arg(long, default_value = "scenes/passivity")]
    pub(crate) scenes: PathBuf,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub(crate) json: bool,
}

#[derive(Args)]
pub(crate) struct AccuracyArgs {
    /// Folder for accuracy.md, accuracy.json and accuracy.png.
    #[arg(long, default_value = "docs")]
    pub(crate) out: PathBuf,
}

#[derive(Args)]
pub(crate) struct SweepArgs {
    #[command(flatten)]
    pub(crate) scene: SceneArgs,
    /// The parameter, as a `--set` key (e.g. coupling.k).
    #[arg(long)]
    pub(crate) param: String,
    /// One end of the range.
    #[arg(long, allow_negative_numbers = true)]
    pub(crate) from: f64,
    /// The other end; stability must differ between the ends.
    #[arg(long, allow_negative_numbers = true)]
    pub(crate) to: f64,
    /// Relative tolerance of the answer.
    #[arg(long, default_value_t = 0.005)]
    pub(crate) tol: f64,
}

#[derive(Args)]
pub(crate) struct Table1Args {
    /// The folder of the Table I scenes.
    #[arg(long, default_value = "scenes/table1")]
    pub(crate) scenes: PathBuf,
    /// Override a value in every case, e.g. `--set
    /// effects.latency.periods=0.5` (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub(crate) sets: Vec<String>,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub(crate) json: bool,
}

#[derive(Args)]
pub(crate) struct LatencyFitArgs {
    #[command(flatten)]
    pub(crate) sweep: SweepArgs,
    /// The measured boundary the latency should explain (the parameter's
    /// unit).
    #[arg(long)]
    pub(crate) target: f64,
}

pub(crate) fn bar(len: u64, msg: String) -> ProgressBar {
    let b = ProgressBar::new(len);
    b.set_style(
        ProgressStyle::with_template("{msg} [{bar:30}] {pos}/{len}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    b.set_message(msg);
    b
}

/// `study` over the scene files in `dir`, with a progress bar of them.
pub(crate) fn over_cases<T>(
    dir: &Path,
    what: &str,
    study: impl FnOnce(&Path, &mut dyn FnMut()) -> Result<T, Error>,
) -> Result<T, Error> {
    let n = table1::case_files(dir)?.len();
    let b = bar(n as u64, what.into());
    let out = study(dir, &mut || b.inc(1));
    b.finish_and_clear();
    out
}

pub(crate) fn sweep(a: &SweepArgs) -> Result<(), Error> {
    if !(a.tol > 0.0 && a.tol < 1.0) {
        return Err(err!("--tol {}: must be between 0 and 1", a.tol));
    }
    let b = bar(
        sweep::steps(a.from, a.to, a.tol),
        format!("sweeping {}", a.param),
    );
    let m = sweep::marginal(
        &a.scene.scene,
        &a.scene.sets,
        &a.param,
        (a.from, a.to),
        a.tol,
        &mut || b.inc(1),
    )?;
    b.finish_and_clear();
    if a.scene.json {
        say!("{}", json!({"param": a.param, "marginal": m}));
    } else {
        say!(
            "{}: marginal value {m:.6} (the last stable value, within {}%)",
            a.param,
            a.tol * 100.0
        );
    }
    Ok(())
}

/// The latency that explains a measured boundary.
pub(crate) fn latency_fit(a: &LatencyFitArgs) -> Result<(), Error> {
    let s = &a.sweep;
    let b = bar(
        30,
        format!("fitting the latency to {} = {}", s.param, a.target),
    );
    let fit = latency::fit(
        &s.scene.scene,
        &s.scene.sets,
        (&s.param, (s.from, s.to), s.tol),
        a.target,
        &mut || b.inc(1),
    )?;
    b.finish_and_clear();
    match (fit, s.scene.json) {
        (latency::LatencySearch::Found { alpha, marginal }, true) => {
            say!("{}", json!({"param": s.param, "target": a.target, "latency_periods": alpha, "marginal": marginal}));
        }
        (latency::LatencySearch::Found { alpha, marginal }, false) => say!(
            "{}: {marginal:.6} at a latency of {alpha:.3} T (the target {})",
            s.param,
            a.target
        ),
        (latency::LatencySearch::NotReached { at_zero, last, at_last }, true) => {
            say!("{}", json!({"param": s.param, "target": a.target, "latency_periods": null,
                "at_zero": at_zero, "last_periods": last, "at_last": at_last}));
        }
        (latency::LatencySearch::NotReached { at_zero, last, at_last }, false) => say!(
            "{}: no latency in [0, 1) gives {}: {at_zero:.6} with none, {at_last:.6} at {last:.3} T, \
             and past it no boundary in the range",
            s.param,
            a.target
        ),
    }
    Ok(())
}

/// The passivity layer's table: each scene off, on, and at its passive
/// reference.
pub(crate) fn passivity(a: &PassivityArgs) -> Result<(), Error> {
    let rows = over_cases(&a.scenes, "passivity scenes", passivity::table)?;
    if a.json {
        say!("{}", json!({ "rows": rows }));
    } else {
        print!("{}", passivity::markdown(&rows));
    }
    Ok(())
}

/// Table I: every VE state x grasp at the theoretical gains, then the
/// boundaries swept as the paper did.
pub(crate) fn table1(a: &Table1Args) -> Result<(), Error> {
    let t = over_cases(&a.scenes, "Table I", |dir, step| {
        table1::table1(dir, &a.sets, step)
    })?;
    let rows: Vec<serde_json::Value> = t
        .cases
        .iter()
        .map(|c| {
            json!({"case": c.case, "display": format!("{:?}", c.display).to_lowercase(),
                "stable_at_theoretical_gains": c.stable_at_theoretical_gains, "marginal": c.marginal})
        })
        .collect();
    let (all_stable, k_bound, m_bound) = (
        t.all_stable(),
        t.impedance_boundary_k,
        t.admittance_boundary_m,
    );
    if a.json {
        say!(
            "{}",
            json!({"cases": rows, "all_stable_at_theoretical_gains": all_stable,
            "impedance_boundary_k": k_bound,
            "admittance_boundary_m": m_bound})
        );
        return Ok(());
    }
    say!("Table I  Theoretical versus experimental (paper) and simulated (linear model) stability boundary gains");
    if !a.sets.is_empty() {
        say!("(every case with {})", a.sets.join(", "));
    }
    say!(
        "{:<26} {:>10} {:>6}   {:>8} {:>6}",
        "",
        "k_cI N/m",
        "b_cI",
        "m_cA kg",
        "b_cA"
    );
    say!(
        "{:<26} {:>10} {:>6}   {:>8} {:>6}",
        "theoretical",
        "51,000",
        "90",
        "5.0",
        "500"
    );
    say!(
        "{:<26} {:>10} {:>6}   {:>8} {:>6}",
        "experimental (paper)",
        "75,000",
        "90",
        "4.3",
        "500"
    );
    let fmt_k = k_bound.map_or("> 2e6".into(), |k| format!("{k:.0}"));
    let fmt_m = m_bound.map_or("< 0.01".into(), |m| format!("{m:.2}"));
    say!(
        "{:<26} {:>10} {:>6}   {:>8} {:>6}",
        "simulated (this model)",
        fmt_k,
        "90",
        fmt_m,
        "500"
    );
    say!();
    say!(
        "{:<36} {:>22} {:>14}",
        "case",
        "stable at theoretical",
        "boundary"
    );
    for r in &rows {
        let m = r["marginal"]
            .as_f64()
            .map_or("none found".into(), |v| format!("{v:.4}"));
        say!(
            "{:<36} {:>22} {:>14}",
            r["case"].as_str().unwrap_or(""),
            r["stable_at_theoretical_gains"],
            m
        );
    }
    Ok(())
}

pub(crate) fn accuracy(a: &AccuracyArgs) -> Result<(), Error> {
    std::fs::create_dir_all(&a.out).map_err(|e| format!("{}: {e}", a.out.display()))?;
    let scenes = host_sim::study::accuracy::scenes(Path::new("."))?;
    let b = bar(scenes.len() as u64, "accuracy study".into());
    let mut cells = Vec::new();
    for s in &scenes {
        cells.extend(host_sim::study::accuracy::study(
            &s.label,
            &s.scene,
            s.reference,
        )?);
        b.inc(1);
    }
    b.finish_and_clear();
    let md = format!(
        "# What accuracy costs in time\n\nRegenerate with `cargo xtask accuracy`. Error: the largest handle-position \
         difference from the reference over the run, relative to the reference's peak displacement. Cost: wall time \
         per simulated millisecond (1 control tick), best of three, on the machine that ran it. References: exact \
         ZOH for the linear scene (exact there), RK4 at 1,000 sub-steps (1 us) for the nonlinear one, both with the \
         f64 controller. Controller: the board's f32 laws, or the same laws computing in f64 (`integrator.controller`); \
         the f32 rows' error cannot fall below what the board's rounding does to the trajectory.\n\n![accuracy](accuracy.png)\n\n{}",
        host_sim::study::accuracy::markdown(&cells)
    );
    let write = |name: &str, text: String| {
        std::fs::write(a.out.join(name), text).map_err(|e| format!("{name}: {e}"))
    };
    write("accuracy.md", md)?;
    write(
        "accuracy.json",
        serde_json::to_string_pretty(&cells).map_err(|e| e.to_string())?,
    )?;
    host_sim::study::plot::accuracy_png(&cells, &a.out.join("accuracy.png"))?;
    say!(
        "wrote {}/accuracy.md, accuracy.json, accuracy.png ({} runs)",
        a.out.display(),
        cells.len()
    );
    Ok(())
}
