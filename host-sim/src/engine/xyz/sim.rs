//! One three-axis simulation: a plant per axis between the hand and the
//! board's own three-axis servo, ticking at 1 kHz.

use crate::engine::human::{GraspKind, Human};
use crate::engine::plant::{Device, Method, Stepper};
use crate::engine::sim::Pick;
use crate::engine::stability::Detector;
use crate::engine::xyz::scene::{XyzScene, XyzVe, MAX_BLOCKS};
use twoport_control::servo::{ImpedanceGains, SensorFrame, Servo, ServoOutput};
use twoport_control::ve::{BilateralConstraint, Port, VeOutput, VeTransfer};
use twoport_control::world::vbb::{Block, Vbb, VbbConfig};
use twoport_control::world::{PerAxis, World};
use twoport_control::{Encoder, Position, SafetyConfig};

/// The control period (s).
const T: f64 = 1e-3;

/// The world a three-axis scene runs.
#[derive(Clone, Debug)]
pub enum XyzWorld {
    /// The building-block world (boxed: 2.6 kB of blocks).
    Blocks(Box<Vbb<f32, MAX_BLOCKS>>),
    /// A bilateral constraint on every axis.
    Bilateral(PerAxis<BilateralConstraint, 3>),
}

impl World<f32, 3> for XyzWorld {
    fn step_axes(&mut self, ports: &[Port; 3]) -> [VeOutput; 3] {
        match self {
            XyzWorld::Blocks(w) => w.step_axes(ports),
            XyzWorld::Bilateral(w) => w.step_axes(ports),
        }
    }
    fn reset_axes(&mut self, x: &[Position; 3]) {
        match self {
            XyzWorld::Blocks(w) => w.reset_axes(x),
            XyzWorld::Bilateral(w) => World::<f32, 3>::reset_axes(w, x),
        }
    }
    fn positions(&self) -> [Position; 3] {
        match self {
            XyzWorld::Blocks(w) => w.positions(),
            XyzWorld::Bilateral(w) => World::<f32, 3>::positions(w),
        }
    }
    fn offsets_m(&self, from: &[Position; 3]) -> [f32; 3] {
        match self {
            XyzWorld::Blocks(w) => w.offsets_m(from),
            XyzWorld::Bilateral(w) => w.offsets_m(from),
        }
    }
    fn axis_tf(&self, axis: usize) -> VeTransfer {
        match self {
            XyzWorld::Blocks(w) => w.axis_tf(axis),
            XyzWorld::Bilateral(w) => World::<f32, 3>::axis_tf(w, axis),
        }
    }
}

/// One tick's record.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct XyzSample {
    /// Time at the end of the tick (s).
    pub t_s: f64,
    /// Each axis's handle position (m).
    pub handle_m: [f64; 3],
    /// The force each actuator delivered (N).
    pub actuator_n: [f64; 3],
    /// The world point the couplings hold: the cursor (m).
    pub cursor_m: [f64; 3],
    /// The block the cursor holds.
    pub held: Option<usize>,
}

/// What a three-axis run found.
#[derive(Clone, Debug, serde::Serialize)]
pub struct XyzReport {
    /// The scene's name.
    pub scene: String,
    /// Stable on every axis by the one-axis criterion (see `stability`).
    pub stable: bool,
    /// Why not, when not.
    pub reason: Option<String>,
    /// Largest delivered actuator force on any axis (N).
    pub peak_force_n: f64,
    /// Simulated time (s).
    pub sim_seconds: f64,
    /// Wall-clock time (s).
    pub wall_seconds: f64,
    /// Simulated over wall-clock time.
    pub realtime_factor: f64,
    /// Each axis's RMS oscillatory force over the final quiet second (N).
    pub late_rms_n: [[f64; 2]; 3],
    /// Where the world's blocks ended (lowest corners, m).
    pub blocks_m: Vec<[f64; 3]>,
}

/// One axis's plant: a stepper for each grasp the hand takes, its state.
struct AxisPlant {
    steppers: Vec<(GraspKind, Stepper)>,
    x: Vec<f64>,
}

/// A three-axis simulation in progress.
pub struct XyzSimulation {
    scene: XyzScene,
    /// Each axis model's degrees of freedom, and where its actuator and
    /// handle are among them.
    n: usize,
    actuator: Pick,
    handle: Pick,
    plants: [AxisPlant; 3],
    /// The hand along each axis.
    humans: [Human; 3],
    /// The board's three-axis servo and its world.
    servo: Servo<XyzWorld, f32, 3>,
    /// The ticks the mouse button grabs and lets go.
    grabs: Vec<u64>,
    releases: Vec<u64>,
    detectors: [Detector; 3],
    tick: u64,
    total_ticks: u64,
    /// The scope's mouse: where it has dragged the hand, beyond the
    /// script (m).
    hand_offset_m: [f64; 3],
    failure: Option<String>,
    peak_force: f64,
}

