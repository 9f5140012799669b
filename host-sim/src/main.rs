//! `host-sim`: the scope (no subcommand), headless scene runs, sweeps to a
//! stability boundary, the paper's Table I, and processor-in-the-loop.

use clap::{Args, Parser, Subcommand};
use host_sim::engine::scene::Scene;
use host_sim::study::{passivity, sweep, table1};
use host_sim::{link, Report, Sample, Simulation};
use indicatif::{ProgressBar, ProgressStyle};
use serde_json::json;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Simulate a haptic device around the board's own control code.
#[derive(Parser)]
#[command(name = "host-sim", version, args_conflicts_with_subcommands = true)]
struct Cli {
    #[command(subcommand)]
    cmd: Option<Cmd>,
    #[command(flatten)]
    scope: ScopeArgs,
}

/// The scope: the default when no subcommand is given.
#[derive(Args, Clone)]
struct ScopeArgs {
    /// The scene to open.
    #[arg(long, default_value = "scenes/stiff_wall.toml")]
    scene: PathBuf,
    /// Save the window to this PNG at --exit-after (and at half that time
    /// to NAME.first.png), then close.
    #[arg(long, requires = "exit_after")]
    screenshot: Option<PathBuf>,
    /// Close after this many seconds.
    #[arg(long)]
    exit_after: Option<f64>,
    /// Run the scene headless even where a display exists.
    #[arg(long)]
    headless: bool,
}

#[derive(Subcommand)]
enum Cmd {
    /// The scope window (the same as no subcommand).
    Scope(ScopeArgs),
    /// Run one scene and judge its stability.
    Run(RunArgs),
    /// Find the marginal value of one parameter by bisection.
    Sweep(SweepArgs),
    /// Run the paper's Table I matrix and sweep its boundaries.
    Table1(Table1Args),
    /// Measure what accuracy costs: every integrator x sub-step count.
    Accuracy(AccuracyArgs),
    /// The passivity layer's scenes: off, on, and at passive settings.
    Passivity(PassivityArgs),
    /// Processor-in-the-loop: this plant against a board over a serial port
    /// (the firmware in QEMU, or a real board), compared with the same
    /// board loop run in-process.
    Pil(PilArgs),
}

#[derive(Args)]
struct PilArgs {
    /// The board's serial port (QEMU prints its pty at start). Without it,
    /// only the in-process board loop runs.
    #[arg(long)]
    port: Option<String>,
    /// The scene: plant, hand and effects; the board brings its own law.
    #[arg(default_value = "scenes/stiff_wall.toml")]
    scene: PathBuf,
    /// Simulated time (s).
    #[arg(long, default_value_t = 10.0)]
    seconds: f64,
    /// Every this many ticks, inject a corrupted frame and garbage (0: never).
    #[arg(long, default_value_t = 100)]
    corrupt_every: u64,
    /// Stop sending heartbeats at this time (s) and check the board goes to
    /// zero force within its watchdog deadline.
    #[arg(long)]
    link_loss_at_s: Option<f64>,
    /// The board runs the passivity image (the series damper at the
    /// actuator's port): compare it with that image's in-process loop.
    #[arg(long)]
    passivity: bool,
    /// Print one JSON object on stdout.
    #[arg(long)]
    json: bool,
    /// Fail unless the board matched the in-process loop bit for bit,
    /// dropped every corrupted frame and, after a link loss, held zero force
    /// within its watchdog deadline.
    #[arg(long)]
    check: bool,
}

#[derive(Args)]
struct PassivityArgs {
    /// The folder of the passivity scenes.
    #[arg(long, default_value = "scenes/passivity")]
    scenes: PathBuf,
    /// Print one JSON object on stdout.
    #[arg(long)]
    json: bool,
}

#[derive(Args)]
struct AccuracyArgs {
    /// Folder for accuracy.md, accuracy.json and accuracy.png.
    #[arg(long, default_value = "docs")]
    out: PathBuf,
}

#[derive(Args)]
struct SceneArgs {
    /// The scene file (TOML).
    scene: PathBuf,
    /// Override a scene value, e.g. `--set coupling.k=60000` (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    sets: Vec<String>,
    /// Print one JSON object on stdout.
    #[arg(long)]
    json: bool,
}

#[derive(Args)]
struct RunArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// Simulated time (s), instead of the scene's.
    #[arg(long)]
    duration: Option<f64>,
    /// Write every tick to this CSV file.
    #[arg(long)]
    csv: Option<PathBuf>,
    /// Draw the run to this PNG file.
    #[arg(long)]
    png: Option<PathBuf>,
}

