//! One simulation: the plant between the hand and the board's own control
//! code, ticking at the control period, with only the named effects.

use crate::engine::effects::{Effect, Pipeline, TIMING_STRIDE};
use crate::engine::human::{GraspKind, Human};
use crate::engine::plant::{Device, Method, Stepper, System};
use crate::engine::scene::Scene;
use crate::engine::servo::{frame_f32, output_f64, SceneServo};
use crate::engine::stability::{Detector, Verdict};
use std::time::Instant;
use twoport_control::servo::{SensorFrame, ServoOutput};
use twoport_control::{Encoder, Position, SafetyConfig};

/// One tick's record.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sample {
    /// Time at the end of the tick (s).
    pub t_s: f64,
    /// Handle position (m).
    pub handle_m: f64,
    /// Handle velocity (m/s).
    pub handle_mps: f64,
    /// Human force on the handle (N).
    pub human_n: f64,
    /// Force the law commanded (N).
    pub commanded_n: f64,
    /// Force the actuator delivered (N).
    pub actuator_n: f64,
    /// VE position (m).
    pub ve_m: f64,
    /// VE force (N).
    pub ve_n: f64,
    /// Coupling force (N).
    pub coupling_n: f64,
    /// Energy the human has put in (J).
    pub energy_in_j: f64,
    /// Energy stored in the device (J); NaN unless energy tracking is on
    /// (see [`Simulation::track_energy`]).
    pub energy_stored_j: f64,
    /// The energy the passivity layer's observer has seen the element take
    /// in (J); NaN without the layer.
    pub layer_energy_j: f64,
    /// What the layer added this tick: damping (N s/m, impedance display)
    /// or conductance (m/(N s), admittance display); NaN without it.
    pub layer_added: f64,
}

/// What the passivity layer did over a run.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct PassivityReport {
    /// Energy the layer dissipated (J): its transparency cost in energy.
    pub dissipated_j: f64,
    /// Ticks on which it added damping.
    pub active_ticks: u64,
    /// The lowest energy its observer saw the element hold (J).
    pub lowest_energy_j: f64,
}

/// An effect's measured cost.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct EffectCost {
    /// Effect name.
    pub name: String,
    /// Wall time per tick it added, measured around its own code (ns).
    pub ns_per_tick: f64,
}

/// What a run found.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Report {
    /// The scene's name.
    pub scene: String,
    /// Stable by the documented criterion (see `stability`).
    pub stable: bool,
    /// Why not, when not.
    pub reason: Option<String>,
    /// Largest delivered actuator force (N).
    pub peak_force_n: f64,
    /// Work done by the human on the handle (J).
    pub energy_in_j: f64,
    /// Simulated time (s).
    pub sim_seconds: f64,
    /// Wall-clock time (s).
    pub wall_seconds: f64,
    /// Simulated over wall-clock time.
    pub realtime_factor: f64,
    /// Effects that ran and their cost.
    pub effects: Vec<EffectCost>,
    /// How the plant was advanced.
    pub integrator: String,
    /// Sub-steps per tick.
    pub substeps: u32,
    /// A predicted integrator instability, if any.
    pub integrator_warning: Option<String>,
    /// RMS oscillatory force over the final quiet second (N).
    pub late_rms_n: [f64; 2],
    /// The passivity layer's work, when the scene runs one.
    pub passivity: Option<PassivityReport>,
}

/// A coordinate read off the plant's positions or velocities, compiled
/// once: one entry when its direction is a unit vector (a handle or an
/// actuator on one coordinate, the usual case), a dot product otherwise.
#[derive(Clone, Debug)]
pub(crate) enum Pick {
    At(usize),
    Dot(Vec<f64>),
}

impl Pick {
    pub(crate) fn new(dir: &[f64]) -> Self {
        let ones: Vec<usize> = (0..dir.len()).filter(|&i| dir[i] != 0.0).collect();
        match ones[..] {
            [i] if dir[i] == 1.0 => Pick::At(i),
            _ => Pick::Dot(dir.to_vec()),
        }
    }

    pub(crate) fn of(&self, q: &[f64]) -> f64 {
        match self {
            Pick::At(i) => q[*i],
            Pick::Dot(d) => d.iter().zip(q).map(|(a, b)| a * b).sum(),
        }
    }
}

