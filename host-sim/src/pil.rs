//! Processor-in-the-loop: host-sim's plant, hand and effects at one end, the
//! board's loop at the other, exchanging one sensor frame and one actuator
//! frame per tick over the link protocol (lockstep).
//!
//! The board end is a [`BoardPort`]: a serial port (the firmware in QEMU
//! through a pty, or a real board), or the same `twoport-board` loop
//! in-process. A run sends both ends the same bytes: heartbeats, sensor
//! frames and, if asked, corrupted frames and a link loss, so the in-process
//! run is the reference the firmware must match.

use crate::engine::sim::round_counts;
use crate::engine::xyz::{XyzSample, XyzScene, XyzSimulation};
use crate::link::{BoardPort, LinkFaults, Session};
use crate::{Sample, Scene, Simulation};
use twoport_board::excalibur::{self, xyz};
use twoport_control::servo::{SensorFrame, ServoOutput};
use twoport_control::Faults as BoardFaults;
use twoport_link::{
    Axes, ConfigSource, LinkStats, Message, Mode, ModeRequest, PilSensors, Status, Telemetry,
};

/// How far a homed board's position may be from the plant's: the stop's
/// give under the homing force (25 µm on the scenes' 2e5 N/m stop) and a
/// count or two.
pub const HOMING_TOLERANCE_M: f64 = 50e-6;

/// One PIL run's record, its samples `S` (the one-axis simulation's by
/// default, or the three-axis one's [`XyzSample`]).
#[derive(Clone, Debug)]
pub struct Run<S = Sample> {
    /// One sample per tick.
    pub samples: Vec<S>,
    /// The duties the board answered each tick, one per axis.
    pub duties: Vec<Axes<i16>>,
    /// Telemetry received.
    pub telemetry: Vec<Telemetry>,
    /// Frames the host injected corrupted.
    pub corrupted_sent: u64,
    /// The board's link counters at the end.
    pub board_stats: LinkStats,
    /// Host-side frames dropped from the board.
    pub host_dropped: u32,
    /// Ticks from the link loss to the first zero duty that stayed zero.
    pub zero_after_loss_ticks: Option<u64>,
    /// How the board was armed.
    pub start: Option<Start>,
    /// Where its configuration came from at boot, and after the run saved
    /// it (disarmed, before arming).
    pub config: Option<(ConfigSource, ConfigSource)>,
    /// The tick the board armed at.
    pub armed_at_tick: u64,
    /// Homing: the ticks it took, and how far the board's calibrated
    /// position was from the plant's then (m).
    pub homing: Option<(u64, f64)>,
}

impl<S> Default for Run<S> {
    fn default() -> Self {
        Run {
            samples: Vec::new(),
            duties: Vec::new(),
            telemetry: Vec::new(),
            corrupted_sent: 0,
            board_stats: LinkStats::default(),
            host_dropped: 0,
            zero_after_loss_ticks: None,
            start: None,
            config: None,
            armed_at_tick: 0,
            homing: None,
        }
    }
}

/// What a PIL run records of a tick: every axis's handle position and
/// delivered force.
pub trait PilSample: Clone {
    /// Axis `axis`'s handle position (m).
    fn handle_m(&self, axis: usize) -> f64;
    /// The force axis `axis`'s actuator delivered (N).
    fn actuator_n(&self, axis: usize) -> f64;
}

impl PilSample for Sample {
    fn handle_m(&self, _: usize) -> f64 {
        self.handle_m
    }
    fn actuator_n(&self, _: usize) -> f64 {
        self.actuator_n
    }
}

impl PilSample for XyzSample {
    fn handle_m(&self, axis: usize) -> f64 {
        self.handle_m[axis]
    }
    fn actuator_n(&self, axis: usize) -> f64 {
        self.actuator_n[axis]
    }
}

/// How a PIL run gets its board going.
#[derive(Clone, Copy, Debug)]
pub struct Setup {
    /// Calibrated or homed, then armed.
    pub start: Start,
    /// Where each axis stands at rest before the run, as the host tells a
    /// board it calibrates (pm).
    pub at_rest_pm: Axes<i64>,
    /// The encoder's index mark (m), if the scene's encoder has one.
    pub index_m: Option<f64>,
}

