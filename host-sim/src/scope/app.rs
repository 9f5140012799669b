//! The scope's state, apart from any drawing: the running simulation, its
//! signals in bounded rings, the transport (play, pause, step, speed), the
//! trigger and freeze, the gains with the designer's live verdict, the hand
//! and wall controls, and the link to a board. `ui.rs` draws it.

use crate::engine::human::GraspKind;
use crate::engine::scene::{Scene, VeSpec};
use crate::scope::board::{BoardLink, WithBoard};
use crate::scope::rings::{last_trigger, Edge, Ring};
use crate::scope::signals::{BoardSignal, Signal};
use crate::Error;
use crate::{Sample, Simulation};
use std::path::{Path, PathBuf};
use std::time::Duration;
use twoport_control::servo::Gains;
use twoport_design::network::HumanBound;
use twoport_design::plot::Figure;
use twoport_design::Designer;
use twoport_link::{Axes, Message};

/// Samples each signal's ring holds: 20 s at 1 kHz.
pub const RING_SAMPLES: usize = 20_000;
/// The rings' memory bound (bytes): every signal, simulation and board.
pub const RING_BYTES: usize =
    (Signal::ALL.len() + BoardSignal::ALL.len()) * RING_SAMPLES * std::mem::size_of::<(f64, f64)>();
/// Wall time the simulation may take per frame, so the window stays live.
const FRAME_BUDGET: Duration = Duration::from_millis(25);

/// How fast simulated time runs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Speed {
    /// Simulated time follows wall time times this factor.
    Times(f64),
    /// As many ticks as the frame budget allows.
    Fastest,
}

/// The oscilloscope trigger.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Trigger {
    /// Whether sweeps start at a crossing.
    pub enabled: bool,
    /// The signal watched.
    pub signal: Signal,
    /// The level crossed (the signal's unit).
    pub level: f64,
    /// Which crossing.
    pub edge: Edge,
}

/// The designer's verdict on the gains in force.
pub struct Light {
    /// Proven absolutely stable.
    pub proven: bool,
    /// Least relative margin and where (Hz).
    pub margin: f64,
    /// Worst frequency (Hz).
    pub worst_hz: f64,
    /// How far inside the proven boundary at the same damping the gains
    /// sit: a stiffness's `1 - k/k_max`, a mass's `1 - m_min/m` (a
    /// fraction, negative past it); `None` where nothing is proven at this
    /// damping.
    pub gain_margin: Option<f64>,
    /// That boundary, as the designer publishes it (rounded to safety).
    pub boundary: Option<String>,
    /// The design bound and the coupling's response (Fig. 8 or 9).
    pub figure: Option<Figure>,
}

/// Everything the scope shows and controls.
pub struct ScopeState {
    /// Scene files found in the scenes folder.
    pub scenes: Vec<PathBuf>,
    /// The folder they were listed from.
    pub scenes_root: PathBuf,
    /// The scene running.
    pub scene_path: PathBuf,
    /// The scene's identification experiment as last played and fitted,
    /// or why it could not be.
    pub identification: Option<Result<crate::scope::identify::Identification, String>>,
    scene: Scene,
    sim: Simulation,
    /// The designer's view of the scene's device (the model file's).
    design: Option<Designer>,
    /// Running or paused.
    pub running: bool,
    /// How fast.
    pub speed: Speed,
    rings: Vec<Ring>,
    board_rings: Vec<Ring>,
    /// The visible time span (s).
    pub window_s: f64,
    /// The trigger.
    pub trigger: Trigger,
    /// A frozen copy of the rings, drawn instead of the live ones.
    frozen: Option<(Vec<Ring>, Vec<Ring>, f64)>,
    /// The gains in force.
    pub gains: Gains,
    /// The designer's verdict on them.
    pub light: Option<Light>,
    /// The grasp override (None: the scene's script).
    pub grasp: Option<GraspKind>,
    /// The mouse push (N).
    pub push_n: f64,
    /// Wall surface (m) and stiffness (N/m), when the VE is a wall.
    pub wall: Option<(f64, f64)>,
    /// The board, in board mode.
    pub board: Option<BoardLink>,
    /// The last problem to show (a refused gain, a lost link, a bad scene).
    pub message: Option<String>,
    /// Simulated seconds owed to real time (real-time speeds).
    debt_s: f64,
    last: Option<Sample>,
}

