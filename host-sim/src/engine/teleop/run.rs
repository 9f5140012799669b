//! A teleoperation run: both devices ticked together, each with its own
//! plant, hand and effects, their sensor frames through the control
//! crate's teleoperator.

use super::link::Link;
use super::scene::TeleopScene;
use crate::engine::sim::{encoder_of, Report, Sample, Simulation};
use crate::Error;
use std::time::Instant;
use twoport_control::passivity::PassivityLimits;
use twoport_control::servo::{SensorFrame, ServoOutput};
use twoport_control::teleop::{ChannelGuard, FourChannel, Motion, TeleopStep, WaveVariables};
use twoport_control::{Encoder, Position};
use twoport_design::verify::{TeleopLaw, MAX_DELAY_TICKS};

/// One tick of both devices.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TeleopSample {
    /// The master's tick; its `human_n` is the operator's force.
    pub master: Sample,
    /// The slave's tick; its `human_n` is the environment's force.
    pub slave: Sample,
    /// The damping each port's guard added this tick (N s/m), master
    /// first; 0 without a guard.
    pub guard_nspm: [f64; 2],
}

/// What a teleoperation run found.
#[derive(Clone, Debug, serde::Serialize)]
pub struct TeleopReport {
    /// The scene's name.
    pub scene: String,
    /// Both sides stable by the simulator's criterion.
    pub stable: bool,
    /// Why not, when not (the side named).
    pub reason: Option<String>,
    /// The RMS of the master's position less the slave's over the run
    /// (m): how well the slave tracked.
    pub tracking_rms_m: f64,
    /// The largest such difference over the run's last second (m).
    pub late_error_m: f64,
    /// The master's own report.
    pub master: Report,
    /// The slave's.
    pub slave: Report,
}

/// A side's sensing, as the board reads it: the encoder unwrapped, the
/// velocity its backward difference (the law's z-form assumes it), the
/// load cell's force.
#[derive(Clone, Debug)]
struct Sensing {
    encoder: Encoder,
    last: Position,
    period_s: f32,
}

impl Sensing {
    fn new(side: &crate::Scene) -> Result<Self, Error> {
        let (encoder, _, _) = encoder_of(&side.effects)?;
        Ok(Sensing {
            encoder,
            last: Position::ZERO,
            period_s: side.period() as f32,
        })
    }

    /// The tick's motion and load-cell force (N), or why the encoder
    /// cannot be read.
    fn read(&mut self, frame: &SensorFrame<f32, 1>) -> Result<(Motion<f32>, f32), String> {
        let x = self
            .encoder
            .update(frame.encoder_raw[0])
            .map_err(|e| format!("{e:?}"))?;
        let v = x.nm_from::<f32>(self.last) * 1e-9 / self.period_s;
        self.last = x;
        Ok(((x, v), frame.load_cell_n[0]))
    }
}

/// What one side sends the other: its motion, its sensed force (N) and
/// the energy its port has put in (J, for the other side's guard).
type Packet = (Motion<f32>, f32, f32);

/// Lawrence's four channels across a network: the links each way, and
/// each port's guard if the scene asks.
struct Network {
    /// The law, its own channel unused: the network hands over what
    /// arrives.
    law: FourChannel<f32, 1>,
    links: [Link<Packet>; 2],
    guards: Option<[ChannelGuard<f32>; 2]>,
}

/// The teleoperator as it runs.
enum Law {
    /// Lawrence's four channels across the law's own constant channel:
    /// the law the proof analyses.
    Constant(Box<FourChannel<f32, MAX_DELAY_TICKS>>),
    /// The same law across a network that jitters and drops, each port
    /// guarded if the scene asks.
    Network(Box<Network>),
    /// The wave-variable channel.
    Wave(Box<WaveVariables<f32, MAX_DELAY_TICKS>>),
}

