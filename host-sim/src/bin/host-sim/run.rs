//! `host-sim run`: one scene, judged, with its CSV or plot on request.

use clap::Args;
use host_sim::engine::scene::Scene;
use host_sim::Error;
use host_sim::{Report, Simulation};
use std::io::Write;
use std::path::{Path, PathBuf};

#[derive(Args)]
pub(crate) struct SceneArgs {
    /// The scene file (TOML).
    pub(crate) scene: PathBuf,
    /// Override a scene value, e.g. `--set coupling.k=60000` (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub(crate) sets: Vec<String>,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub(crate) json: bool,
}

#[derive(Args)]
pub(crate) struct RunArgs {
    #[command(flatten)]
    pub(crate) scene: SceneArgs,
    /// Simulated time (s), instead of the scene's.
    #[arg(long)]
    pub(crate) duration: Option<f64>,
    /// Write every tick to this CSV file.
    #[arg(long)]
    pub(crate) csv: Option<PathBuf>,
    /// Draw the run to this PNG file.
    #[arg(long)]
    pub(crate) png: Option<PathBuf>,
}

pub(crate) fn load(path: &Path, sets: &[String]) -> Result<Scene, Error> {
    Scene::load(path, sets)
}

/// `$body` with `N` the scene's axis count, a constant.
macro_rules! with_axes {
    ($scene:expr, $n:ident => $body:expr) => {
        match $scene.axes {
            1 => {
                const $n: usize = 1;
                $body
            }
            2 => {
                const $n: usize = 2;
                $body
            }
            _ => {
                const $n: usize = 3;
                $body
            }
        }
    };
}

pub(crate) fn run(a: &RunArgs) -> Result<(), Error> {
    let mut sets = a.scene.sets.clone();
    if let Some(d) = a.duration {
        sets.push(format!("duration_s={d}"));
    }
    let scene = load(&a.scene.scene, &sets)?;
    with_axes!(scene, N => run_axes::<N>(a, scene))
}

/// The CSV's columns: each quantity once on one axis, once per axis
/// (`_x`, `_y`, `_z`) on several.
fn csv_header(axes: usize) -> String {
    const COLUMNS: [(&str, &str); 7] = [
        ("handle_position", "m"),
        ("handle_velocity", "mps"),
        ("human_force", "n"),
        ("commanded_force", "n"),
        ("actuator_force", "n"),
        ("ve_position", "m"),
        ("ve_force", "n"),
    ];
    let mut h = String::from("t_s");
    for (name, unit) in COLUMNS {
        if axes == 1 {
            h += &format!(",{name}_{unit}");
        } else {
            for axis in ["x", "y", "z"].iter().take(axes) {
                h += &format!(",{name}_{axis}_{unit}");
            }
        }
    }
    h
}

fn run_axes<const N: usize>(a: &RunArgs, scene: Scene) -> Result<(), Error> {
    if a.png.is_some() && N != 1 {
        return Err(err!(
            "--png draws a one-axis scene; give this {N}-axis one --csv"
        ));
    }
    let name = scene.name.clone();
    let mut sim = Simulation::<N>::with_axes(scene)?;
    let mut rec = Recorder::new(a.csv.as_deref(), &csv_header(N), a.png.is_some())?;
    let report = sim.run(|s| {
        rec.record(s, || {
            let mut row = s.t_s.to_string();
            for v in [
                &s.handle_m,
                &s.handle_mps,
                &s.human_n,
                &s.commanded_n,
                &s.actuator_n,
                &s.ve_m,
                &s.ve_n,
            ] {
                for x in v {
                    row += &format!(",{x}");
                }
            }
            row
        })
    });
    let kept = rec.finish()?;
    if let Some(p) = &a.png {
        host_sim::study::plot::png(&kept, &name, p)?;
    }
    say_report(&report, a.scene.json, print_report)
}

