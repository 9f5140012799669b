//! `host-sim pil`: this plant against a board, compared with the same
//! board loop in-process.

use crate::run::load;
use clap::Args;
use host_sim::link;
use host_sim::Error;
use serde_json::json;
use std::path::PathBuf;

#[derive(Args)]
pub(crate) struct PilArgs {
    /// The board's serial port (QEMU prints its pty at start). Without it,
    /// only the in-process board loop runs.
    #[arg(long)]
    pub(crate) port: Option<String>,
    /// The scene: plant, hand and effects; the board brings its own law.
    #[arg(default_value = "scenes/stiff_wall.toml")]
    pub(crate) scene: PathBuf,
    /// Override a scene value, e.g. `--set plant.handle_mass_kg=0.5`
    /// (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub(crate) sets: Vec<String>,
    /// Simulated time (s).
    #[arg(long, default_value_t = 10.0)]
    pub(crate) seconds: f64,
    /// Every this many ticks, inject a corrupted frame and garbage (0: never).
    #[arg(long, default_value_t = 100)]
    pub(crate) corrupt_every: u64,
    /// Stop sending heartbeats at this time (s) and check the board goes to
    /// zero force within its watchdog deadline.
    #[arg(long)]
    pub(crate) link_loss_at_s: Option<f64>,
    /// The board runs the passivity image (the series damper at the
    /// actuator's port): compare it with that image's in-process loop.
    #[arg(long)]
    pub(crate) passivity: bool,
    /// The board runs a linkage image: the device file's nonlinear arm
    /// against it, pressed into the image's floor (the scene is not read).
    #[arg(long, value_enum)]
    pub(crate) linkage: Option<host_sim::pil::linkage::LinkageImage>,
    /// The board runs the 4 kHz image (`twoport_board::excalibur::fast`):
    /// the scene's period must be its 0.25 ms.
    #[arg(long)]
    pub(crate) fast: bool,
    /// Run the VE on the host at this rate (Hz): the scene's wall sent as
    /// a surface every board-rate / this ticks, ramped over as many, the
    /// board's own wall set aside. The board's rate must be a whole
    /// multiple.
    #[arg(long)]
    pub(crate) host_ve_hz: Option<f64>,
    /// Write the identification experiment's record (the scene's
    /// `[identify]`) to this CSV file: the board's over the port where
    /// there is one, else the in-process loop's. With --sines, the folder
    /// the levels' records go into.
    #[arg(long)]
    pub(crate) log: Option<PathBuf>,
    /// With --linkage: instead of the press, the image plays a sine on
    /// each Cartesian axis at each of these peak forces (N, lowest first),
    /// hands off from its calibration pose, the joints' friction acting,
    /// in-process; each level's records go into --log's folder as
    /// LEVELN/PUSHED-AXIS.csv, what `twoport identify-pose` reads.
    #[arg(long, value_delimiter = ',', allow_negative_numbers = true)]
    pub(crate) sines: Vec<f64>,
    /// The sines' frequency (Hz).
    #[arg(long, default_value_t = 10.0, allow_negative_numbers = true)]
    pub(crate) sine_hz: f64,
    /// The scene is a teleoperation scene: its master and its slave each
    /// on a board of the one-axis image (`--port` the master's,
    /// `--slave-port` the slave's), the host the channel between them.
    #[arg(long)]
    pub(crate) teleop: bool,
    /// With --teleop: the slave's board's serial port.
    #[arg(long, requires = "teleop")]
    pub(crate) slave_port: Option<String>,
    /// Print one JSON object on stdout (with --teleop, one per side).
    #[arg(long)]
    pub(crate) json: bool,
    /// Fail unless the board matched the in-process loop bit for bit,
    /// dropped every corrupted frame and, after a link loss, held zero force
    /// within its watchdog deadline.
    #[arg(long)]
    pub(crate) check: bool,
}