#[derive(Args)]
struct SweepArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// The parameter, as a `--set` key (e.g. coupling.k).
    #[arg(long)]
    param: String,
    /// One end of the range.
    #[arg(long, allow_negative_numbers = true)]
    from: f64,
    /// The other end; stability must differ between the ends.
    #[arg(long, allow_negative_numbers = true)]
    to: f64,
    /// Relative tolerance of the answer.
    #[arg(long, default_value_t = 0.005)]
    tol: f64,
}

#[derive(Args)]
struct Table1Args {
    /// The folder of the Table I scenes.
    #[arg(long, default_value = "scenes/table1")]
    scenes: PathBuf,
    /// Print one JSON object on stdout.
    #[arg(long)]
    json: bool,
}

fn load(path: &Path, sets: &[String]) -> Result<Scene, String> {
    Scene::load(path, sets).map_err(|e| e.to_string())
}

fn run_scene(scene: Scene, mut sink: impl FnMut(&Sample)) -> Result<Report, String> {
    let mut sim = Simulation::new(scene)?;
    Ok(sim.run(&mut sink))
}

fn run(a: &RunArgs) -> Result<(), String> {
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
fn csv_file(
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
fn finish_csv(
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
fn run_xyz(a: &RunArgs, sets: &[String]) -> Result<(), String> {
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
fn print_verdict(scene: &str, reason: &Option<String>) {
    match reason {
        None => println!("{scene}: stable"),
        Some(why) => println!("{scene}: UNSTABLE\n  {why}"),
    }
}

fn print_report(r: &Report) {
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

fn bar(len: u64, msg: String) -> ProgressBar {
    let b = ProgressBar::new(len);
    b.set_style(
        ProgressStyle::with_template("{msg} [{bar:30}] {pos}/{len}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    b.set_message(msg);
    b
}

/// `study` over the scene files in `dir`, with a progress bar of them.
fn over_cases<T>(
    dir: &Path,
    what: &str,
    study: impl FnOnce(&Path, &mut dyn FnMut()) -> Result<T, String>,
) -> Result<T, String> {
    let n = table1::case_files(dir)?.len();
    let b = bar(n as u64, what.into());
    let out = study(dir, &mut || b.inc(1));
    b.finish_and_clear();
    out
}

fn sweep(a: &SweepArgs) -> Result<(), String> {
    if !(a.tol > 0.0 && a.tol < 1.0) {
        return Err(format!("--tol {}: must be between 0 and 1", a.tol));
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
        println!("{}", json!({"param": a.param, "marginal": m}));
    } else {
        println!(
            "{}: marginal value {m:.6} (the last stable value, within {}%)",
            a.param,
            a.tol * 100.0
        );
    }
    Ok(())
}

/// The passivity layer's table: each scene off, on, and at its passive
/// reference.
fn passivity(a: &PassivityArgs) -> Result<(), String> {
    let rows = over_cases(&a.scenes, "passivity scenes", passivity::table)?;
    if a.json {
        println!("{}", json!({ "rows": rows }));
    } else {
        print!("{}", passivity::markdown(&rows));
    }
    Ok(())
}

/// Table I: every VE state x grasp at the theoretical gains, then the
/// boundaries swept as the paper did.
fn table1(a: &Table1Args) -> Result<(), String> {
    let t = over_cases(&a.scenes, "Table I", table1::table1)?;
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
        println!(
            "{}",
            json!({"cases": rows, "all_stable_at_theoretical_gains": all_stable,
            "impedance_boundary_k": k_bound,
            "admittance_boundary_m": m_bound})
        );
        return Ok(());
    }
    println!("Table I  Theoretical versus experimental (paper) and simulated (linear model) stability boundary gains");
    println!(
        "{:<26} {:>10} {:>6}   {:>8} {:>6}",
        "", "k_cI N/m", "b_cI", "m_cA kg", "b_cA"
    );
    println!(
        "{:<26} {:>10} {:>6}   {:>8} {:>6}",
        "theoretical", "51,000", "90", "5.0", "500"
    );
    println!(
        "{:<26} {:>10} {:>6}   {:>8} {:>6}",
        "experimental (paper)", "75,000", "90", "4.3", "500"
    );
    let fmt_k = k_bound.map_or("> 2e6".into(), |k| format!("{k:.0}"));
    let fmt_m = m_bound.map_or("< 0.01".into(), |m| format!("{m:.2}"));
    println!(
        "{:<26} {:>10} {:>6}   {:>8} {:>6}",
        "simulated (this model)", fmt_k, "90", fmt_m, "500"
    );
    println!();
    println!(
        "{:<36} {:>22} {:>14}",
        "case", "stable at theoretical", "boundary"
    );
    for r in &rows {
        let m = r["marginal"]
            .as_f64()
            .map_or("none found".into(), |v| format!("{v:.4}"));
        println!(
            "{:<36} {:>22} {:>14}",
            r["case"].as_str().unwrap_or(""),
            r["stable_at_theoretical_gains"],
            m
        );
    }
    Ok(())
}

fn accuracy(a: &AccuracyArgs) -> Result<(), String> {
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
    println!(
        "wrote {}/accuracy.md, accuracy.json, accuracy.png ({} runs)",
        a.out.display(),
        cells.len()
    );
    Ok(())
}

fn pil(a: &PilArgs) -> Result<(), String> {
    use host_sim::pil;
    if !(a.seconds.is_finite() && a.seconds > 0.0 && a.seconds <= 3600.0) {
        return Err(format!("--seconds {}: must be in (0, 3600]", a.seconds));
    }
    let text =
        std::fs::read_to_string(&a.scene).map_err(|e| format!("{}: {e}", a.scene.display()))?;
    let xyz = host_sim::engine::xyz::axes_of(&text) == Some(3);
    // (Every scene ticks at the board's 1 kHz.)
    let period = 1e-3;
    let ticks = (a.seconds / period).round() as u64;
    let link_loss_at = match a.link_loss_at_s {
        Some(t) if t.is_finite() && t >= 0.0 && t < a.seconds => Some((t / period).round() as u64),
        Some(t) => return Err(format!("--link-loss-at-s {t}: must be in [0, --seconds)")),
        None => None,
    };
    let faults = link::LinkFaults {
        corrupt_every: a.corrupt_every,
        link_loss_at,
    };
    let port = a.port.as_deref().map(link::SerialBoard::open).transpose()?;
    let start = std::time::Instant::now();
    if xyz {
        if a.passivity {
            return Err("--passivity: the three-axis image has no passivity build".into());
        }
        let scene =
            host_sim::engine::xyz::XyzScene::load(&a.scene, &[]).map_err(|e| e.to_string())?;
        let reference = pil::run_xyz(
            scene.clone(),
            ticks,
            link::LocalBoard::excalibur_xyz()?,
            faults,
        )?;
        let local_s = start.elapsed().as_secs_f64();
        let run = port
            .map(|p| pil::run_xyz(scene, ticks, p, faults))
            .transpose()?;
        return pil_report(a, ticks, faults, reference, run, local_s, start);
    }
    let scene = load(&a.scene, &[])?;
    if (scene.period() - period).abs() > 1e-12 {
        return Err(format!(
            "{}: a PIL scene ticks at the board's 1 kHz",
            a.scene.display()
        ));
    }
    let reference = if a.passivity {
        pil::run(
            scene.clone(),
            ticks,
            link::LocalBoard::excalibur_with_passivity()?,
            faults,
        )?
    } else {
        pil::run(scene.clone(), ticks, link::LocalBoard::excalibur()?, faults)?
    };
    let local_s = start.elapsed().as_secs_f64();
    let run = port
        .map(|p| pil::run(scene, ticks, p, faults))
        .transpose()?;
    pil_report(a, ticks, faults, reference, run, local_s, start)
}

/// A PIL run's report, compared with the in-process `reference`: the
/// board's `run` over the serial port where there was one.
fn pil_report<S: host_sim::pil::PilSample>(
    a: &PilArgs,
    ticks: u64,
    faults: host_sim::link::LinkFaults,
    reference: host_sim::pil::Run<S>,
    run: Option<host_sim::pil::Run<S>>,
    local_s: f64,
    start: std::time::Instant,
) -> Result<(), String> {
    use host_sim::pil;
    let board = if run.is_some() {
        "serial"
    } else {
        "in-process"
    };
    let (run, remote_s) = match run {
        Some(r) => (r, start.elapsed().as_secs_f64() - local_s),
        None => (reference.clone(), local_s),
    };
    let c = pil::compare(&run, &reference);
    let frames_dropped = run.board_stats.rx.dropped() + run.host_dropped;
    let loop_cycles = run.telemetry.last().map(|t| t.loop_cycles);
    let axes = run.duties.first().map_or(1, |d| d.len());
    let peak = run
        .samples
        .iter()
        .flat_map(|s| (0..axes).map(|i| s.actuator_n(i).abs()))
        .fold(0.0, f64::max);
    let v = json!({
        "ticks": c.ticks,
        "max_position_error_m": c.max_position_error_m,
        "max_force_error_n": c.max_force_error_n,
        "duty_mismatches": c.duty_mismatches,
        "frames_dropped": frames_dropped,
        "corrupted_sent": run.corrupted_sent,
        "board_frames_received": run.board_stats.rx.frames,
        "zero_force_after_link_loss_ticks": run.zero_after_loss_ticks,
        "watchdog_deadline_ticks": twoport_board::excalibur::HEARTBEAT_TIMEOUT_TICKS,
        "telemetry_frames": run.telemetry.len(),
        "axes": axes,
        "peak_force_n": peak,
        "last_loop_cycles": loop_cycles,
        "last_stage_cycles": run.telemetry.last().map(|t| t.stage_cycles),
        "start": run.start,
        "config_booted": run.config.map(|c| format!("{:?}", c.0)),
        "config_saved": run.config.map(|c| format!("{:?}", c.1)),
        "armed_at_tick": run.armed_at_tick,
        "homing_ticks": run.homing.map(|h| h.0),
        "homing_error_m": run.homing.map(|h| h.1),
        "board": board,
        "wall_s": remote_s,
    });
    if a.json {
        println!("{v}");
    } else {
        println!(
            "PIL ({board}): {} ticks in {remote_s:.2} s; position error {:.3e} m, force error {:.3e} N, \
             {} duty mismatches; {} corrupted frames sent, {frames_dropped} dropped",
            c.ticks, c.max_position_error_m, c.max_force_error_n, c.duty_mismatches,
            run.corrupted_sent
        );
        match run.homing {
            Some((n, err)) => println!(
                "  homed onto the hard stop in {n} ticks (calibration {:+.1} um off the plant), armed at tick {}",
                err * 1e6,
                run.armed_at_tick
            ),
            None => println!("  calibrated at rest, armed at tick {}", run.armed_at_tick),
        }
        if let Some(z) = run.zero_after_loss_ticks {
            println!(
                "  link loss: zero force after {z} ticks (watchdog deadline {})",
                twoport_board::excalibur::HEARTBEAT_TIMEOUT_TICKS
            );
        }
    }
    if a.check {
        let deadline = u64::from(twoport_board::excalibur::HEARTBEAT_TIMEOUT_TICKS);
        let bad = pil::failures(&run, &c, ticks, faults, deadline);
        if !bad.is_empty() {
            return Err(format!("PIL check failed: {}", bad.join("; ")));
        }
    }
    Ok(())
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let r = match &cli.cmd {
        None => scope(&cli.scope),
        Some(Cmd::Scope(a)) => scope(a),
        Some(c) => subcommand(c),
    };
    match r {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("host-sim: {e}");
            ExitCode::from(2)
        }
    }
}

/// The scope, or where no window can open, a headless run of its scene.
fn scope(a: &ScopeArgs) -> Result<(), String> {
    if let Some(t) = a.exit_after {
        if !(t.is_finite() && t > 0.0) {
            return Err(format!(
                "--exit-after {t}: must be a positive number of seconds"
            ));
        }
    }
    let why_headless = if a.headless {
        Some("--headless".to_string())
    } else {
        open_window(a)?
    };
    let Some(why_headless) = why_headless else {
        return Ok(()); // the window ran and closed
    };
    if a.screenshot.is_some() {
        return Err(format!("--screenshot needs a window: {why_headless}"));
    }
    eprintln!(
        "host-sim: {why_headless}; running {} headless instead",
        a.scene.display()
    );
    run(&RunArgs {
        scene: SceneArgs {
            scene: a.scene.clone(),
            sets: Vec::new(),
            json: false,
        },
        duration: None,
        csv: None,
        png: None,
    })
}

/// The scope window; `Ok(Some(why))` where none can open.
#[cfg(feature = "gui")]
fn open_window(a: &ScopeArgs) -> Result<Option<String>, String> {
    if !host_sim::scope::window::display_available() {
        return Ok(Some(
            "no display (DISPLAY and WAYLAND_DISPLAY are unset)".to_string(),
        ));
    }
    let script = host_sim::scope::window::Script {
        screenshot: a.screenshot.clone(),
        exit_after_s: a.exit_after,
    };
    match host_sim::scope::window::run(&a.scene, script) {
        Ok(shots) => {
            for p in shots {
                eprintln!("host-sim: saved {}", p.display());
            }
            Ok(None)
        }
        Err(e) if e.starts_with("the window would not open") => Ok(Some(e)),
        Err(e) => Err(e),
    }
}

/// Built without the `gui` feature: there is no window to open.
#[cfg(not(feature = "gui"))]
fn open_window(_: &ScopeArgs) -> Result<Option<String>, String> {
    Ok(Some("built without the `gui` feature".to_string()))
}

fn subcommand(c: &Cmd) -> Result<(), String> {
    match c {
        Cmd::Scope(a) => scope(a),
        Cmd::Run(a) => run(a),
        Cmd::Sweep(a) => sweep(a),
        Cmd::Passivity(a) => passivity(a),
        Cmd::Table1(a) => table1(a),
        Cmd::Accuracy(a) => accuracy(a),
        Cmd::Pil(a) => pil(a),
    }
}
