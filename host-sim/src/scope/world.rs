//! The scope of a scene of two or three axes: its state, kept apart from
//! drawing. The
//! simulation runs in real time; the last seconds of each axis's force are
//! kept for the plots; the mouse drags the hand and the button grabs. In
//! board mode a three-axis board drives the plant (lockstep) or runs on its
//! own sensors, and its force on every axis is plotted beside the
//! simulation's.

use crate::engine::servo::WorldView;
use crate::scope::board::{BoardChoice, BoardLink, WithBoard};
use crate::scope::rings::Ring;
use crate::Error;
use crate::{Sample, Scene, Simulation};
use std::path::Path;
use twoport_control::world::vbb::Block;

/// Seconds of force history per axis.
const HISTORY_S: f64 = 5.0;

/// What the world view shows and the plots draw, for a scene of `N` axes
/// (3 by default; a two-axis scene is drawn in its x-y plane).
pub struct WorldState<const N: usize = 3> {
    sim: Simulation<N>,
    /// Each axis's actuator force over the last seconds (N).
    pub forces: [Ring; N],
    /// The last sample.
    pub last: Option<Sample<N>>,
    /// The 3-D world after the last tick (none for a VE on each axis).
    world: Option<WorldView>,
    /// Where the mouse has dragged the hand, beyond the script (m).
    pub hand_offset_m: [f64; N],
    /// Why the run stopped, if it has.
    pub stopped: Option<String>,
    /// The board, in board mode.
    pub board: Option<BoardLink>,
    /// What the board panel's connect controls hold.
    pub link: BoardChoice,
    /// Each axis's force as the board's telemetry reports it (N).
    pub board_forces: [Ring; N],
    /// The last problem to show (a refused connection, a lost link).
    pub message: Option<String>,
    /// The span each projection shows on each axis (m): the Excalibur's
    /// workspace, widened to take in a linkage's arm as it starts.
    pub span_m: [(f64, f64); 3],
    pace: crate::scope::pace::Pacer,
}

/// The Excalibur's workspace (m), the world view's span by default.
const WORKSPACE_M: [(f64, f64); 3] = [(-0.15, 0.15), (-0.15, 0.15), (0.0, 0.2)];

impl<const N: usize> WorldState<N> {
    /// The scope on a scene file of `N` axes.
    pub fn open(path: &Path) -> Result<Self, Error> {
        let scene = Scene::load(path, &[])?;
        Self::new(scene)
    }

    /// The scope on `scene`.
    pub fn new(scene: Scene) -> Result<Self, Error> {
        let n = (HISTORY_S * 1000.0) as usize;
        let sim = Simulation::with_axes(scene)?;
        let mut span_m = WORKSPACE_M;
        for p in sim.linkage_skeleton().into_iter().flatten().flatten() {
            for (a, (lo, hi)) in span_m.iter_mut().enumerate() {
                *lo = lo.min(p[a] - 0.02);
                *hi = hi.max(p[a] + 0.02);
            }
        }
        Ok(WorldState {
            span_m,
            world: sim.servo().blocks(),
            sim,
            forces: core::array::from_fn(|_| Ring::new(n)),
            last: None,
            hand_offset_m: [0.0; N],
            stopped: None,
            board: None,
            link: BoardChoice::default(),
            board_forces: core::array::from_fn(|_| Ring::new(n)),
            message: None,
            pace: Default::default(),
        })
    }

    /// The scene's name.
    pub fn name(&self) -> &str {
        &self.sim.scene().name
    }