/// `--linkage --sines`: every level's records written for
/// `twoport identify-pose`.
fn sines(a: &PilArgs, device: host_sim::pil::linkage::LinkageImage) -> Result<(), Error> {
    use twoport_identify::pose::record_file;
    let dir = a
        .log
        .as_ref()
        .ok_or_else(|| err!("--sines: give --log, the folder the records go into"))?;
    if a.port.is_some() {
        return Err(err!("--sines: the sines run in-process (no --port)"));
    }
    if let Some(l) = a.sines.iter().find(|l| !(l.is_finite() && **l > 0.0)) {
        return Err(err!(
            "--sines {l}: each level must be a finite force > 0 (N)"
        ));
    }
    let s = host_sim::pil::linkage::Sines {
        hz: a.sine_hz,
        periods: 24,
        levels_n: a.sines.clone(),
        hold: (100.0, 1.0),
        friction: true,
    };
    let levels = s.play(device)?;
    let mut folders = Vec::new();
    for (level, runs) in a.sines.iter().zip(&levels) {
        let folder = dir.join(format!("{level}N"));
        std::fs::create_dir_all(&folder).map_err(|e| err!("--log {}: {e}", folder.display()))?;
        for (pushed, axes) in runs.iter().enumerate() {
            for (axis, log) in axes.iter().enumerate() {
                let path = folder.join(record_file(pushed, axis).expect("three axes"));
                std::fs::write(&path, log.to_csv())
                    .map_err(|e| err!("--log {}: {e}", path.display()))?;
            }
        }
        folders.push(folder);
    }
    if a.json {
        let v = serde_json::json!({
            "linkage": device,
            "sine_hz": s.hz,
            "periods": s.periods,
            "levels_n": s.levels_n,
            "folders": folders,
        });
        say!("{v}");
    } else {
        say!(
            "{device:?}: a {} Hz sine on each axis at {:?} N, {} periods each; records in {}",
            s.hz,
            s.levels_n,
            s.periods,
            folders
                .iter()
                .map(|f| f.display().to_string())
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    Ok(())
}

pub(crate) fn pil(a: &PilArgs) -> Result<(), Error> {
    if !a.sines.is_empty() {
        let device = a
            .linkage
            .ok_or_else(|| err!("--sines: the sines play on a linkage image (give --linkage)"))?;
        return sines(a, device);
    }
    if !(a.seconds.is_finite() && a.seconds > 0.0 && a.seconds <= 3600.0) {
        return Err(err!("--seconds {}: must be in (0, 3600]", a.seconds));
    }
    if a.teleop {
        return pair(a);
    }
    let scene = load(&a.scene, &a.sets)?;
    // The board's period: the scene must tick at it.
    let (period, deadline) = if a.fast {
        let f = twoport_board::excalibur::fast::PERIOD_S;
        (
            f64::from(f),
            twoport_board::excalibur::fast::HEARTBEAT_TIMEOUT_TICKS,
        )
    } else {
        (1e-3, twoport_board::excalibur::HEARTBEAT_TIMEOUT_TICKS)
    };
    let host_ve = host_ve(a, period)?;
    // (The board's f32 period, to its rounding.)
    if (scene.period() - period).abs() > 1e-6 * period {
        return Err(err!(
            "{}: a PIL scene ticks at the board's {} Hz (period_s = {period})",
            a.scene.display(),
            1.0 / period
        ));
    }
    let faults = faults(a, period)?;
    let port = a.port.as_deref().map(link::SerialBoard::open).transpose()?;
    let run = Compared {
        a,
        side: None,
        ticks: (a.seconds / period).round() as u64,
        faults,
        // (After the port opens: the in-process run's time starts here.)
        start: std::time::Instant::now(),
        deadline,
    };
    if a.fast || host_ve.is_some() {
        return run.wall_image(scene, port, host_ve);
    }
    if let Some(device) = a.linkage {
        return run.linkage(device, port);
    }
    if scene.axes == 3 {
        return run.three_axes(scene, port);
    }
    run.one_axis(scene, port)
}

/// One run against a board, and the same run against the board's loop in
/// this process: what every kind of run shares.
pub(crate) struct Compared<'a> {
    a: &'a PilArgs,
    /// Which side of a teleoperator, if one.
    side: Option<&'static str>,
    ticks: u64,
    faults: link::LinkFaults,
    /// When the in-process run began.
    start: std::time::Instant,
    /// The board's heartbeat deadline (ticks).
    deadline: u32,
}

impl Compared<'_> {
    /// The one-axis wall images with `--fast` or a host VE.
    fn wall_image(
        &self,
        scene: host_sim::Scene,
        port: Option<link::SerialBoard>,
        host_ve: Option<host_sim::pil::HostVe>,
    ) -> Result<(), Error> {
        use host_sim::pil::run_with;
        let a = self.a;
        if a.passivity || a.linkage.is_some() || scene.axes != 1 {
            return Err(
                "--fast and --host-ve-hz run the one-axis wall images (no --passivity, --linkage or three axes)".into(),
            );
        }
        let (ticks, faults) = (self.ticks, self.faults);
        let reference = if a.fast {
            let board = link::LocalFast::excalibur_fast()?;
            run_with::<_, 1>(scene.clone(), ticks, board, faults, host_ve)?
        } else {
            let board = link::LocalBoard::excalibur()?;
            run_with::<_, 1>(scene.clone(), ticks, board, faults, host_ve)?
        };
        let local_s = self.start.elapsed().as_secs_f64();
        let run = port
            .map(|p| run_with::<_, 1>(scene, ticks, p, faults, host_ve))
            .transpose()?;
        self.report(reference, run, local_s)
    }

    /// `--linkage`: a linkage image pressing its floor.
    fn linkage(
        &self,
        device: host_sim::pil::linkage::LinkageImage,
        port: Option<link::SerialBoard>,
    ) -> Result<(), Error> {
        use host_sim::pil::linkage;
        if self.a.passivity {
            return Err("--passivity: the linkage images have no passivity build".into());
        }
        let (ticks, faults) = (self.ticks, self.faults);
        let reference = linkage::run_local(device, ticks, faults, linkage::Plan::Press)?;
        let local_s = self.start.elapsed().as_secs_f64();
        let run = port
            .map(|p| linkage::run(device, ticks, p, faults))
            .transpose()?;
        self.report(reference, run, local_s)
    }

    /// The three-axis image.
    fn three_axes(
        &self,
        scene: host_sim::Scene,
        port: Option<link::SerialBoard>,
    ) -> Result<(), Error> {
        use host_sim::pil::run_axes;
        if self.a.passivity {
            return Err("--passivity: the three-axis image has no passivity build".into());
        }
        let (ticks, faults) = (self.ticks, self.faults);
        let board = link::LocalBoard::excalibur_xyz()?;
        let reference = run_axes::<_, 3>(scene.clone(), ticks, board, faults)?;
        let local_s = self.start.elapsed().as_secs_f64();
        let run = port
            .map(|p| run_axes::<_, 3>(scene, ticks, p, faults))
            .transpose()?;
        self.report(reference, run, local_s)
    }

    /// The one-axis image, with or without its passivity layer, and the
    /// experiment's log on request.
    fn one_axis(
        &self,
        scene: host_sim::Scene,
        port: Option<link::SerialBoard>,
    ) -> Result<(), Error> {
        use host_sim::pil::run;
        let (a, ticks, faults) = (self.a, self.ticks, self.faults);
        let reference = if a.passivity {
            let board = link::LocalBoard::excalibur_with_passivity()?;
            run(scene.clone(), ticks, board, faults)?
        } else {
            run(scene.clone(), ticks, link::LocalBoard::excalibur()?, faults)?
        };
        let local_s = self.start.elapsed().as_secs_f64();
        let load_cell = scene.effects.load_cell;
        let remote = port.map(|p| run(scene, ticks, p, faults)).transpose()?;
        if let Some(path) = &a.log {
            let log = remote
                .as_ref()
                .unwrap_or(&reference)
                .experiment_log(load_cell)
                .ok_or_else(|| {
                    err!("--log: the scene plays no experiment (add an [identify] section)")
                })??;
            std::fs::write(path, log.to_csv())
                .map_err(|e| err!("--log {}: {e}", path.display()))?;
        }
        self.report(reference, remote, local_s)
    }
}

