//! One simulation of a device of any number of axes: a plant per axis
//! between the hand and the board's own control code, ticking at the
//! control period, with only the named effects.

mod linkage;
mod step;

pub use step::External;

use crate::engine::effects::{Pipeline, TIMING_STRIDE};
use crate::engine::human::{GraspKind, Human};
use crate::engine::plant::{Method, SimDevice, Stepper, System};
use crate::engine::scene::Scene;
use crate::engine::servo::SceneServo;
use crate::engine::stability::Detector;
use crate::Error;
use twoport_control::{Encoder, Position, SafetyConfig};

/// One tick's record on a device of `N` axes: each per-axis field holds
/// one value per axis, x first.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample<const N: usize = 1> {
    /// Time at the end of the tick (s).
    pub t_s: f64,
    /// Handle position (m).
    pub handle_m: [f64; N],
    /// Handle velocity (m/s).
    pub handle_mps: [f64; N],
    /// Human force on the handle (N).
    pub human_n: [f64; N],
    /// Force the law commanded (N).
    pub commanded_n: [f64; N],
    /// Force the actuator delivered (N).
    pub actuator_n: [f64; N],
    /// The point the coupling holds in the VE (m).
    pub ve_m: [f64; N],
    /// VE force (N).
    pub ve_n: [f64; N],
    /// Coupling force (N).
    pub coupling_n: [f64; N],
    /// Energy the human has put in, over every axis (J).
    pub energy_in_j: f64,
    /// Energy stored in the device, over every axis (J); NaN unless
    /// energy tracking is on (see [`Simulation::track_energy`]).
    pub energy_stored_j: f64,
    /// The energy the passivity layer's observer has seen the element take
    /// in (J); NaN without the layer.
    pub layer_energy_j: [f64; N],
    /// What the layer added this tick: damping (N s/m, impedance display)
    /// or conductance (m/(N s), admittance display); NaN without it.
    pub layer_added: [f64; N],
}

impl<const N: usize> Default for Sample<N> {
    fn default() -> Self {
        Sample {
            t_s: 0.0,
            handle_m: [0.0; N],
            handle_mps: [0.0; N],
            human_n: [0.0; N],
            commanded_n: [0.0; N],
            actuator_n: [0.0; N],
            ve_m: [0.0; N],
            ve_n: [0.0; N],
            coupling_n: [0.0; N],
            energy_in_j: 0.0,
            energy_stored_j: 0.0,
            layer_energy_j: [0.0; N],
            layer_added: [0.0; N],
        }
    }
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
    /// Each axis's RMS oscillatory force over the final quiet second (N):
    /// its two estimates (see `stability`), x first.
    pub late_rms_n: Vec<[f64; 2]>,
    /// The passivity layer's work, over every axis, when the scene runs
    /// one.
    pub passivity: Option<PassivityReport>,
    /// Where the 3-D world's blocks ended (lowest corners, m); empty for
    /// any other VE.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub blocks_m: Vec<[f64; 3]>,
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

    #[inline]
    pub(crate) fn of(&self, q: &[f64]) -> f64 {
        match self {
            Pick::At(i) => q[*i],
            Pick::Dot(d) => d.iter().zip(q).map(|(a, b)| a * b).sum(),
        }
    }
}

/// One axis of a simulation: its plant's state, its hand and what is
/// booked of it.
#[derive(Clone, Debug)]
struct Axis {
    /// Plant state `[q, q', w]`.
    x: Vec<f64>,
    human: Human,
    /// Which stepper runs: the hand's grasp and its index in `steppers`.
    current: Option<(GraspKind, usize)>,
    detector: Detector,
    energy_in: f64,
    last_power: f64,
    /// The scope's mouse: a push added to the script's (N), and how far
    /// it has dragged the hand beyond the script (m).
    push_n: f64,
    offset_m: f64,
    /// Ticks the passivity layer acted, and the lowest energy it saw.
    layer_active: u64,
    layer_lowest: f64,
    /// The force the amplifier holds from the last tick until this one's
    /// latency has passed (N).
    held_n: f64,
}