/// What a run writes as it goes: each tick's CSV row, and the samples a
/// plot needs.
pub(crate) struct Recorder<T> {
    csv: Option<std::io::BufWriter<std::fs::File>>,
    err: Option<std::io::Error>,
    kept: Option<Vec<T>>,
}

impl<T: Copy> Recorder<T> {
    /// A CSV file at `csv` (if any) with `header`, and the samples kept
    /// if `keep`.
    pub(crate) fn new(csv: Option<&Path>, header: &str, keep: bool) -> Result<Self, Error> {
        Ok(Recorder {
            csv: csv_file(csv, header)?,
            err: None,
            kept: keep.then(Vec::new),
        })
    }

    /// One tick: `row` written (made only with a CSV to write), `s` kept.
    pub(crate) fn record(&mut self, s: &T, row: impl FnOnce() -> String) {
        if let Some(w) = self.csv.as_mut() {
            if let Err(e) = writeln!(w, "{}", row()) {
                self.err.get_or_insert(e);
            }
        }
        if let Some(k) = self.kept.as_mut() {
            k.push(*s);
        }
    }

    /// The CSV flushed (the first error writing it), and the samples kept.
    pub(crate) fn finish(self) -> Result<Vec<T>, Error> {
        finish_csv(self.csv, self.err)?;
        Ok(self.kept.unwrap_or_default())
    }
}

/// A run's report: one JSON object on stdout with `json`, else `text`.
pub(crate) fn say_report<R: serde::Serialize>(
    report: &R,
    json: bool,
    text: impl FnOnce(&R),
) -> Result<(), Error> {
    if json {
        say!(
            "{}",
            serde_json::to_string(report).map_err(|e| e.to_string())?
        );
    } else {
        text(report);
    }
    Ok(())
}

/// A CSV file at `path` (if any), its `header` written.
fn csv_file(
    path: Option<&Path>,
    header: &str,
) -> Result<Option<std::io::BufWriter<std::fs::File>>, Error> {
    let Some(p) = path else { return Ok(None) };
    let f = std::fs::File::create(p).map_err(|e| format!("{}: {e}", p.display()))?;
    let mut w = std::io::BufWriter::new(f);
    writeln!(w, "{header}").map_err(|e| e.to_string())?;
    Ok(Some(w))
}

/// The first error writing a CSV's rows, or the flush's.
fn finish_csv(
    csv: Option<std::io::BufWriter<std::fs::File>>,
    row_err: Option<std::io::Error>,
) -> Result<(), Error> {
    if let Some(e) = row_err {
        return Err(err!("writing the CSV: {e}"));
    }
    match csv {
        Some(mut w) => w.flush().map_err(|e| err!("writing the CSV: {e}")),
        None => Ok(()),
    }
}

/// A run's first lines: the scene, stable or not, and why not.
pub(crate) fn print_verdict(scene: &str, reason: &Option<String>) {
    match reason {
        None => say!("{scene}: stable"),
        Some(why) => say!("{scene}: UNSTABLE\n  {why}"),
    }
}

pub(crate) fn print_report(r: &Report) {
    print_verdict(&r.scene, &r.reason);
    say!(
        "  peak force {:.1} N, human energy in {:.3} J, {:.1} s simulated in {:.3} s ({:.0}x real time)",
        r.peak_force_n, r.energy_in_j, r.sim_seconds, r.wall_seconds, r.realtime_factor
    );
    say!("  plant: {} x {} per tick", r.integrator, r.substeps);
    if let Some(w) = &r.integrator_warning {
        say!("  warning: {w}");
    }
    for e in &r.effects {
        say!("  effect {:<12} {:>8.1} ns/tick", e.name, e.ns_per_tick);
    }
    for (i, b) in r.blocks_m.iter().enumerate() {
        say!(
            "  block {i} at ({:.1}, {:.1}, {:.1}) mm",
            b[0] * 1e3,
            b[1] * 1e3,
            b[2] * 1e3
        );
    }
}