/// A simulated device a PIL run drives through a board: the one-axis
/// [`Simulation`] or the three-axis [`XyzSimulation`].
pub trait PilPlant {
    /// What a tick records.
    type Sample: PilSample;
    /// The device's axes.
    const AXES: u8;
    /// How a run begins, once the scene's device is checked to be the
    /// board's (its sensors, its world).
    fn setup(&self) -> Result<Setup, String>;
    /// One tick with the board at the other end of `session` as its
    /// controller: the sample and the duties the board answered.
    fn step_with<P: BoardPort>(
        &mut self,
        session: &mut Session<P>,
    ) -> Result<(Self::Sample, Axes<i16>), String>;
}

impl PilPlant for Simulation {
    type Sample = Sample;
    const AXES: u8 = 1;
    fn setup(&self) -> Result<Setup, String> {
        check_scene(self.scene())?;
        Ok(Setup {
            start: Start::for_scene(self.scene()),
            at_rest_pm: Axes::one(0),
            index_m: self.scene().effects.encoder.and_then(|e| e.index_m),
        })
    }
    fn step_with<P: BoardPort>(
        &mut self,
        session: &mut Session<P>,
    ) -> Result<(Sample, Axes<i16>), String> {
        session.step(self).map(|(s, d)| (s, Axes::one(d)))
    }
}

impl PilPlant for XyzSimulation {
    type Sample = XyzSample;
    const AXES: u8 = 3;
    fn setup(&self) -> Result<Setup, String> {
        check_xyz_scene(self.scene())?;
        // Calibrated where the image's world starts its cursor.
        let x = xyz::world().map(|w| w.cursor()).unwrap_or_default();
        Ok(Setup {
            start: Start::Calibrate,
            at_rest_pm: Axes::new(x.map(|p| p.nm() as i64 * 1000)).unwrap_or_default(),
            index_m: None,
        })
    }
    fn step_with<P: BoardPort>(
        &mut self,
        session: &mut Session<P>,
    ) -> Result<(XyzSample, Axes<i16>), String> {
        session.tick_heartbeat()?;
        let io = session.io;
        let (bits, pm) = excalibur::ENCODER;
        let mask = ((1u64 << bits) - 1) as u32;
        let tick = self.ticks();
        let mut answer = Ok(Axes::one(0));
        let mut ctl = |x_m: [f64; 3]| -> [f64; 3] {
            // The counter keeps the count's low `bits`, as in the one-axis
            // simulation's sensing.
            let raw = x_m.map(|x| (round_counts(x * 1e12 / pm as f64) as u32) & mask);
            let sensors = PilSensors {
                tick: tick as u32,
                encoder_raw: Axes::new(raw).unwrap_or_default(),
                load_cell_raw: Axes::new([0; 3]).unwrap_or_default(),
                dead_man_closed: true,
                index_raw: Axes::new([None; 3]).unwrap_or_default(),
            };
            answer = session.exchange(tick, sensors);
            let duty = |a: usize| answer.as_ref().ok().and_then(|d| d.get(a).copied());
            [0, 1, 2].map(|a| io.force_n(duty(a).unwrap_or(0)) as f64)
        };
        let sample = self.step_external(&mut ctl);
        Ok((sample, answer?))
    }
}

impl<P: BoardPort> Session<P> {
    /// One tick of `sim` with the board as its controller; returns the
    /// sample and the duty the board answered.
    pub fn step(&mut self, sim: &mut Simulation) -> Result<(Sample, i16), String> {
        let tick = self.tick_heartbeat()?;
        let mut answer: Result<i16, String> = Ok(0);
        let io = self.io;
        let mut ctl = |f: &SensorFrame| -> ServoOutput {
            let sensors = PilSensors {
                tick: f.tick,
                encoder_raw: Axes::one(f.encoder_raw[0]),
                load_cell_raw: Axes::one(io.load_cell_counts(f.load_cell_n[0])),
                dead_man_closed: f.dead_man_closed,
                index_raw: Axes::one(self.index_crossing(f.encoder_raw[0])),
            };
            answer = self.exchange(tick, sensors).map(|d| d[0]);
            let force = io.force_n(*answer.as_ref().unwrap_or(&0));
            ServoOutput {
                actuator_force_n: [force],
                commanded_force_n: [force],
                ..ServoOutput::default()
            }
        };
        let sample = sim.step_external(&mut ctl);
        Ok((sample, answer?))
    }
}