/// The scene files in `dir` and its sub-folders one level down (the
/// Table I set lives in `scenes/table1/`), sorted.
pub fn list_scenes(dir: &Path) -> Vec<PathBuf> {
    let entries = |d: &Path| -> Vec<PathBuf> {
        std::fs::read_dir(d)
            .map(|it| it.filter_map(Result::ok).map(|e| e.path()).collect())
            .unwrap_or_default()
    };
    let is_scene = |p: &PathBuf| p.extension().is_some_and(|x| x == "toml");
    let mut v: Vec<PathBuf> = Vec::new();
    for p in entries(dir) {
        if p.is_dir() {
            v.extend(entries(&p).into_iter().filter(is_scene));
        } else if is_scene(&p) {
            v.push(p);
        }
    }
    v.sort();
    v
}

impl ScopeState {
    /// The scope on `scene_path`, listing the scenes beside it.
    pub fn open(scene_path: &Path) -> Result<Self, Error> {
        let scene = Scene::load(scene_path, &[])?;
        let sim = Simulation::new(scene.clone())?;
        let dir = scene_path.parent().unwrap_or(Path::new("."));
        let mut s = ScopeState {
            scenes: list_scenes(dir),
            scenes_root: dir.to_path_buf(),
            scene_path: scene_path.to_path_buf(),
            design: designer(&scene),
            gains: scene.gains_of(0),
            wall: wall_of(&scene),
            scene,
            sim,
            running: true,
            speed: Speed::Times(1.0),
            rings: Signal::ALL
                .iter()
                .map(|_| Ring::new(RING_SAMPLES))
                .collect(),
            board_rings: BoardSignal::ALL
                .iter()
                .map(|_| Ring::new(RING_SAMPLES))
                .collect(),
            window_s: 5.0,
            trigger: Trigger {
                enabled: false,
                signal: Signal::ActuatorForce,
                level: 1.0,
                edge: Edge::Rising,
            },
            frozen: None,
            light: None,
            grasp: None,
            push_n: 0.0,
            board: None,
            message: None,
            debt_s: 0.0,
            last: None,
            identification: None,
        };
        s.sim.track_energy(true);
        s.update_light();
        Ok(s)
    }

    /// Play the scene's identification experiment and fit its record
    /// (the board's loop in-process; it takes a second or two).
    pub fn identify(&mut self) {
        self.identification = Some(crate::scope::identify::identify(&self.scene));
    }

    /// Switch to another scene (keeps the board link).
    pub fn load_scene(&mut self, path: &Path) {
        match ScopeState::open(path) {
            Ok(mut n) => {
                n.scenes = std::mem::take(&mut self.scenes);
                n.scenes_root = std::mem::take(&mut self.scenes_root);
                n.board = self.board.take();
                n.speed = self.speed;
                *self = n;
            }
            Err(e) => self.message = Some(format!("{}: {e}", path.display())),
        }
    }

    /// Start the scene again (the gains and controls stay as set).
    pub fn reset(&mut self) {
        let path = self.scene_path.clone();
        let (gains, grasp, push, wall, speed) =
            (self.gains, self.grasp, self.push_n, self.wall, self.speed);
        self.load_scene(&path);
        self.speed = speed;
        self.set_gains(gains);
        self.set_grasp(grasp);
        self.set_push(push);
        if let Some((x, k)) = wall {
            self.set_wall(x, k);
        }
    }

    /// The gains the running simulation uses.
    pub fn running_gains(&self) -> Gains {
        self.sim.servo().gains()[0]
    }

    /// The scene in force.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// Whether the scene runs a passivity layer (its plot is shown).
    pub fn has_layer(&self) -> bool {
        self.sim.servo().layer(0).is_some()
    }

    /// Simulated time (s).
    pub fn time_s(&self) -> f64 {
        self.last.map_or(0.0, |s| s.t_s)
    }