fn world_of(ve: &XyzVe) -> Result<XyzWorld, String> {
    Ok(match ve {
        XyzVe::Bilateral => {
            XyzWorld::Bilateral(PerAxis([BilateralConstraint::new(Position::ZERO); 3]))
        }
        XyzVe::Blocks {
            blocks,
            cursor_mass_kg,
            friction,
            knobs,
            explicit,
            ..
        } => {
            let mut cfg = VbbConfig::excalibur(T as f32);
            cfg.explicit = *explicit;
            cfg.cursor_mass_kg = *cursor_mass_kg as f32;
            cfg.friction = *friction as f32;
            if !knobs {
                cfg.knobs = None;
            }
            let mut list = Vec::with_capacity(blocks.len());
            for (i, b) in blocks.iter().enumerate() {
                let f = |v: [f64; 3]| v.map(|x| x as f32);
                list.push(
                    Block::new(f(b.at_m), f(b.size_m), b.mass_kg as f32)
                        .ok_or_else(|| format!("ve.blocks[{i}]: out of the world's range"))?,
                );
            }
            XyzWorld::Blocks(Box::new(
                Vbb::new(cfg, &list).map_err(|e| format!("ve: {e}"))?,
            ))
        }
    })
}

impl XyzSimulation {
    /// Build a simulation for `scene`. The device starts at rest with its
    /// handle where the world's cursor is.
    pub fn new(scene: XyzScene) -> Result<Self, String> {
        let model = twoport_design::DeviceModel::load_or_excalibur(&scene.plant.model)
            .map_err(|e| format!("plant.model: {e}"))?;
        let device = Device::flexible(&model)?;
        let humans = scene.humans()?;
        let grasps = |h: &Human| -> Result<Vec<(GraspKind, Stepper)>, String> {
            h.grasps()
                .into_iter()
                .map(|g| {
                    let sys = device.system(h.grasp_of(g), false);
                    Ok((g, Stepper::new(&sys, Method::ExactZoh, T)?))
                })
                .collect()
        };
        let plant = |h: &Human| -> Result<AxisPlant, String> {
            Ok(AxisPlant {
                steppers: grasps(h)?,
                x: vec![0.0; 2 * device.n],
            })
        };
        let plants = [plant(&humans[0])?, plant(&humans[1])?, plant(&humans[2])?];
        let world = world_of(&scene.ve)?;
        let start = world.positions();
        // Ideal sensing: 1 nm counts on a 32-bit counter.
        let enc = Encoder::new(32, 1000, 0, Position::ZERO).map_err(|e| format!("{e:?}"))?;
        let gains = scene
            .couplings()
            .map(|c| ImpedanceGains::new(c.k.unwrap_or(0.0) as f32, c.b as f32).into());
        let mut servo = Servo::new(gains, [enc; 3], [SafetyConfig::excalibur(); 3], world)
            .map_err(|e| format!("coupling: {e}"))?;
        // The device's zero is the world's starting point.
        servo.calibrate(start);
        servo
            .enable()
            .map_err(|f| format!("the servo will not enable: {f}"))?;
        let total_ticks = (scene.duration_s / T).round() as u64;
        let last = humans.iter().map(Human::last_event_end).fold(0.0, f64::max);
        let quiet = ((last / T).ceil() as u64).min(total_ticks);
        let ticks_of = |ts: &[f64]| ts.iter().map(|t| (t / T).round() as u64).collect();
        let (grabs, releases) = match &scene.ve {
            XyzVe::Blocks {
                grab_at_s,
                release_at_s,
                ..
            } => (ticks_of(grab_at_s), ticks_of(release_at_s)),
            XyzVe::Bilateral => (Vec::new(), Vec::new()),
        };
        Ok(XyzSimulation {
            n: device.n,
            actuator: Pick::new(&device.actuator),
            handle: Pick::new(&device.handle),
            plants,
            humans,
            servo,
            tick: 0,
            total_ticks,
            grabs,
            releases,
            detectors: [0, 1, 2].map(|_| Detector::new(total_ticks, quiet, 1000)),
            failure: None,
            peak_force: 0.0,
            hand_offset_m: [0.0; 3],
            scene,
        })
    }

    /// The running servo and its world.
    pub fn servo(&self) -> &Servo<XyzWorld, f32, 3> {
        &self.servo
    }

    /// Move the hand by `offset_m` (m) beyond where the script has it:
    /// the scope's mouse dragging it. A grip is needed for it to pull.
    pub fn set_hand_offset(&mut self, offset_m: [f64; 3]) {
        if offset_m.iter().all(|x| x.is_finite()) {
            self.hand_offset_m = offset_m;
        }
    }

    /// Grab the block the cursor touches (the scope's button); whether
    /// one was there.
    pub fn grab(&mut self) -> bool {
        match self.servo.world_mut() {
            XyzWorld::Blocks(w) => w.grab(),
            XyzWorld::Bilateral(_) => false,
        }
    }

    /// Let go of the held block.
    pub fn release(&mut self) {
        if let XyzWorld::Blocks(w) = self.servo.world_mut() {
            w.release();
        }
    }

    /// Ticks run so far.
    pub fn ticks(&self) -> u64 {
        self.tick
    }

    /// Ticks in the scene's duration.
    pub fn total_ticks(&self) -> u64 {
        self.total_ticks
    }