/// How a run gets its board from disarmed to armed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub enum Start {
    /// Tell the board where it stands: every scene starts at rest at 0.
    Calibrate,
    /// Home it onto the scene's hard stop (`effects.hard_stop`).
    Home,
}

impl Start {
    /// Home where the scene has a hard stop, else calibrate.
    pub fn for_scene(scene: &Scene) -> Start {
        if scene.effects.hard_stop.is_some() {
            Start::Home
        } else {
            Start::Calibrate
        }
    }
}

/// The scene's sensors must be the board's: the same encoder.
pub fn check_scene(scene: &Scene) -> Result<(), String> {
    let (bits, pm) = excalibur::ENCODER;
    match scene.effects.encoder {
        Some(e) if e.bits == bits && (e.resolution_m * 1e12).round() as i64 == pm => Ok(()),
        _ => Err(format!(
            "the scene's encoder must be the board's ({bits} bits, {} um per count): \
             set effects.encoder = {{ resolution_m = {:e}, bits = {bits} }}",
            pm as f64 * 1e-6,
            pm as f64 * 1e-12
        )),
    }
}

/// The three-axis scene's device must be the three-axis image's: its
/// world holds the image's blocks, which the board simulates (the scene's
/// grab and release times cannot reach it over the link).
pub fn check_xyz_scene(scene: &XyzScene) -> Result<(), String> {
    use crate::engine::xyz::XyzVe;
    let want: Vec<_> = xyz::BLOCKS.to_vec();
    match &scene.ve {
        XyzVe::Blocks {
            blocks,
            grab_at_s,
            release_at_s,
            ..
        } if grab_at_s.is_empty() && release_at_s.is_empty() => {
            let have: Vec<_> = blocks
                .iter()
                .map(|b| {
                    (
                        b.at_m.map(|x| x as f32),
                        b.size_m.map(|x| x as f32),
                        b.mass_kg as f32,
                    )
                })
                .collect();
            if have == want {
                Ok(())
            } else {
                Err(format!(
                    "the scene's blocks must be the three-axis image's (twoport_board::excalibur::xyz::BLOCKS): {want:?}"
                ))
            }
        }
        XyzVe::Blocks { .. } => Err(
            "a processor-in-the-loop scene cannot grab or release: the board's world runs there, \
             and the link carries no grab; remove ve.grab_at_s and ve.release_at_s"
                .into(),
        ),
        _ => Err(
            "the three-axis image runs the building-block world: set ve.kind = \"blocks\"".into(),
        ),
    }
}

/// How homing has ended, from the statuses a board sent: `None` while it
/// goes on, the error where it failed.
pub fn homed(statuses: &[Status]) -> Option<Result<(), String>> {
    statuses.iter().find_map(|s| match s.mode {
        Mode::Homing => None,
        _ if s.faults != 0 => Some(Err(format!(
            "homing ended with faults: {}",
            BoardFaults(s.faults)
        ))),
        _ if s.calibrated => Some(Ok(())),
        m => Some(Err(format!("homing ended uncalibrated, in mode {m:?}"))),
    })
}

/// One tick of a run, recorded; returns the statuses the board sent.
fn record<P: BoardPort, M: PilPlant>(
    session: &mut Session<P>,
    sim: &mut M,
    r: &mut Run<M::Sample>,
) -> Result<Vec<Status>, String> {
    let (s, duty) = sim.step_with(session)?;
    r.samples.push(s);
    r.duties.push(duty);
    let mut statuses = Vec::new();
    for m in session.take_messages() {
        match m {
            Message::Telemetry(t) => r.telemetry.push(t),
            Message::Status(s) => statuses.push(s),
            _ => {}
        }
    }
    Ok(statuses)
}

/// Run `scene` for `ticks` against the board at `port`: the first tick
/// disarmed, then the board calibrated (or homed, for a scene with a hard
/// stop) and armed, then the rest.
pub fn run<P: BoardPort>(
    scene: Scene,
    ticks: u64,
    port: P,
    faults: LinkFaults,
) -> Result<Run, String> {
    run_plant(Simulation::new(scene)?, ticks, port, faults)
}