    /// The last sample.
    pub fn last(&self) -> Option<&Sample> {
        self.last.as_ref()
    }

    /// Why the simulation stopped, if it did.
    pub fn failure(&self) -> Option<&str> {
        self.sim.failure()
    }

    /// The ring of `s` (live or frozen).
    pub fn ring(&self, s: Signal) -> &Ring {
        match &self.frozen {
            Some((r, _, _)) => &r[s.index()],
            None => &self.rings[s.index()],
        }
    }

    /// The ring of a board signal (live or frozen).
    pub fn board_ring(&self, s: BoardSignal) -> &Ring {
        let i = BoardSignal::ALL.iter().position(|x| *x == s).unwrap_or(0);
        match &self.frozen {
            Some((_, r, _)) => &r[i],
            None => &self.board_rings[i],
        }
    }

    /// Whether the display is frozen.
    pub fn is_frozen(&self) -> bool {
        self.frozen.is_some()
    }

    /// Freeze the display (a copy of the rings) or let it run again.
    pub fn set_frozen(&mut self, on: bool) {
        self.frozen = on.then(|| (self.rings.clone(), self.board_rings.clone(), self.time_s()));
    }

    /// The time span to draw: the last `window_s`, or from the last
    /// trigger crossing that still has a full window after it.
    pub fn view(&self) -> (f64, f64) {
        let end = match &self.frozen {
            Some((_, _, t)) => *t,
            None => self.time_s(),
        };
        if self.trigger.enabled {
            let ring = self.ring(self.trigger.signal);
            let early = ring.iter().filter(|(t, _)| *t <= end - 0.8 * self.window_s);
            if let Some(t) = last_trigger(early, self.trigger.level, self.trigger.edge) {
                let start = (t - 0.2 * self.window_s).max(0.0);
                return (start, start + self.window_s);
            }
        }
        // From the run's start until the window fills, then scrolling.
        let start = (end - self.window_s).max(0.0);
        (start, start + self.window_s)
    }

    /// Advance by one frame of `wall_s` wall time at the set speed.
    pub fn advance(&mut self, wall_s: f64) {
        self.watch_board();
        if !self.running {
            return;
        }
        let start = std::time::Instant::now();
        let period = self.sim.period();
        let ticks = match self.speed {
            Speed::Times(f) => {
                self.debt_s = (self.debt_s + wall_s * f).min(1.0);
                (self.debt_s / period).floor() as u64
            }
            Speed::Fastest => u64::MAX,
        };
        for _ in 0..ticks {
            if !self.tick() || start.elapsed() > FRAME_BUDGET {
                break;
            }
        }
    }

    /// One tick (the step button); false if the simulation cannot go on.
    pub fn tick(&mut self) -> bool {
        if self.sim.failure().is_some() {
            self.running = false;
            return false;
        }
        let s = match self.board.as_mut().filter(|b| b.lockstep) {
            Some(b) => match b.step(&mut self.sim) {
                Ok(s) => s,
                Err(e) => {
                    self.message = Some(format!("board link lost: {e}"));
                    self.board = None;
                    self.running = false;
                    return false;
                }
            },
            None => self.sim.step(),
        };
        self.debt_s -= self.sim.period();
        for (sig, ring) in Signal::ALL.iter().zip(&mut self.rings) {
            // A scene without a passivity layer has no layer signals.
            let v = sig.of(&s, 0);
            if !v.is_nan() {
                ring.push(s.t_s, v);
            }
        }
        self.last = Some(s);
        self.board_messages();
        true
    }

    /// A free-running board: keep its link watchdog fed and read what it
    /// sent. (A lockstep board is fed and read every tick.)
    fn watch_board(&mut self) {
        let Some(b) = self.board.as_mut().filter(|b| !b.lockstep) else {
            return;
        };
        if let Err(e) = b.watch() {
            self.message = Some(format!("board link lost: {e}"));
            self.board = None;
            return;
        }
        self.board_messages();
    }