/// A simulation in progress.
pub struct Simulation {
    scene: Scene,
    period: f64,
    device: Device,
    load_cell: bool,
    steppers: Vec<(GraspKind, Stepper)>,
    method: Method,
    substeps: u32,
    /// Plant state `[q, q', w]`.
    x: Vec<f64>,
    servo: SceneServo,
    human: Human,
    tick: u64,
    total_ticks: u64,
    held_force: f64,
    encoder_mask: u32,
    counts_per_m: f64,
    /// The scene's effects, compiled.
    effects: Pipeline,
    /// Which stepper runs: the hand's grasp and its index in `steppers`.
    current: Option<(GraspKind, usize)>,
    peak_force: f64,
    energy_in: f64,
    last_power: f64,
    detector: Detector,
    failure: Option<String>,
    warning: Option<String>,
    actuator_dir: Vec<f64>,
    /// The actuator's and the handle's coordinate.
    actuator: Pick,
    handle: Pick,
    track_energy: bool,
    /// The scope's grasp, instead of the script's.
    grasp_override: Option<GraspKind>,
    /// The scope's mouse push, added to the script's (N).
    extra_push_n: f64,
    /// Ticks the passivity layer acted, and the lowest energy it saw.
    layer_active: u64,
    layer_lowest: f64,
}

/// Round half away from zero without a libm call.
pub(crate) fn round_counts(c: f64) -> i64 {
    (c + 0.5f64.copysign(c)) as i64
}