/// [`run`] for a three-axis scene against a three-axis board: calibrated
/// where the scene's device starts (the image's world's start), then armed.
pub fn run_xyz<P: BoardPort>(
    scene: XyzScene,
    ticks: u64,
    port: P,
    faults: LinkFaults,
) -> Result<Run<XyzSample>, String> {
    run_plant(XyzSimulation::new(scene)?, ticks, port, faults)
}

/// [`run`] of any simulated device.
pub fn run_plant<P: BoardPort, M: PilPlant>(
    mut sim: M,
    ticks: u64,
    port: P,
    faults: LinkFaults,
) -> Result<Run<M::Sample>, String> {
    let setup = sim.setup()?;
    let start = setup.start;
    let mut session = Session::open_axes(port, faults, M::AXES)?;
    session.set_index(setup.index_m);
    let mut r = Run {
        start: Some(start),
        ..Run::default()
    };
    // The configuration: what it booted with, then saved, which a PIL
    // board does while it waits for its first tick.
    let booted = session.config()?;
    session.send(&Message::SaveConfig)?;
    let saved = session.wait("SaveConfig", |m| match m {
        Message::Config(c @ ConfigSource::Stored { .. }) => Some(Ok(*c)),
        Message::ModeRefused {
            asked: ModeRequest::SaveConfig,
            why,
        } => Some(Err(format!("the board refused SaveConfig: {why:?}"))),
        _ => None,
    })??;
    r.config = Some((booted, saved));
    record(&mut session, &mut sim, &mut r)?;
    match start {
        Start::Calibrate => {
            session.calibrate(setup.at_rest_pm)?;
        }
        Start::Home => {
            session.home()?;
            loop {
                let statuses = record(&mut session, &mut sim, &mut r)?;
                if let Some(done) = homed(&statuses) {
                    done?;
                    break;
                }
                if r.samples.len() as u64 >= ticks {
                    return Err(format!("the board had not homed after {ticks} ticks"));
                }
            }
            r.homing = Some((r.samples.len() as u64 - 1, f64::NAN));
        }
    }
    // Armed straight after the status that allowed it, which the board
    // sends before that tick's actuator frame: the same tick on every
    // transport.
    session.arm()?;
    r.armed_at_tick = r.samples.len() as u64;
    while (r.samples.len() as u64) < ticks {
        record(&mut session, &mut sim, &mut r)?;
    }
    if let Some((n, err)) = &mut r.homing {
        // The board's position in its first telemetry after homing
        // against the plant's where that tick read its sensors: the end of
        // the tick before.
        if let Some(t) = r.telemetry.iter().find(|t| u64::from(t.tick) > *n) {
            if let Some(s) = r.samples.get(t.tick as usize - 1) {
                *err = t.axes[0].position_pm as f64 * 1e-12 - s.handle_m(0);
            }
        }
    }
    r.board_stats = session.board_stats()?;
    r.host_dropped = session.host_dropped();
    r.corrupted_sent = session.corrupted_sent;
    if let Some(t0) = faults.link_loss_at {
        // The last tick with a non-zero duty after the loss, plus one.
        let last_nonzero = r
            .duties
            .iter()
            .skip(t0 as usize)
            .rposition(|d| d.iter().any(|d| *d != 0));
        r.zero_after_loss_ticks = Some(last_nonzero.map_or(0, |i| i as u64 + 1));
    }
    Ok(r)
}

/// How far two runs of the same scene drift apart.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct Comparison {
    /// Ticks compared.
    pub ticks: u64,
    /// Largest handle-position difference (m).
    pub max_position_error_m: f64,
    /// Largest actuator-force difference (N).
    pub max_force_error_n: f64,
    /// Ticks whose duty differs.
    pub duty_mismatches: u64,
    /// Whether the two boards armed (or homed) at different ticks.
    pub start_differs: bool,
}

