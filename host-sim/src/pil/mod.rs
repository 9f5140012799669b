//! Processor-in-the-loop: host-sim's plant, hand and effects at one end, the
//! board's loop at the other, exchanging one sensor frame and one actuator
//! frame per tick over the link protocol (lockstep).
//!
//! The board end is a [`BoardPort`]: a serial port (the firmware in QEMU
//! through a pty, or a real board), or the same `twoport-board` loop
//! in-process. A run sends both ends the same bytes: heartbeats, sensor
//! frames and, if asked, corrupted frames and a link loss, so the in-process
//! run is the reference the firmware must match.

mod check;
pub mod linkage;
mod record;
pub mod teleop;

pub use check::{compare, failures, Comparison};
pub use record::Run;

use crate::engine::scene::VeSpec;
use crate::link::{BoardPort, LinkFaults, Session};
use crate::Error;
use crate::{Sample, Scene, Simulation};
use twoport_board::excalibur::{self, xyz};
use twoport_control::servo::{SensorFrame, ServoOutput};
use twoport_control::Faults as BoardFaults;
use twoport_link::{Axes, BoardMode, ConfigSource, Message, PilSensors, Status};

/// How far a homed board's position may be from the plant's: the stop's
/// give under the homing force (25 µm on the scenes' 2e5 N/m stop) and a
/// count or two.
pub const HOMING_TOLERANCE_M: f64 = 50e-6;

/// A VE on the host beside the board's servo: the scene's wall sent as a
/// surface every `every_ticks` ticks (a 1 kHz host on a 4 kHz board: 4),
/// each ramped over that many, the board faulting past `deadline_ticks`
/// on one update.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct HostVe {
    /// Ticks between the host's updates (>= 1).
    pub every_ticks: u32,
    /// The board's deadline on one update (ticks).
    pub deadline_ticks: u32,
}

impl HostVe {
    /// The scene's wall as the host's surface: where it is (pm) and which
    /// side is solid; other VEs have no surface to send.
    fn surface(scene: &Scene) -> Result<(i64, twoport_link::Contact), Error> {
        match scene.ve {
            VeSpec::Wall {
                position_m, solid, ..
            } => Ok(((position_m * 1e12).round() as i64, solid.into())),
            _ => Err(Error::Pil(
                "a host VE run sends the scene's wall: set ve.kind = \"wall\"".into(),
            )),
        }
    }
}

/// How a PIL run gets its board going.
#[derive(Clone, Copy, Debug)]
pub struct Startup {
    /// Calibrated or homed, then armed.
    pub start: Start,
    /// Where each axis stands at rest before the run, as the host tells a
    /// board it calibrates (pm).
    pub at_rest_pm: Axes<i64>,
    /// The encoder's index mark (m), if the scene's encoder has one.
    pub index_m: Option<f64>,
}

impl Startup {
    /// How `sim`'s run begins, once its scene's device is checked to be
    /// the board's (its sensors, its world): calibrated where the device
    /// starts (the 3-D world's cursor, or 0), or homed onto the scene's
    /// hard stop.
    pub fn for_sim<const N: usize>(sim: &Simulation<N>) -> Result<Startup, Error> {
        let scene = sim.scene();
        check_scene(scene)?;
        let at_rest: Vec<i64> = match sim.servo().blocks() {
            Some(w) => w.cursor.iter().map(|p| p.nm() as i64 * 1000).collect(),
            None => vec![0; N],
        };
        Ok(Startup {
            start: Start::for_scene(scene),
            at_rest_pm: Axes::from_slice(&at_rest).ok_or("a device of at most 3 axes")?,
            index_m: scene.effects.encoder.and_then(|e| e.index_m),
        })
    }
}

/// A session as a simulation's controller: the board plays its servo,
/// this process its plant.
pub trait Lockstep {
    /// One tick of `sim` with the board as its controller; returns the
    /// sample, the duties the board answered and the encoder counts it
    /// was sent.
    fn step_read<const N: usize>(
        &mut self,
        sim: &mut Simulation<N>,
    ) -> Result<(Sample<N>, Axes<i16>, [u32; N]), Error>;

    /// [`step_read`](Self::step_read) without the counts.
    fn step<const N: usize>(
        &mut self,
        sim: &mut Simulation<N>,
    ) -> Result<(Sample<N>, Axes<i16>), Error> {
        self.step_read(sim).map(|(s, d, _)| (s, d))
    }
}