impl Law {
    fn new(scene: &TeleopScene) -> Result<Self, Error> {
        let (t, c) = (scene.period() as f32, &scene.channel);
        let bad = |e: twoport_control::ParamError| sim_err!("law: {e}");
        Ok(match scene.law {
            TeleopLaw::FourChannel(g) if c.is_constant() => Law::Constant(Box::new(
                FourChannel::new(g, t, c.delay_ticks, Position::ZERO).map_err(bad)?,
            )),
            TeleopLaw::FourChannel(g) => {
                let still: Packet = ((Position::ZERO, 0.0), 0.0, 0.0);
                let link =
                    |seed| Link::new(c.delay_ticks, c.jitter_ticks, c.drop_fraction, seed, still);
                let guards = match c.guard {
                    Some(g) => {
                        let limits = PassivityLimits::for_device(
                            g.mass_kg as f32,
                            t,
                            g.force_limit_n as f32,
                        )
                        .map_err(|e| sim_err!("channel.guard: {e}"))?;
                        let one = ChannelGuard::new(limits)
                            .map_err(|e| sim_err!("channel.guard: {e}"))?;
                        Some([one, one])
                    }
                    None => None,
                };
                Law::Network(Box::new(Network {
                    law: FourChannel::new(g, t, 0, Position::ZERO).map_err(bad)?,
                    links: [link(c.seed), link(c.seed.wrapping_mul(0x9e37_79b9).max(1))],
                    guards,
                }))
            }
            TeleopLaw::Wave(w) => Law::Wave(Box::new(
                WaveVariables::new(w.b_nspm, c.delay_ticks)
                    .and_then(|l| l.with_wave_filter(w.filter_pole))
                    .map_err(bad)?,
            )),
        })
    }

    /// The tick's forces from each side's motion and sensed force, and
    /// each guard's damping (N s/m).
    fn step(
        &mut self,
        tick: u64,
        (master, f_h): (Motion<f32>, f32),
        (slave, f_e): (Motion<f32>, f32),
    ) -> (TeleopStep<f32>, [f32; 2]) {
        match self {
            Law::Constant(law) => (law.step(master, slave, f_h, f_e), [0.0; 2]),
            Law::Wave(law) => (law.step(master.1, slave.1), [0.0; 2]),
            Law::Network(n) => {
                let Network { law, links, guards } = &mut **n;
                let energy = |i: usize| guards.as_ref().map_or(0.0, |g| g[i].energy_in_j());
                let at_slave = links[0].pass(tick, (master, f_h, energy(0)));
                let at_master = links[1].pass(tick, (slave, f_e, energy(1)));
                let f = law.forces(
                    master,
                    slave,
                    f_h,
                    f_e,
                    (at_master.0, at_master.1),
                    (at_slave.0, at_slave.1),
                );
                match guards {
                    None => (f, [0.0; 2]),
                    Some([gm, gs]) => {
                        let step = TeleopStep {
                            master_n: gm.step(master.0, master.1, f.master_n, at_master.2),
                            slave_n: gs.step(slave.0, slave.1, f.slave_n, at_slave.2),
                        };
                        (step, [gm.damping_nspm(), gs.damping_nspm()])
                    }
                }
            }
        }
    }
}

/// A teleoperation in progress: master and slave, each a one-axis
/// [`Simulation`] stepped by the teleoperator in place of its servo.
pub struct Teleoperation {
    scene: TeleopScene,
    sides: [Simulation; 2],
    sensing: [Sensing; 2],
    law: Law,
    tick: u64,
    failure: Option<String>,
    /// The run's tracking error: its sum of squares (m²), and its peak
    /// (m) from `late_from`, the first tick of the run's last second.
    error_sq: f64,
    late_error_m: f64,
    late_from: u64,
}

impl Teleoperation {
    /// Build the run of `scene`.
    pub fn new(scene: TeleopScene) -> Result<Self, Error> {
        let build = |name: &str, side| {
            let s = scene.side(side, name);
            let sensing = Sensing::new(&s)?;
            Ok::<_, Error>((Simulation::new(s)?, sensing))
        };
        let (m, m_sense) = build("master", &scene.master)?;
        let (s, s_sense) = build("slave", &scene.slave)?;
        let per_second = (1.0 / scene.period()).round() as u64;
        Ok(Teleoperation {
            late_from: m.total_ticks().saturating_sub(per_second),
            law: Law::new(&scene)?,
            scene,
            sides: [m, s],
            sensing: [m_sense, s_sense],
            tick: 0,
            failure: None,
            error_sq: 0.0,
            late_error_m: 0.0,
        })
    }