/// `--host-ve-hz` as the host's VE period in board ticks (`period` s),
/// with ten of them as its deadline.
fn host_ve(a: &PilArgs, period: f64) -> Result<Option<host_sim::pil::HostVe>, Error> {
    let Some(hz) = a.host_ve_hz else {
        return Ok(None);
    };
    let every = 1.0 / (period * hz);
    if !(every.is_finite() && every >= 1.0 - 1e-6 && (every - every.round()).abs() < 1e-6 * every) {
        return Err(err!(
            "--host-ve-hz {hz}: the board's {} Hz is not a whole multiple of it",
            1.0 / period
        ));
    }
    let every = every.round() as u32;
    Ok(Some(host_sim::pil::HostVe {
        every_ticks: every,
        deadline_ticks: 10 * every,
    }))
}

/// The faults `--corrupt-every` and `--link-loss-at-s` put on the link,
/// in ticks of `period` s.
fn faults(a: &PilArgs, period: f64) -> Result<link::LinkFaults, Error> {
    let link_loss_at = match a.link_loss_at_s {
        Some(t) if t.is_finite() && t >= 0.0 && t < a.seconds => Some((t / period).round() as u64),
        Some(t) => return Err(err!("--link-loss-at-s {t}: must be in [0, --seconds)")),
        None => None,
    };
    Ok(link::LinkFaults {
        corrupt_every: a.corrupt_every,
        link_loss_at,
    })
}