    fn board_messages(&mut self) {
        let Some(b) = self.board.as_mut() else {
            return;
        };
        for t in b.take_telemetry() {
            // Lockstep: the board's tick is the simulation's. Free running:
            // shown when it arrives.
            let ts = if b.lockstep {
                t.tick as f64 * self.sim.period()
            } else {
                self.last.map_or(0.0, |s| s.t_s)
            };
            for (sig, ring) in BoardSignal::ALL.iter().zip(&mut self.board_rings) {
                ring.push(ts, sig.of(&t));
            }
        }
    }

    /// New gains for the running simulation (and the board, which may
    /// refuse them); the light follows.
    pub fn set_gains(&mut self, g: Gains) {
        if let Err(e) = self.sim.servo_mut().set_gains([g]) {
            self.message = Some(format!("gains not applied: {e}"));
            return;
        }
        self.gains = g;
        if let Some(b) = self.board.as_mut() {
            if let Err(e) = b.tell(&Message::SetGains(Axes::one(g))) {
                self.message = Some(format!("board: {e}"));
            }
        }
        self.update_light();
    }

    fn update_light(&mut self) {
        let Some(d) = &self.design else {
            self.light = None;
            return;
        };
        let a = &d.poses()[0].analysis;
        let (report, figure) = match self.gains {
            Gains::Impedance(g) => {
                let (k, b) = (g.k_npm as f64, g.b_nspm as f64);
                (
                    d.check_impedance(k, b),
                    twoport_design::figures::fig8(a, k, b).ok(),
                )
            }
            Gains::Admittance(g) => {
                let kp = (g.kp_npm as f64, g.bp_nspm as f64);
                let (m, b) = (g.m_kg as f64, g.b_nspm as f64);
                (
                    d.check_admittance(kp, m, b),
                    twoport_design::figures::fig9(a, kp, (m, b)).ok(),
                )
            }
        };
        self.light = Some(match report {
            Ok(r) => Light {
                proven: r.check.absolutely_stable,
                margin: r.check.min_margin,
                worst_hz: r.check.worst_frequency_hz,
                gain_margin: r.gain_margin,
                boundary: r.boundary_text(),
                figure,
            },
            Err(_) => Light {
                proven: false,
                margin: f64::NEG_INFINITY,
                worst_hz: 0.0,
                gain_margin: None,
                boundary: None,
                figure,
            },
        });
    }

    /// Hold the hand in a grasp, or give it back to the script.
    pub fn set_grasp(&mut self, g: Option<GraspKind>) {
        match self.sim.set_grasp(g) {
            Ok(()) => self.grasp = g,
            Err(e) => self.message = Some(format!("grasp not changed: {e}")),
        }
    }

    /// The mouse push (N).
    pub fn set_push(&mut self, f: f64) {
        self.push_n = f;
        self.sim.set_push([f]);
    }

    /// Move the wall and set its stiffness.
    pub fn set_wall(&mut self, x_m: f64, k_npm: f64) {
        match self.sim.servo_mut().set_wall(x_m, k_npm) {
            Ok(()) => self.wall = Some((x_m, k_npm)),
            Err(e) => self.message = Some(e.to_string()),
        }
    }
}

impl WithBoard for ScopeState {
    fn board_parts(&mut self) -> (&mut Option<BoardLink>, &mut Option<String>, &Scene) {
        (&mut self.board, &mut self.message, &self.scene)
    }
}

fn wall_of(scene: &Scene) -> Option<(f64, f64)> {
    match scene.ve {
        VeSpec::Wall {
            position_m,
            stiffness_npm,
            ..
        } => Some((position_m, stiffness_npm)),
        _ => None,
    }
}

/// The designer's plant for the scene's device, at the period the
/// simulation runs.
/// The designer on the scene's device at its period, with the paper's
/// human bound; none where the model does not discretise.
fn designer(scene: &Scene) -> Option<Designer> {
    let model = scene.device_model().ok()?;
    Designer::new(vec![model], Some(scene.period()), Some(HumanBound::PAPER)).ok()
}

/// Serial ports the system lists (a pty from QEMU is not listed; type its
/// path).
pub fn list_ports() -> Vec<String> {
    serialport::available_ports()
        .map(|v| v.into_iter().map(|p| p.port_name).collect())
        .unwrap_or_default()
}