    /// The scene this run is of.
    pub fn scene(&self) -> &TeleopScene {
        &self.scene
    }

    /// Ticks run so far.
    pub fn ticks(&self) -> u64 {
        self.tick
    }

    /// Ticks in the scene's duration.
    pub fn total_ticks(&self) -> u64 {
        self.sides[0].total_ticks()
    }

    /// Push the master's handle with `force_n` (N) beside its script
    /// (the scope's mouse).
    pub fn set_push(&mut self, force_n: f64) {
        self.sides[0].set_push([force_n]);
    }

    /// Why the run failed so far, if it has.
    pub fn failure(&self) -> Option<&str> {
        self.failure
            .as_deref()
            .or_else(|| self.sides[0].failure())
            .or_else(|| self.sides[1].failure())
    }

    /// Advance both devices one tick. A sensor the law cannot read stops
    /// the force on both (and the run, as a failure).
    pub fn step(&mut self) -> TeleopSample {
        let tick = self.tick;
        let [master, slave] = &mut self.sides;
        let (law, sensing, failure) = (&mut self.law, &mut self.sensing, &mut self.failure);
        let mut slave_sample = Sample::default();
        let mut guard_nspm = [0.0f32; 2];
        let master_sample = master.step_external(&mut |at_master| {
            let mut to_master = ServoOutput::default();
            slave_sample = slave.step_external(&mut |at_slave| {
                let [m, l] = &mut *sensing;
                let read = m
                    .read(at_master)
                    .map_err(|e| format!("the master's encoder: {e}"))
                    .and_then(|m| {
                        l.read(at_slave)
                            .map(|l| (m, l))
                            .map_err(|e| format!("the slave's encoder: {e}"))
                    });
                let f = match (read, failure.is_some()) {
                    (Ok((m, l)), false) => {
                        let (f, g) = law.step(tick, m, l);
                        guard_nspm = g;
                        f
                    }
                    (Err(why), false) => {
                        *failure = Some(why);
                        TeleopStep::default()
                    }
                    (_, true) => TeleopStep::default(),
                };
                to_master = holding(f.master_n, sensing[0].last);
                holding(f.slave_n, sensing[1].last)
            });
            to_master
        });
        self.tick += 1;
        let e = master_sample.handle_m[0] - slave_sample.handle_m[0];
        self.error_sq += e * e;
        if self.tick > self.late_from {
            self.late_error_m = self.late_error_m.max(e.abs());
        }
        TeleopSample {
            master: master_sample,
            slave: slave_sample,
            guard_nspm: guard_nspm.map(f64::from),
        }
    }

    /// Run to the scene's end (or the first failure), passing each sample
    /// to `sink`.
    pub fn run(&mut self, mut sink: impl FnMut(&TeleopSample)) -> TeleopReport {
        let start = Instant::now();
        while self.tick < self.total_ticks() && self.failure().is_none() {
            let s = self.step();
            sink(&s);
        }
        self.report(start.elapsed().as_secs_f64())
    }

    /// The report so far, given the wall time spent.
    pub fn report(&self, wall_s: f64) -> TeleopReport {
        let [master, slave] = [0, 1].map(|i| self.sides[i].report(wall_s));
        let reason = self
            .failure
            .clone()
            .or_else(|| master.reason.as_ref().map(|r| format!("master: {r}")))
            .or_else(|| slave.reason.as_ref().map(|r| format!("slave: {r}")));
        TeleopReport {
            scene: self.scene.name.clone(),
            stable: reason.is_none(),
            reason,
            tracking_rms_m: (self.error_sq / self.tick.max(1) as f64).sqrt(),
            late_error_m: self.late_error_m,
            master,
            slave,
        }
    }
}

/// The output that holds `force_n` (N) on a device read at `at`.
fn holding(force_n: f32, at: Position) -> ServoOutput<f32, 1> {
    ServoOutput {
        actuator_force_n: [force_n],
        commanded_force_n: [force_n],
        ..ServoOutput::at_rest([at], [0.0])
    }
}