impl<P: BoardPort> Lockstep for Session<P> {
    fn step_read<const N: usize>(
        &mut self,
        sim: &mut Simulation<N>,
    ) -> Result<(Sample<N>, Axes<i16>, [u32; N]), Error> {
        let tick = self.tick_heartbeat()?;
        let mut raw = [0u32; N];
        let mut answer: Result<Axes<i16>, Error> = Ok(Axes::default());
        let io = self.io;
        let mut ctl = |f: &SensorFrame<f32, N>| -> ServoOutput<f32, N> {
            raw = f.encoder_raw;
            // The encoder's index is on the first axis.
            let index = self.index_crossing(f.encoder_raw[0]);
            let sensors = PilSensors {
                tick: f.tick,
                encoder_raw: Axes::new(f.encoder_raw).unwrap_or_default(),
                load_cell_raw: Axes::new(f.load_cell_n.map(|n| io.load_cell_counts(n)))
                    .unwrap_or_default(),
                dead_man_closed: f.dead_man_closed,
                index_raw: Axes::new(core::array::from_fn::<_, N, _>(|a| {
                    index.filter(|_| a == 0)
                }))
                .unwrap_or_default(),
            };
            answer = self.exchange(tick, sensors).map_err(Error::from);
            let duty = |a: usize| answer.as_ref().ok().and_then(|d| d.get(a).copied());
            let force = core::array::from_fn(|a| io.force_n(duty(a).unwrap_or(0)));
            ServoOutput {
                actuator_force_n: force,
                commanded_force_n: force,
                ..ServoOutput::default()
            }
        };
        let sample = sim.step_external(&mut ctl);
        Ok((sample, answer?, raw))
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

/// The scene's device must be the board's: the same encoder on every
/// axis and, on three axes, the three-axis image's world, which the board
/// simulates (the scene's grab and release times cannot reach it over the
/// link).
pub fn check_scene(scene: &Scene) -> Result<(), Error> {
    let twoport_board::EncoderScale {
        bits,
        pm_per_count: pm,
    } = excalibur::ENCODER;
    match scene.effects.encoder {
        Some(e) if e.bits == bits && (e.resolution_m * 1e12).round() as i64 == pm => {}
        _ => {
            return Err(pil_err!(
                "the scene's encoder must be the board's ({bits} bits, {} um per count): \
                 set effects.encoder = {{ resolution_m = {:e}, bits = {bits} }}",
                pm as f64 * 1e-6,
                pm as f64 * 1e-12
            ))
        }
    }
    match (scene.axes, &scene.ve) {
        (1, _) => Ok(()),
        (
            3,
            VeSpec::World {
                blocks,
                grab_at_s,
                release_at_s,
                ..
            },
        ) if grab_at_s.is_empty() && release_at_s.is_empty() => {
            let want: Vec<_> = xyz::BLOCKS.to_vec();
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
                Err(pil_err!(
                    "the scene's blocks must be the three-axis image's (twoport_board::excalibur::xyz::BLOCKS): {want:?}"
                ))
            }
        }
        (3, VeSpec::World { .. }) => Err(Error::Pil(
            "a processor-in-the-loop scene cannot grab or release: the board's world runs there, \
             and the link carries no grab; remove ve.grab_at_s and ve.release_at_s"
                .into(),
        )),
        (3, _) => Err(Error::Pil(
            "the three-axis image runs the building-block world: set ve.kind = \"world\"".into(),
        )),
        (n, _) => Err(pil_err!(
            "no board image runs {n} axes (the images run 1 or 3)"
        )),
    }
}

/// How homing has ended, from the statuses a board sent: `None` while it
/// goes on, the error where it failed.
pub fn homed(statuses: &[Status]) -> Option<Result<(), Error>> {
    statuses.iter().find_map(|s| match s.mode {
        BoardMode::Homing => None,
        _ if s.faults != 0 => Some(Err(pil_err!(
            "homing ended with faults: {}",
            BoardFaults(s.faults)
        ))),
        _ if s.calibrated => Some(Ok(())),
        m => Some(Err(pil_err!("homing ended uncalibrated, in mode {m:?}"))),
    })
}

/// One tick of a run, recorded; returns the statuses the board sent.
fn record<P: BoardPort, const N: usize>(
    session: &mut Session<P>,
    sim: &mut Simulation<N>,
    r: &mut Run<N>,
) -> Result<Vec<Status>, Error> {
    record_read(session, sim, r).map(|(statuses, _)| statuses)
}

/// [`record`], with the encoder counts the board was sent.
fn record_read<P: BoardPort, const N: usize>(
    session: &mut Session<P>,
    sim: &mut Simulation<N>,
    r: &mut Run<N>,
) -> Result<(Vec<Status>, [u32; N]), Error> {
    let (s, duty, raw) = session.step_read(sim)?;
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
    Ok((statuses, raw))
}

/// Run the one-axis `scene` for `ticks` against the board at `port`: the
/// first tick disarmed, then the board calibrated (or homed, for a scene
/// with a hard stop) and armed, then the rest.
pub fn run<P: BoardPort>(
    scene: Scene,
    ticks: u64,
    port: P,
    faults: LinkFaults,
) -> Result<Run, Error> {
    run_axes(scene, ticks, port, faults)
}

/// [`run`] on a device of `N` axes: the scene's `axes` must be `N`, the
/// board's.
pub fn run_axes<P: BoardPort, const N: usize>(
    scene: Scene,
    ticks: u64,
    port: P,
    faults: LinkFaults,
) -> Result<Run<N>, Error> {
    run_with(scene, ticks, port, faults, None)
}

/// [`run_axes`], with the VE on the host where `host_ve` says: the board
/// handed the VE before it arms, then sent the scene's wall from the tick
/// it arms and every `every_ticks` after, before that tick's sensors.
pub fn run_with<P: BoardPort, const N: usize>(
    scene: Scene,
    ticks: u64,
    port: P,
    faults: LinkFaults,
    host_ve: Option<HostVe>,
) -> Result<Run<N>, Error> {
    let surface = host_ve.map(|_| HostVe::surface(&scene)).transpose()?;
    let mut sim = Simulation::<N>::with_axes(scene)?;
    let setup = Startup::for_sim(&sim)?;
    let start = setup.start;
    let mut session = Session::open_axes(port, faults, N as u8)?;
    session.set_index(setup.index_m);
    let spec = session.spec()?;
    let period = sim.scene().period();
    if (spec.period_s() - period).abs() > 1e-9 {
        return Err(pil_err!(
            "the board's servo runs every {} s and the scene's every {period} s: \
             set the scene's period_s to the board's",
            spec.period_s()
        ));
    }
    let mut r = Run {
        start: Some(start),
        spec: Some(spec),
        ..Run::default()
    };
    r.config = Some(boot_and_save(&mut session)?);
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
                    return Err(pil_err!("the board had not homed after {ticks} ticks"));
                }
            }
            r.homing = Some((r.samples.len() as u64 - 1, f64::NAN));
        }
    }
    if let Some(h) = host_ve {
        session.set_ve(twoport_link::VeSource::Host {
            ramp_ticks: h.every_ticks,
            deadline_ticks: h.deadline_ticks,
        })?;
    }
    // Armed straight after the status that allowed it, which the board
    // sends before that tick's actuator frame: the same tick on every
    // transport.
    session.arm()?;
    r.armed_at_tick = r.samples.len() as u64;
    // The host's VE: the wall sent from the armed tick on, every
    // `every_ticks`, always before a tick's sensors (so on the same tick
    // whatever the transport).
    let armed = r.armed_at_tick;
    let mut seq = 0u32;
    let mut host = |session: &mut Session<P>, at: u64| -> Result<(), Error> {
        if let (Some(h), Some((pm, contact))) = (host_ve, surface) {
            if (at - armed).is_multiple_of(u64::from(h.every_ticks.max(1))) {
                seq += 1;
                let pm = Axes::new([pm; N]).unwrap_or_default();
                let contact = Axes::new([contact; N]).unwrap_or_default();
                session.ve_update(seq, pm, contact)?;
            }
        }
        Ok(())
    };
    if let Some(spec) = sim.scene().identify {
        let period = sim.scene().period();
        let x = spec.experiment(period)?;
        let at = r.armed_at_tick + (spec.start_s / period).round() as u64;
        while (r.samples.len() as u64) < at.min(ticks) {
            host(&mut session, r.samples.len() as u64)?;
            record(&mut session, &mut sim, &mut r)?;
        }
        session.identify(x)?;
        r.experiment = Some((x, r.samples.len() as u64));
    }
    while (r.samples.len() as u64) < ticks {
        host(&mut session, r.samples.len() as u64)?;
        record(&mut session, &mut sim, &mut r)?;
    }
    r.ve_updates_sent = seq;
    if let Some((n, err)) = &mut r.homing {
        // The board's position in its first telemetry after homing
        // against the plant's where that tick read its sensors: the end of
        // the tick before.
        if let Some(t) = r.telemetry.iter().find(|t| u64::from(t.tick) > *n) {
            if let Some(s) = r.samples.get(t.tick as usize - 1) {
                *err = t.axes[0].position_pm as f64 * 1e-12 - s.handle_m[0];
            }
        }
    }
    r.board_stats = session.board_stats()?;
    r.host_dropped = session.host_dropped();
    r.corrupted_sent = session.corrupted_sent;
    r.zero_after_loss_ticks = zero_after_loss(&r.duties, faults);
    Ok(r)
}

/// The configuration a board booted with, then saved, which a PIL board
/// does while it waits for its first tick.
fn boot_and_save<P: BoardPort>(
    session: &mut Session<P>,
) -> Result<(ConfigSource, ConfigSource), Error> {
    let booted = session.config()?;
    let saved = session.save()?;
    Ok((booted, saved))
}

/// After a link loss (`faults.link_loss_at`), the ticks until the duties
/// went to zero and stayed there: the last tick with a non-zero duty after
/// the loss, plus one.
fn zero_after_loss(duties: &[Axes<i16>], faults: LinkFaults) -> Option<u64> {
    let t0 = faults.link_loss_at?;
    let last_nonzero = duties
        .iter()
        .skip(t0 as usize)
        .rposition(|d| d.iter().any(|d| *d != 0));
    Some(last_nonzero.map_or(0, |i| i as u64 + 1))
}