/// A PIL run's report, compared with the in-process `reference`: the
/// board's `run` over the serial port where there was one; the board's
/// watchdog waits `deadline` ticks.
#[allow(clippy::too_many_arguments)]
impl Compared<'_> {
    /// Compare `run` (the board's, if one ran) with `reference`, the
    /// in-process run that took `local_s` (s); say how they compare, and
    /// with `--check` fail where the board broke a promise.
    fn report<const N: usize>(
        &self,
        reference: host_sim::pil::Run<N>,
        run: Option<host_sim::pil::Run<N>>,
        local_s: f64,
    ) -> Result<(), Error> {
        let Compared {
            a,
            side,
            ticks,
            faults,
            start,
            deadline,
        } = *self;
        use host_sim::pil;
        let board = match (run.is_some(), side) {
            (true, None) => "serial".to_string(),
            (false, None) => "in-process".to_string(),
            (true, Some(s)) => format!("serial, {s}"),
            (false, Some(s)) => format!("in-process, {s}"),
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
            .flat_map(|s| s.actuator_n.iter().map(|f| f.abs()))
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
            "watchdog_deadline_ticks": deadline,
            "ve_updates_sent": run.ve_updates_sent,
            "ve_seq_held": run.telemetry.last().map(|t| t.ve_seq),
            "telemetry_frames": run.telemetry.len(),
            "axes": axes,
            "peak_force_n": peak,
            "last_loop_cycles": loop_cycles,
            "last_stage_cycles": run.telemetry.last().map(|t| t.stage_cycles),
            "worst_latency_cycles": run.telemetry.last().map(|t| t.worst_latency_cycles),
            "start": run.start,
            "config_booted": run.config.map(|c| format!("{:?}", c.0)),
            "config_saved": run.config.map(|c| format!("{:?}", c.1)),
            "armed_at_tick": run.armed_at_tick,
            "homing_ticks": run.homing.map(|h| h.0),
            "homing_error_m": run.homing.map(|h| h.1),
            "board": board,
            "side": side,
            "wall_s": remote_s,
        });
        if a.json {
            say!("{v}");
        } else {
            say!(
            "PIL ({board}): {} ticks in {remote_s:.2} s; position error {:.3e} m, force error {:.3e} N, \
             {} duty mismatches; {} corrupted frames sent, {frames_dropped} dropped",
            c.ticks, c.max_position_error_m, c.max_force_error_n, c.duty_mismatches,
            run.corrupted_sent
        );
            match run.homing {
            Some((n, err)) => say!(
                "  homed onto the hard stop in {n} ticks (calibration {:+.1} um off the plant), armed at tick {}",
                err * 1e6,
                run.armed_at_tick
            ),
            None => say!("  calibrated at rest, armed at tick {}", run.armed_at_tick),
        }
            if run.ve_updates_sent > 0 {
                say!(
                    "  host VE: {} updates sent, the board's last telemetry holds update {}",
                    run.ve_updates_sent,
                    run.telemetry.last().map_or(0, |t| t.ve_seq)
                );
            }
            if let Some(z) = run.zero_after_loss_ticks {
                say!("  link loss: zero force after {z} ticks (watchdog deadline {deadline})");
            }
        }
        if a.check {
            let bad = pil::failures(&run, &c, ticks, faults, u64::from(deadline));
            if !bad.is_empty() {
                let on = side.map(|s| format!(" ({s})")).unwrap_or_default();
                return Err(err!("PIL check failed{on}: {}", bad.join("; ")));
            }
        }
        Ok(())
    }
}