/// One grasp's steppers: over the whole tick, and with a latency inside
/// the tick over its two parts (before and after the hold switches).
#[derive(Clone, Debug)]
pub(super) struct Steppers {
    pub(super) tick: Stepper,
    pub(super) split: Option<[Stepper; 2]>,
}

impl Steppers {
    /// `sys`'s steppers by `method`, `substeps` a tick of `period` (s),
    /// the hold switching `inside_s` (s) into the tick.
    fn new(
        sys: &System,
        method: Method,
        (period, substeps): (f64, u32),
        inside_s: f64,
    ) -> Result<Self, Error> {
        let n = f64::from(substeps);
        let split = if inside_s > 0.0 {
            Some([
                Stepper::new(sys, method, inside_s / n)?,
                Stepper::new(sys, method, (period - inside_s) / n)?,
            ])
        } else {
            None
        };
        Ok(Steppers {
            tick: Stepper::new(sys, method, period / n)?,
            split,
        })
    }
}

/// A simulation in progress of a device of `N` axes (1 by default): one
/// plant per axis, the same model, between a hand along each axis and the
/// board's `N`-axis servo.
pub struct Simulation<const N: usize = 1> {
    scene: Scene,
    period: f64,
    device: SimDevice,
    load_cell: bool,
    /// A stepper per grasp the hands take, shared by the axes (each has
    /// its own state).
    steppers: Vec<(GraspKind, Steppers)>,
    method: Method,
    substeps: u32,
    /// The latency inside the tick (s): the hold switches this long after
    /// the sample (0: at it).
    inside_s: f64,
    axes: [Axis; N],
    servo: SceneServo<N>,
    tick: u64,
    total_ticks: u64,
    encoder_mask: u32,
    counts_per_m: f64,
    /// The scene's effects, compiled.
    effects: Pipeline<N>,
    peak_force: f64,
    failure: Option<String>,
    warning: Option<String>,
    actuator_dir: Vec<f64>,
    /// The actuator's and the handle's coordinate.
    actuator: Pick,
    handle: Pick,
    /// The fraction of each actuator's force that pushes every other
    /// axis's actuator.
    cross_coupling: f64,
    track_energy: bool,
    /// The scope's grasp, instead of the script's.
    grasp_override: Option<GraspKind>,
    /// A linkage scene's arm, in place of the axes' models.
    linkage: Option<Box<linkage::SceneArm<N>>>,
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
    let Some(poles) = sys.poles() else {
        return Some(format!(
            "{} at h = {h:.3e} s: the plant's poles could not be found, so its stability is unknown",
            method.name()
        ));
    };
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

/// The scene's plant: its model's flexible device (whose own delay joins
/// the scene's delay effect), or the rigid reduction.
fn device_of(scene: &mut Scene) -> Result<SimDevice, Error> {
    if !scene.effects.flexibility {
        return Ok(SimDevice::rigid(
            scene.plant.rigid_mass_kg + scene.plant.handle_mass_kg,
            scene.plant.rigid_damping_nspm,
            235.0,
        ));
    }
    let model = scene.device_model()?;
    // The model's own measurement-to-actuation delay is part of the
    // device: it runs as the delay effect, after any the scene adds.
    if model.delay_samples > 0 {
        let extra = scene.effects.delay.map_or(0, |d| d.ticks);
        scene.effects.delay = Some(crate::engine::scene::DelayEffect {
            ticks: extra + model.delay_samples,
        });
    }
    // Its latency, likewise, adds to the scene's.
    if model.latency_s > 0.0 {
        let extra = scene
            .effects
            .latency
            .map_or(0.0, |l| l.seconds_at(scene.period()));
        scene.effects.latency = Some(crate::engine::scene::LatencyEffect {
            seconds: Some(extra + model.latency_s),
            periods: None,
        });
    }
    SimDevice::flexible(&model)
}

/// The scene's latency split at its period: the whole ticks join the
/// delay effect (a delay is a delay, whichever side of the controller it
/// sits), and the rest (s) is where the hold switches inside the tick.
fn split_latency(scene: &mut Scene) -> f64 {
    let period = scene.period();
    let Some(l) = scene.effects.latency else {
        return 0.0;
    };
    let lag = twoport_design::model::Lag::of(l.seconds_at(period), period);
    if lag.ticks > 0 {
        let before = scene.effects.delay.map_or(0, |d| d.ticks);
        scene.effects.delay = Some(crate::engine::scene::DelayEffect {
            ticks: before + lag.ticks,
        });
    }
    lag.fraction * period
}

/// The integrator and its sub-steps a tick: the exact hold on a linear
/// plant unless the scene asks otherwise; on a linkage's arm, which is
/// nonlinear, fourth-order Runge-Kutta with at least 4 sub-steps.
fn integrator_of(scene: &Scene, nonlinear: bool) -> (Method, u32) {
    if scene.plant.linkage.is_some() {
        (Method::Rk4, scene.integrator.substeps.max(4))
    } else if nonlinear || scene.integrator.on_linear {
        (scene.integrator.method, scene.integrator.substeps)
    } else {
        (Method::ExactZoh, 1)
    }
}

/// The board's encoder for the scene's effects, the mask of its count
/// and its picometres per count: ideal sensing counts 1 nm, the
/// resolution of a Position.
pub(crate) fn encoder_of(e: &crate::engine::scene::Effects) -> Result<(Encoder, u32, f64), Error> {
    let (bits, pm_per_count) = match e.encoder {
        Some(enc) => (enc.bits, (enc.resolution_m * 1e12).round()),
        None => (32, 1000.0),
    };
    let mask = if bits >= 32 {
        u32::MAX
    } else {
        (1u32 << bits) - 1
    };
    let encoder = Encoder::new(bits, pm_per_count as i64, 0, Position::ZERO)
        .map_err(|e| format!("effects.encoder: {e:?}"))?;
    Ok((encoder, mask, pm_per_count))
}

impl Simulation {
    /// Build a simulation for a one-axis `scene`.
    pub fn new(scene: Scene) -> Result<Self, Error> {
        Self::with_axes(scene)
    }
}

impl<const N: usize> Simulation<N> {
    /// Build a simulation for `scene`, whose `axes` must be `N`.
    pub fn with_axes(mut scene: Scene) -> Result<Self, Error> {
        if scene.axis_count() != N {
            return Err(sim_err!(
                "axes = {}: this simulation runs a device of {N}",
                scene.axes
            ));
        }
        let device = device_of(&mut scene)?;
        let period = scene.period();
        let inside_s = split_latency(&mut scene);
        let e = scene.effects.clone();
        let humans = scene.humans()?;
        let nonlinear = scene.nonlinear();
        let (method, substeps) = integrator_of(&scene, nonlinear);
        let h = period / substeps as f64;
        let mut warning = None;
        // Every axis's hand has the same grips (they come from one script).
        let steppers = humans[0]
            .grasps()
            .into_iter()
            .map(|g| {
                let sys = device.system(humans[0].grasp_of(g), e.load_cell);
                warning = warning
                    .take()
                    .or_else(|| integrator_warning(&sys, method, h));
                Ok((
                    g,
                    Steppers::new(&sys, method, (period, substeps), inside_s)?,
                ))
            })
            .collect::<Result<_, Error>>()?;
        let (encoder, mask, pm_per_count) = encoder_of(&e)?;
        let t32 = period as f32;
        let safety = SafetyConfig {
            period_s: t32,
            ..SafetyConfig::excalibur()
        };
        let (servo, linkage) = match &scene.plant.linkage {
            Some(path) => {
                let file = twoport_design::linkage::LinkageFile::load(path)
                    .map_err(|e| sim_err!("plant.linkage: {e}"))?;
                let arm = linkage::SceneArm::at_rest(&scene, &file)?;
                let servo = SceneServo::linkage(&scene, &arm, safety)?;
                let start: Vec<f64> = servo.ve_position().iter().map(|p| p.m() as f64).collect();
                (servo, Some(Box::new(linkage::SceneArm::new(arm, &start)?)))
            }
            None => (SceneServo::new(&scene, encoder, safety)?, None),
        };
        let total_ticks = (scene.duration_s / period).round() as u64;
        let last_event = humans.iter().map(Human::last_event_end).fold(0.0, f64::max);
        let quiet_tick = ((last_event / period).ceil() as u64).min(total_ticks);
        let ns = 2 * device.n + usize::from(e.load_cell) + if humans[0].has_arm() { 2 } else { 0 };
        let per_second = (1.0 / period).round() as u64;
        let axes: Vec<Axis> = humans
            .into_iter()
            .map(|human| Axis {
                x: vec![0.0; ns],
                human,
                current: None,
                detector: Detector::new(total_ticks, quiet_tick, per_second),
                energy_in: 0.0,
                last_power: 0.0,
                push_n: 0.0,
                offset_m: 0.0,
                layer_active: 0,
                layer_lowest: 0.0,
                held_n: 0.0,
            })
            .collect();
        let actuator_dir = device.actuator.clone();
        // The cable between the actuator (q1) and the first link (q2) is
        // K's coupling term between them.
        let cable_k = if device.n > 1 {
            (-device.stiffness(0, 1)).max(0.0)
        } else {
            0.0
        };
        Ok(Simulation {
            period,
            load_cell: e.load_cell,
            steppers,
            method,
            substeps,
            inside_s,
            axes: axes
                .try_into()
                .map_err(|_| "one hand per axis".to_string())?,
            servo,
            tick: 0,
            total_ticks,
            encoder_mask: mask,
            counts_per_m: 1e12 / pm_per_count,
            effects: Pipeline::new(&e, cable_k),
            peak_force: 0.0,
            failure: None,
            warning,
            actuator: Pick::new(&actuator_dir),
            handle: Pick::new(&device.handle),
            actuator_dir,
            cross_coupling: scene.plant.cross_coupling,
            track_energy: false,
            device,
            scene,
            grasp_override: None,
            linkage,
        })
    }