    /// The scene.
    pub fn scene(&self) -> &XyzScene {
        &self.scene
    }

    /// Each axis's actuator position (m).
    pub fn actuator_m(&self) -> [f64; 3] {
        let n = self.n;
        [0, 1, 2].map(|a| self.actuator.of(&self.plants[a].x[..n]))
    }

    /// Advance one control tick.
    pub fn step(&mut self) -> XyzSample {
        self.step_inner(None)
    }

    /// Advance one control tick with `controller` in place of the servo
    /// (processor in the loop): it gets each axis's actuator position (m)
    /// and answers with each actuator's force (N). The scene's world does
    /// not run; the controller's does.
    pub fn step_external(&mut self, controller: &mut dyn FnMut([f64; 3]) -> [f64; 3]) -> XyzSample {
        self.step_inner(Some(controller))
    }

    fn step_inner(&mut self, external: Option<&mut dyn FnMut([f64; 3]) -> [f64; 3]>) -> XyzSample {
        let t = self.tick as f64 * T;
        let n = self.n;
        let f = match external {
            Some(c) => c(self.actuator_m()),
            None => self.servo_tick(),
        };
        // Each actuator's force, with the part of the others' that couples
        // across where the scene names it.
        let c = self.scene.plant.cross_coupling;
        let applied = if c == 0.0 {
            f
        } else {
            let total: f64 = f.iter().sum();
            f.map(|f| f + c * (total - f))
        };
        let mut handle_m = [0.0; 3];
        for a in 0..3 {
            let mut hand = self.humans[a].at(t);
            hand.position_m += self.hand_offset_m[a];
            let f_a = applied[a];
            let p = &mut self.plants[a];
            let i = p
                .steppers
                .iter()
                .position(|(g, _)| *g == hand.grasp)
                .unwrap_or(0);
            p.steppers[i]
                .1
                .step(&mut p.x, [hand.input_force(), f_a], None);
            handle_m[a] = self.handle.of(&p.x[..n]);
            self.detectors[a].push(f[a]);
            self.peak_force = self.peak_force.max(f[a].abs());
        }
        self.tick += 1;
        let (cursor, held) = match self.servo.world() {
            XyzWorld::Blocks(w) => (w.cursor(), w.held()),
            XyzWorld::Bilateral(w) => (World::<f32, 3>::positions(w), None),
        };
        XyzSample {
            t_s: self.tick as f64 * T,
            handle_m,
            actuator_n: f,
            cursor_m: cursor.map(|p| p.nm() as f64 * 1e-9),
            held,
        }
    }

    /// The board's servo's tick, in the simulation: ideal sensing.
    fn servo_tick(&mut self) -> [f64; 3] {
        let raw = self.actuator_m().map(|x| (x * 1e9).round() as i64 as u32);
        if let XyzWorld::Blocks(w) = self.servo.world_mut() {
            if self.grabs.contains(&self.tick) {
                w.grab();
            }
            if self.releases.contains(&self.tick) {
                w.release();
            }
        }
        let out: ServoOutput<f32, 3> = self.servo.tick(&SensorFrame {
            tick: self.tick as u32,
            encoder_raw: raw,
            load_cell_n: [0.0; 3],
            dead_man_closed: true,
        });
        if !out.faults.is_empty() && self.failure.is_none() {
            self.failure = Some(format!("the safety layer tripped: {}", out.faults));
        }
        out.actuator_force_n.map(f64::from)
    }

    /// Run to the end; `each` sees every sample.
    pub fn run(&mut self, mut each: impl FnMut(&XyzSample)) -> XyzReport {
        let start = std::time::Instant::now();
        while self.tick < self.total_ticks {
            let s = self.step();
            each(&s);
            if s.handle_m.iter().any(|x| !x.is_finite() || x.abs() > 1.0) {
                self.failure
                    .get_or_insert_with(|| "the handle left the workspace".into());
                break;
            }
        }
        let wall = start.elapsed().as_secs_f64();
        let verdicts = self.detectors.clone().map(|d| d.verdict());
        let unstable = verdicts.iter().position(|v| !v.stable);
        let reason = self.failure.clone().or_else(|| {
            unstable.map(|a| {
                format!(
                    "axis {a}: {}",
                    verdicts[a].reason.clone().unwrap_or_default()
                )
            })
        });
        let sim = self.tick as f64 * T;
        XyzReport {
            scene: self.scene.name.clone(),
            stable: reason.is_none(),
            reason,
            peak_force_n: self.peak_force,
            sim_seconds: sim,
            wall_seconds: wall,
            realtime_factor: if wall > 0.0 {
                sim / wall
            } else {
                f64::INFINITY
            },
            late_rms_n: verdicts.map(|v| v.late_rms_n),
            blocks_m: match self.servo.world() {
                XyzWorld::Blocks(w) => w
                    .blocks()
                    .iter()
                    .map(|b| b.min.map(|p| p.nm() as f64 * 1e-9))
                    .collect(),
                XyzWorld::Bilateral(_) => Vec::new(),
            },
        }
    }
}