/// `--teleop`: the scene's master and slave each on a board, the host
/// between them, against the same pair of board loops in-process.
fn pair(a: &PilArgs) -> Result<(), Error> {
    use host_sim::engine::teleop::TeleopScene;
    use host_sim::pil::teleop::run_pair;
    if a.fast || a.passivity || a.linkage.is_some() || a.host_ve_hz.is_some() || a.log.is_some() {
        return Err(err!(
            "--teleop: a pair runs the one-axis image (no --fast, --passivity, --linkage, --host-ve-hz or --log)"
        ));
    }
    let scene = TeleopScene::load(&a.scene, &a.sets)?;
    let (period, deadline) = (1e-3, twoport_board::excalibur::HEARTBEAT_TIMEOUT_TICKS);
    if (scene.period() - period).abs() > 1e-6 * period {
        return Err(err!(
            "{}: a PIL pair ticks at the board's 1000 Hz (period_s = {period})",
            a.scene.display()
        ));
    }
    let ticks = (a.seconds / period).round() as u64;
    let faults = faults(a, period)?;
    let ports = match (&a.port, &a.slave_port) {
        (Some(m), Some(s)) => Some([link::SerialBoard::open(m)?, link::SerialBoard::open(s)?]),
        (None, None) => None,
        _ => {
            return Err(err!(
                "--teleop: give both boards' ports (--port and --slave-port), or neither"
            ))
        }
    };
    let start = std::time::Instant::now();
    let local = || link::LocalBoard::excalibur();
    let reference = run_pair(&scene, ticks, [local()?, local()?], faults)?;
    let local_s = start.elapsed().as_secs_f64();
    let runs = ports
        .map(|p| run_pair(&scene, ticks, p, faults))
        .transpose()?;
    let [rm, rs] = reference.runs;
    let (m, s) = match runs {
        Some(p) => {
            let [m, s] = p.runs;
            (Some(m), Some(s))
        }
        None => (None, None),
    };
    let mut run = Compared {
        a,
        side: Some("master"),
        ticks,
        faults,
        start,
        deadline,
    };
    run.report(rm, m, local_s)?;
    run.side = Some("slave");
    run.report(rs, s, local_s)
}