    /// The time (s) at the start of `tick`. Through `i64`, whose
    /// conversion is one instruction where `u64`'s is a branchy sequence:
    /// a run never reaches 2^63 ticks, so the value is the same.
    #[inline]
    fn time_of(&self, tick: u64) -> f64 {
        tick as i64 as f64 * self.period
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
    pub fn set_grasp(&mut self, grasp: Option<GraspKind>) -> Result<(), Error> {
        if let Some(g) = grasp {
            if !self.steppers.iter().any(|(k, _)| *k == g) {
                let grasp = self.axes[0].human.grasp_of(g);
                let sys = self.device.system(grasp, self.load_cell);
                let tick = (self.period, self.substeps);
                let steppers = Steppers::new(&sys, self.method, tick, self.inside_s)?;
                self.steppers.push((g, steppers));
            }
        }
        self.grasp_override = grasp;
        Ok(())
    }

    /// A hand force on each axis added to the script's (N): the scope's
    /// mouse push.
    pub fn set_push(&mut self, force_n: [f64; N]) {
        for (a, f) in self.axes.iter_mut().zip(force_n) {
            a.push_n = if f.is_finite() { f } else { 0.0 };
        }
    }

    /// Move the hand by `offset_m` (m) beyond where the script has it:
    /// the scope's mouse dragging it. A grip is needed for it to pull.
    pub fn set_hand_offset(&mut self, offset_m: [f64; N]) {
        if offset_m.iter().all(|x| x.is_finite()) {
            for (a, x) in self.axes.iter_mut().zip(offset_m) {
                a.offset_m = x;
            }
        }
    }

    /// The running servo (gains, VE).
    pub fn servo(&self) -> &SceneServo<N> {
        &self.servo
    }

    /// The running servo, to change gains between ticks.
    pub fn servo_mut(&mut self) -> &mut SceneServo<N> {
        &mut self.servo
    }

    /// The control period (s).
    pub fn period(&self) -> f64 {
        self.period
    }

    /// Ticks run so far.
    pub fn ticks(&self) -> u64 {
        self.tick
    }

    /// Ticks in the scene's duration.
    pub fn total_ticks(&self) -> u64 {
        self.total_ticks
    }

    /// Why the run failed so far, if it has.
    pub fn failure(&self) -> Option<&str> {
        self.failure.as_deref()
    }

    /// Axis `axis`'s plant state `[q, q', w]` (empty past the last axis).
    pub fn state(&self, axis: usize) -> &[f64] {
        self.axes.get(axis).map_or(&[], |a| &a.x)
    }

    /// The scene this simulation runs.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }
}