    /// Run the simulation for `wall_s` seconds of wall time, in real time,
    /// until the scene's end; in lockstep, the board is its controller.
    pub fn advance(&mut self, wall_s: f64) {
        if let Some(b) = self.board.as_mut().filter(|b| !b.lockstep) {
            if let Err(e) = b.watch() {
                self.lost(e);
            }
        }
        for _ in 0..self.pace.due(wall_s, self.sim.period()) {
            if self.stopped.is_some() {
                break;
            }
            if self.sim.ticks() >= self.sim.total_ticks() {
                self.stopped = Some("the scene's time is up".into());
                break;
            }
            self.sim.set_hand_offset(self.hand_offset_m);
            let s = match self.board.as_mut().filter(|b| b.lockstep) {
                Some(b) => match b.step(&mut self.sim) {
                    Ok(s) => s,
                    Err(e) => {
                        self.lost(e);
                        break;
                    }
                },
                None => self.sim.step(),
            };
            for (ring, f) in self.forces.iter_mut().zip(s.actuator_n) {
                ring.push(s.t_s, f);
            }
            if s.handle_m.iter().any(|x| !x.is_finite()) {
                self.stopped = Some("the handle left the workspace".into());
            }
            self.last = Some(s);
            self.board_telemetry();
        }
        // (The blocks are copied for drawing once a frame, not each tick.)
        self.world = self.sim.servo().blocks();
    }

    /// The board's telemetry into each axis's board ring: at its own tick
    /// in lockstep, when it arrives otherwise.
    fn board_telemetry(&mut self) {
        let Some(b) = self.board.as_mut() else { return };
        for t in b.take_telemetry() {
            let ts = if b.lockstep {
                t.tick as f64 * self.sim.period()
            } else {
                self.last.map_or(0.0, |s| s.t_s)
            };
            for (ring, axis) in self.board_forces.iter_mut().zip(t.axes.iter()) {
                ring.push(ts, axis.actuator_n as f64);
            }
        }
    }

    fn lost(&mut self, why: crate::Error) {
        self.message = Some(format!("board link lost: {why}"));
        self.board = None;
    }

    /// Where the device stands at rest before a run, as a board is told
    /// when calibrated (pm): where the world's cursor starts.
    pub fn at_rest_pm(&self) -> Result<twoport_link::Axes<i64>, Error> {
        crate::pil::Startup::for_sim(&self.sim).map(|s| s.at_rest_pm)
    }

    /// Drag the hand by `d_m` (m) along each axis (x, y, z; those past
    /// the scene's axes are left out).
    pub fn drag(&mut self, d_m: [f64; 3]) {
        for (o, d) in self.hand_offset_m.iter_mut().zip(d_m) {
            *o = (*o + d).clamp(-0.2, 0.2);
        }
    }

    /// Grab the touched block, or let go of the held one.
    pub fn toggle_grab(&mut self) {
        match self.held() {
            Some(_) => self.sim.servo_mut().release(),
            None => {
                self.sim.servo_mut().grab();
            }
        }
        self.world = self.sim.servo().blocks();
    }

    /// The world's blocks (none for a constraint).
    pub fn blocks(&self) -> &[Block] {
        self.world.as_ref().map_or(&[], |w| &w.blocks)
    }

    /// A linkage scene's arm, drawn in the world's frame (m).
    pub fn arm(&self) -> Option<Vec<Vec<[f64; 3]>>> {
        self.sim.linkage_skeleton()
    }

    /// The block the cursor holds.
    pub fn held(&self) -> Option<usize> {
        self.world.as_ref().and_then(|w| w.held)
    }

    /// The cursor (m): the simulation's, or in board mode the board's
    /// (its world runs there; the link does not carry its blocks, so the
    /// blocks drawn are the scene's).
    pub fn cursor_m(&self) -> [f64; 3] {
        match self.board.as_ref().and_then(|b| b.telemetry) {
            Some(t) => core::array::from_fn(|a| {
                t.axes
                    .get(a)
                    .map_or(0.0, |x| x.ve_position_pm as f64 * 1e-12)
            }),
            None => self.last.map_or([0.0; 3], |s| {
                core::array::from_fn(|a| s.ve_m.get(a).copied().unwrap_or(0.0))
            }),
        }
    }
}

impl<const N: usize> WithBoard for WorldState<N> {
    fn board_parts(&mut self) -> (&mut Option<BoardLink>, &mut Option<String>, &Scene) {
        (&mut self.board, &mut self.message, self.sim.scene())
    }
}