/// Compare a run with its reference, tick by tick, every axis.
pub fn compare<S: PilSample>(a: &Run<S>, b: &Run<S>) -> Comparison {
    let mut c = Comparison {
        ticks: a.samples.len().min(b.samples.len()) as u64,
        ..Comparison::default()
    };
    let axes = a.duties.first().map_or(1, |d| d.len());
    for (x, y) in a.samples.iter().zip(&b.samples) {
        for i in 0..axes {
            let dx = (x.handle_m(i) - y.handle_m(i)).abs();
            let df = (x.actuator_n(i) - y.actuator_n(i)).abs();
            c.max_position_error_m = c.max_position_error_m.max(dx);
            c.max_force_error_n = c.max_force_error_n.max(df);
        }
    }
    c.start_differs =
        (a.armed_at_tick, a.homing.map(|h| h.0)) != (b.armed_at_tick, b.homing.map(|h| h.0));
    c.duty_mismatches = a
        .duties
        .iter()
        .zip(&b.duties)
        .filter(|(x, y)| x != y)
        .count() as u64;
    c
}
/// Why a PIL run fails its check, or nothing where it passes. `run` is the
/// board's, compared with the in-process loop as `c`; it was to take
/// `ticks` ticks with the host's heartbeats stopping at `faults.link_loss_at`,
/// after which the board must have zeroed the force within
/// `deadline_ticks`. A run fails where the board differs from the loop at
/// all (bit for bit), where ticks are missing, where it dropped fewer frames
/// than were corrupted on purpose, or where it was late to zero the force
/// (or was not pushing before the loss, so the check would prove nothing).
pub fn failures<S: PilSample>(
    run: &Run<S>,
    c: &Comparison,
    ticks: u64,
    faults: LinkFaults,
    deadline_ticks: u64,
) -> Vec<String> {
    let mut bad = Vec::new();
    if c.duty_mismatches > 0 || c.max_position_error_m > 0.0 || c.max_force_error_n > 0.0 {
        bad.push(format!(
            "the board differs from the in-process loop ({} duties, {:.3e} m, {:.3e} N)",
            c.duty_mismatches, c.max_position_error_m, c.max_force_error_n
        ));
    }
    match run.config {
        Some((ConfigSource::Defaults { .. }, ConfigSource::Stored { .. })) => {}
        Some((booted, saved)) => bad.push(format!(
            "a fresh board should boot on its defaults and save: {booted:?}, then {saved:?}"
        )),
        None => bad.push("the board never said where its configuration came from".into()),
    }
    if c.start_differs {
        bad.push(format!(
            "the board armed at tick {}, the in-process loop at another",
            run.armed_at_tick
        ));
    }
    if c.ticks != ticks {
        bad.push(format!("{} of {ticks} ticks ran", c.ticks));
    }
    if u64::from(run.board_stats.rx.dropped()) < run.corrupted_sent {
        bad.push(format!(
            "{} corrupted frames sent, the board dropped {}",
            run.corrupted_sent,
            run.board_stats.rx.dropped()
        ));
    }
    if let Some((n, err_m)) = run.homing {
        if err_m.is_nan() || err_m.abs() > HOMING_TOLERANCE_M {
            bad.push(format!(
                "homing calibrated {:.1} um off the plant (tolerance {:.0} um)",
                err_m * 1e6,
                HOMING_TOLERANCE_M * 1e6
            ));
        }
        let limit = excalibur::HOMING.force_limit_n as f64;
        let io = twoport_board::IoScale::EXCALIBUR;
        let peak = run.duties[..(n as usize + 1).min(run.duties.len())]
            .iter()
            .flat_map(|d| d.iter())
            .map(|d| io.force_n(*d).abs() as f64)
            .fold(0.0, f64::max);
        if peak > limit + 0.01 {
            bad.push(format!("homing pushed {peak:.2} N (limit {limit} N)"));
        }
    }
    if let (Some(t0), Some(z)) = (faults.link_loss_at, run.zero_after_loss_ticks) {
        let before = &run.duties[..(t0 as usize).min(run.duties.len())];
        if !before
            .iter()
            .rev()
            .take(10)
            .any(|d| d.iter().any(|d| *d != 0))
        {
            bad.push("no force before the link loss: the check would prove nothing".into());
        }
        if z > deadline_ticks {
            bad.push(format!(
                "zero force {z} ticks after the link loss (deadline {deadline_ticks})"
            ));
        }
    }
    bad
}