/// Largest stable sub-step for `method` over `poles` (s), by bisection.
fn max_stable_step(method: Method, poles: &[nalgebra::Complex<f64>]) -> f64 {
    poles
        .iter()
        .filter(|l| l.norm() > 0.0)
        .map(|&l| {
            let (mut lo, mut hi) = (0.0f64, 10.0 / l.norm());
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if method.stable_for(l, mid) {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            lo
        })
        .fold(f64::INFINITY, f64::min)
}

/// The warning for a sub-step `h` that `method` cannot take on `sys`.
pub fn integrator_warning(sys: &System, method: Method, h: f64) -> Option<String> {
    let poles = sys.poles();
    let bad = poles
        .iter()
        .filter(|l| !method.stable_for(**l, h))
        .map(|l| l.im.abs())
        .fold(0.0, f64::max);
    if bad == 0.0 && poles.iter().all(|l| method.stable_for(*l, h)) {
        return None;
    }
    let hmax = max_stable_step(method, &poles);
    Some(format!(
        "{} at h = {:.3e} s is unstable on the {:.0} Hz mode (needs h < {:.3e} s)",
        method.name(),
        h,
        bad / (2.0 * std::f64::consts::PI),
        hmax
    ))
}

impl Simulation {
    /// Build a simulation for `scene`.
    pub fn new(mut scene: Scene) -> Result<Self, String> {
        let device = if scene.effects.flexibility {
            let model = scene.device_model()?;
            // The model's own measurement-to-actuation delay is part of the
            // device: it runs as the delay effect, after any the scene adds.
            if model.delay_samples > 0 {
                let extra = scene.effects.delay.map_or(0, |d| d.ticks);
                scene.effects.delay = Some(crate::engine::scene::DelayEffect {
                    ticks: extra + model.delay_samples,
                });
            }
            Device::flexible(&model)?
        } else {
            Device::rigid(
                scene.plant.rigid_mass_kg,
                scene.plant.rigid_damping_nspm,
                235.0,
            )
        };
        let e = scene.effects.clone();
        let period = scene.period();
        let human =
            Human::new(scene.human.grasp, scene.human.script.clone())?.with_arm(scene.human.arm)?;
        let nonlinear = scene.nonlinear();
        let (method, substeps) = if nonlinear || scene.integrator.on_linear {
            (scene.integrator.method, scene.integrator.substeps)
        } else {
            (Method::ExactZoh, 1)
        };
        let h = period / substeps as f64;
        let mut warning = None;
        let steppers = human
            .grasps()
            .into_iter()
            .map(|g| {
                let sys = device.system(human.grasp_of(g), e.load_cell);
                warning = warning
                    .take()
                    .or_else(|| integrator_warning(&sys, method, h));
                Ok((g, Stepper::new(&sys, method, h)?))
            })
            .collect::<Result<_, String>>()?;
        let (bits, pm_per_count) = match e.encoder {
            Some(enc) => (enc.bits, (enc.resolution_m * 1e12).round()),
            // Ideal sensing: 1 nm counts, the resolution of a Position.
            None => (32, 1000.0),
        };
        let mask = if bits >= 32 {
            u32::MAX
        } else {
            (1u32 << bits) - 1
        };
        let encoder = Encoder::new(bits, pm_per_count as i64, 0, Position::ZERO)
            .map_err(|e| format!("effects.encoder: {e:?}"))?;
        let t32 = period as f32;
        let safety = SafetyConfig {
            period_s: t32,
            ..SafetyConfig::excalibur()
        };
        let servo = SceneServo::new(&scene, encoder, safety)?;
        let total_ticks = (scene.duration_s / period).round() as u64;
        let quiet_tick = ((human.last_event_end() / period).ceil() as u64).min(total_ticks);
        let ns = 2 * device.n + usize::from(e.load_cell) + if human.has_arm() { 2 } else { 0 };
        let actuator_dir = device.actuator.clone();
        // The cable between the actuator (q1) and the first link (q2) is
        // K's coupling term between them.
        let cable_k = if device.n > 1 {
            (-device.stiffness(0, 1)).max(0.0)
        } else {
            0.0
        };
        let sim = Simulation {
            period,
            load_cell: e.load_cell,
            steppers,
            method,
            substeps,
            x: vec![0.0; ns],
            servo,
            human,
            tick: 0,
            total_ticks,
            held_force: 0.0,
            encoder_mask: mask,
            counts_per_m: 1e12 / pm_per_count,
            effects: Pipeline::new(&e, cable_k),
            current: None,
            peak_force: 0.0,
            energy_in: 0.0,
            last_power: 0.0,
            detector: Detector::new(total_ticks, quiet_tick, (1.0 / period).round() as u64),
            failure: None,
            warning,
            actuator: Pick::new(&actuator_dir),
            handle: Pick::new(&device.handle),
            actuator_dir,
            track_energy: false,
            device,
            scene,
            grasp_override: None,
            extra_push_n: 0.0,
            layer_active: 0,
            layer_lowest: 0.0,
        };
        Ok(sim)
    }

    /// The time (s) at the start of `tick`. Through `i64`, whose
    /// conversion is one instruction where `u64`'s is a branchy sequence:
    /// a run never reaches 2^63 ticks, so the value is the same.
    #[inline]
    fn time_of(&self, tick: u64) -> f64 {
        tick as i64 as f64 * self.period
    }

    /// Names of the effects this scene simulates.
    pub fn effect_names(&self) -> Vec<String> {
        self.effects
            .costs
            .per_tick(1.0)
            .map(|(e, _)| e.name().to_string())
            .collect()
    }

    /// Effects are timed on one tick in [`TIMING_STRIDE`] and the time is
    /// scaled up: a clock read costs more than most effects do.
    fn timing(&self) -> bool {
        self.tick.is_multiple_of(TIMING_STRIDE)
    }

    /// Compute the device's stored energy every tick (for a passivity view;
    /// off by default, it costs about a fifth of a tick).
    pub fn track_energy(&mut self, on: bool) {
        self.track_energy = on;
    }

    /// Hold the hand in `grasp` (the scope's grasp control), or give it
    /// back to the script with `None`.
    pub fn set_grasp(&mut self, grasp: Option<GraspKind>) -> Result<(), String> {
        if let Some(g) = grasp {
            if !self.steppers.iter().any(|(k, _)| *k == g) {
                let sys = self.device.system(self.human.grasp_of(g), self.load_cell);
                let h = self.period / self.substeps as f64;
                self.steppers.push((g, Stepper::new(&sys, self.method, h)?));
            }
        }
        self.grasp_override = grasp;
        Ok(())
    }

    /// A hand force added to the script's (N): the scope's mouse push.
    pub fn set_push(&mut self, force_n: f64) {
        self.extra_push_n = if force_n.is_finite() { force_n } else { 0.0 };
    }

    /// The running servo (gains, VE).
    pub fn servo(&self) -> &SceneServo {
        &self.servo
    }

    /// The running servo, to change gains between ticks.
    pub fn servo_mut(&mut self) -> &mut SceneServo {
        &mut self.servo
    }

    /// The control period (s).
    pub fn period(&self) -> f64 {
        self.period
    }

    /// Ticks in the scene's duration.
    pub fn total_ticks(&self) -> u64 {
        self.total_ticks
    }

    /// Why the run failed so far, if it has.
    pub fn failure(&self) -> Option<&str> {
        self.failure.as_deref()
    }

    /// The plant state `[q, q', w]`.
    pub fn state(&self) -> &[f64] {
        &self.x
    }

    /// The scene this simulation runs.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// Set the plant state (tests).
    pub fn set_state(&mut self, x: &[f64]) {
        self.x.copy_from_slice(x);
    }

    fn sense(&mut self, timing: bool) -> SensorFrame<f64> {
        let n = self.device.n;
        let x_a = self.actuator.of(&self.x[..n]);
        let t0 = (timing && self.effects.encoder_timed()).then(Instant::now);
        let counts = round_counts(x_a * self.counts_per_m);
        // The counter keeps the low `bits` of the count: for a power-of-two
        // modulus that is a mask of the two's-complement value.
        let raw = (counts as u32) & self.encoder_mask;
        self.effects.costs.charge(&[Effect::Encoder], t0);
        let f_m = if self.load_cell { self.x[2 * n] } else { 0.0 };
        SensorFrame {
            tick: self.tick as u32,
            encoder_raw: [raw],
            load_cell_n: [self.effects.adc(f_m, timing)],
            dead_man_closed: true,
        }
    }

    /// Advance one control tick with the scene's own servo.
    pub fn step(&mut self) -> Sample {
        self.step_inner(None)
    }

    /// Advance one control tick with the controller outside this process
    /// (a board over a serial link, or the board loop in-process): it gets
    /// the tick's sensor frame and answers with the force to hold. Only its
    /// `actuator_force_n` drives the plant; the VE position shown is its
    /// `reference`.
    pub fn step_external(
        &mut self,
        controller: &mut dyn FnMut(&SensorFrame) -> ServoOutput,
    ) -> Sample {
        self.step_inner(Some(controller))
    }

    fn step_inner(
        &mut self,
        external: Option<&mut dyn FnMut(&SensorFrame) -> ServoOutput>,
    ) -> Sample {
        let t = self.time_of(self.tick);
        let n = self.device.n;
        let mut hand = self.human.at(t);
        if let Some(g) = self.grasp_override {
            hand.grasp = g;
        }
        hand.push_n += self.extra_push_n;
        let timing = self.timing();
        let frame = self.sense(timing);
        let frame = self.effects.delay(frame, timing);
        let is_external = external.is_some();
        let out = match external {
            Some(c) => output_f64(c(&frame_f32(&frame))),
            None => self.servo.tick(&frame),
        };
        let f_a = self.effects.saturate(out.actuator_force_n[0], timing);
        self.held_force = f_a;
        if !out.faults.is_empty() && self.failure.is_none() {
            self.failure = Some(format!("the safety layer tripped: {}", out.faults));
        }
        // Behind an arm the hand is still: only pushes reach the handle.
        let u = [
            if self.human.has_arm() {
                hand.push_n
            } else {
                hand.input_force()
            },
            f_a,
        ];
        let at = match self.current {
            Some((g, at)) if g == hand.grasp => at,
            _ => {
                let at = self
                    .steppers
                    .iter()
                    .position(|(g, _)| *g == hand.grasp)
                    .expect("a stepper for every grasp in the script");
                self.current = Some((hand.grasp, at));
                at
            }
        };
        let stepper = &mut self.steppers[at].1;
        match self.effects.forces() {
            Some((forces, costs)) => {
                let t0 = timing.then(Instant::now);
                let dir = &self.actuator_dir;
                let mut nl = |x: &[f64], f: &mut [f64]| forces.add(n, dir, x, f);
                for _ in 0..self.substeps {
                    stepper.step(&mut self.x, u, Some(&mut nl));
                }
                // On a timed tick, the sub-stepping's cost is shared among
                // the nonlinear effects that ran (they are evaluated
                // together).
                costs.charge(forces.effects(), t0);
            }
            None => {
                for _ in 0..self.substeps {
                    stepper.step(&mut self.x, u, None);
                }
            }
        }
        self.tick += 1;
        let x_h = self.handle.of(&self.x[..n]);
        let v_h = self.handle.of(&self.x[n..2 * n]);
        let f_h = match self.human.grasp_of(hand.grasp).arm {
            Some(_) => {
                let g = hand.grasp.grasp();
                let at = 2 * n + usize::from(self.load_cell);
                g.stiffness_npm * (self.x[at] - x_h)
                    + g.damping_nspm * (self.x[at + 1] - v_h)
                    + hand.push_n
            }
            None => hand.force_on(x_h, v_h),
        };
        let p = f_h * v_h;
        self.energy_in += 0.5 * (p + self.last_power) * self.period;
        self.last_power = p;
        self.peak_force = self.peak_force.max(f_a.abs());
        self.detector.push(f_a);
        let stored = if self.track_energy {
            self.device.energy(&self.x)
        } else {
            f64::NAN
        };
        if self.failure.is_none() && (!x_h.is_finite() || x_h.abs() > 10.0 || !v_h.is_finite()) {
            self.failure = Some(match &self.warning {
                Some(w) => format!("diverged: the integrator is unstable ({w})"),
                None => "diverged: the device ran 10 m away".to_string(),
            });
        }
        let (layer_energy_j, layer_added) = match self.servo.layer() {
            Some(l) if !is_external => {
                let (e, a) = (l.energy_in_j(), l.added());
                self.layer_active += u64::from(a > 0.0);
                self.layer_lowest = self.layer_lowest.min(e);
                (e, a)
            }
            _ => (f64::NAN, f64::NAN),
        };
        Sample {
            t_s: self.time_of(self.tick),
            handle_m: x_h,
            handle_mps: v_h,
            human_n: f_h,
            commanded_n: out.commanded_force_n[0],
            actuator_n: f_a,
            ve_m: if is_external {
                out.reference[0].m() as f64
            } else {
                self.servo.ve_position().m() as f64
            },
            ve_n: out.ve_force_n[0],
            coupling_n: out.coupling_force_n[0],
            energy_in_j: self.energy_in,
            energy_stored_j: stored,
            layer_energy_j,
            layer_added,
        }
    }

    /// Run to the scene's end (or the first failure), passing each sample
    /// to `sink`.
    pub fn run(&mut self, mut sink: impl FnMut(&Sample)) -> Report {
        let start = Instant::now();
        while self.tick < self.total_ticks && self.failure.is_none() {
            let s = self.step();
            sink(&s);
        }
        self.report(start.elapsed().as_secs_f64())
    }

    /// The report so far, given the wall time spent.
    pub fn report(&self, wall: f64) -> Report {
        let Verdict {
            stable,
            reason,
            late_rms_n,
        } = self.detector.verdict();
        let ticks = self.tick.max(1) as f64;
        let sim_seconds = self.tick as f64 * self.period;
        let (stable, reason) = match &self.failure {
            Some(f) => (false, Some(f.clone())),
            None => (stable, reason),
        };
        Report {
            scene: self.scene.name.clone(),
            stable,
            reason,
            peak_force_n: self.peak_force,
            energy_in_j: self.energy_in,
            sim_seconds,
            wall_seconds: wall,
            realtime_factor: if wall > 0.0 {
                sim_seconds / wall
            } else {
                f64::INFINITY
            },
            effects: self
                .effects
                .costs
                .per_tick(ticks)
                .map(|(e, ns)| EffectCost {
                    name: e.name().to_string(),
                    ns_per_tick: ns,
                })
                .collect(),
            integrator: self.method.name().to_string(),
            substeps: self.substeps,
            integrator_warning: self.warning.clone(),
            late_rms_n,
            passivity: self
                .servo
                .layer()
                .filter(|l| !l.energy_in_j().is_nan())
                .map(|l| PassivityReport {
                    dissipated_j: l.dissipated_j(),
                    active_ticks: self.layer_active,
                    lowest_energy_j: self.layer_lowest.min(0.0),
                }),
        }
    }
}
