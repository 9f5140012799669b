//! `host-sim run`: one scene, judged, with its CSV or plot on request.

use clap::Args;
use host_sim::engine::scene::Scene;
use host_sim::{Report, Sample, Simulation};
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

pub(crate) fn load(path: &Path, sets: &[String]) -> Result<Scene, String> {
    Scene::load(path, sets).map_err(|e| e.to_string())
}

pub(crate) fn run_scene(scene: Scene, mut sink: impl FnMut(&Sample)) -> Result<Report, String> {
    let mut sim = Simulation::new(scene)?;
    Ok(sim.run(&mut sink))
}

pub(crate) fn run(a: &RunArgs) -> Result<(), String> {
    let mut sets = a.scene.sets.clone();
    if let Some(d) = a.duration {
        sets.push(format!("duration_s={d}"));
    }
    let path = &a.scene.scene;
    let text = std::fs::read_to_string(path).unwrap_or_default();
    if host_sim::engine::xyz::axes_of(&text) == Some(3) {
        return run_xyz(a, &sets);
    }
    let scene = load(path, &sets)?;
    let name = scene.name.clone();
    let mut csv = csv_file(
        a.csv.as_deref(),
        "t_s,handle_position_m,handle_velocity_mps,human_force_n,commanded_force_n,actuator_force_n,ve_position_m,ve_force_n",
    )?;
    let mut kept: Vec<Sample> = Vec::new();
    let mut csv_err = None;
    let report = run_scene(scene, |s| {
        if let Some(w) = csv.as_mut() {
            if let Err(e) = writeln!(
                w,
                "{},{},{},{},{},{},{},{}",
                s.t_s,
                s.handle_m,
                s.handle_mps,
                s.human_n,
                s.commanded_n,
                s.actuator_n,
                s.ve_m,
                s.ve_n
            ) {
                csv_err.get_or_insert(e);
            }
        }
        if a.png.is_some() {
            kept.push(*s);
        }
    })?;
    finish_csv(csv, csv_err)?;
    if let Some(p) = &a.png {
        host_sim::study::plot::png(&kept, &name, p)?;
    }
    if a.scene.json {
        println!(
            "{}",
            serde_json::to_string(&report).map_err(|e| e.to_string())?
        );
    } else {
        print_report(&report);
    }
    Ok(())
}

/// A CSV file at `path` (if any), its `header` written.
pub(crate) fn csv_file(
    path: Option<&Path>,
    header: &str,
) -> Result<Option<std::io::BufWriter<std::fs::File>>, String> {
    let Some(p) = path else { return Ok(None) };
    let f = std::fs::File::create(p).map_err(|e| format!("{}: {e}", p.display()))?;
    let mut w = std::io::BufWriter::new(f);
    writeln!(w, "{header}").map_err(|e| e.to_string())?;
    Ok(Some(w))
}

/// The first error writing a CSV's rows, or the flush's.
pub(crate) fn finish_csv(
    csv: Option<std::io::BufWriter<std::fs::File>>,
    row_err: Option<std::io::Error>,
) -> Result<(), String> {
    if let Some(e) = row_err {
        return Err(format!("writing the CSV: {e}"));
    }
    match csv {
        Some(mut w) => w.flush().map_err(|e| format!("writing the CSV: {e}")),
        None => Ok(()),
    }
}

/// A three-axis scene, headless: the report, and each tick in a CSV.
pub(crate) fn run_xyz(a: &RunArgs, sets: &[String]) -> Result<(), String> {
    use host_sim::engine::xyz::{XyzScene, XyzSimulation};
    if a.png.is_some() {
        return Err("--png draws a one-axis scene; give a three-axis one --csv".into());
    }
    let scene = XyzScene::load(&a.scene.scene, sets).map_err(|e| e.to_string())?;
    let mut sim = XyzSimulation::new(scene)?;
    let mut csv = csv_file(
        a.csv.as_deref(),
        "t_s,handle_x_m,handle_y_m,handle_z_m,force_x_n,force_y_n,force_z_n,cursor_x_m,cursor_y_m,cursor_z_m,held",
    )?;
    let mut csv_err = None;
    let r = sim.run(|s| {
        if let Some(w) = csv.as_mut() {
            let [hx, hy, hz] = s.handle_m;
            let [fx, fy, fz] = s.actuator_n;
            let [cx, cy, cz] = s.cursor_m;
            let held = s.held.map_or(-1, |i| i as i64);
            if let Err(e) = writeln!(
                w,
                "{},{hx},{hy},{hz},{fx},{fy},{fz},{cx},{cy},{cz},{held}",
                s.t_s
            ) {
                csv_err.get_or_insert(e);
            }
        }
    });
    finish_csv(csv, csv_err)?;
    if a.scene.json {
        println!("{}", serde_json::to_string(&r).map_err(|e| e.to_string())?);
    } else {
        print_verdict(&r.scene, &r.reason);
        println!(
            "  peak force {:.1} N, {:.1} s simulated in {:.3} s ({:.0}x real time)",
            r.peak_force_n, r.sim_seconds, r.wall_seconds, r.realtime_factor
        );
        for (i, b) in r.blocks_m.iter().enumerate() {
            println!(
                "  block {i} at ({:.1}, {:.1}, {:.1}) mm",
                b[0] * 1e3,
                b[1] * 1e3,
                b[2] * 1e3
            );
        }
    }
    Ok(())
}

/// A run's first lines: the scene, stable or not, and why not.
pub(crate) fn print_verdict(scene: &str, reason: &Option<String>) {
    match reason {
        None => println!("{scene}: stable"),
        Some(why) => println!("{scene}: UNSTABLE\n  {why}"),
    }
}

pub(crate) fn print_report(r: &Report) {
    print_verdict(&r.scene, &r.reason);
    println!(
        "  peak force {:.1} N, human energy in {:.3} J, {:.1} s simulated in {:.3} s ({:.0}x real time)",
        r.peak_force_n, r.energy_in_j, r.sim_seconds, r.wall_seconds, r.realtime_factor
    );
    println!("  plant: {} x {} per tick", r.integrator, r.substeps);
    if let Some(w) = &r.integrator_warning {
        println!("  warning: {w}");
    }
    for e in &r.effects {
        println!("  effect {:<12} {:>8.1} ns/tick", e.name, e.ns_per_tick);
    }
}
