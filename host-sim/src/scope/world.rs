//! The scope of a three-axis scene: its state, kept apart from drawing. The
//! simulation runs in real time; the last seconds of each axis's force are
//! kept for the plots; the mouse drags the hand and the button grabs.

use crate::engine::servo::WorldView;
use crate::scope::rings::Ring;
use crate::{Sample, Scene, Simulation};
use std::path::Path;
use twoport_control::world::vbb::Block;

/// Seconds of force history per axis.
const HISTORY_S: f64 = 5.0;

/// What the world view shows and the plots draw.
pub struct WorldState {
    sim: Simulation<3>,
    /// Each axis's actuator force over the last seconds (N).
    pub forces: [Ring; 3],
    /// The last sample.
    pub last: Option<Sample<3>>,
    /// The 3-D world after the last tick (none for a VE on each axis).
    world: Option<WorldView>,
    /// Where the mouse has dragged the hand, beyond the script (m).
    pub hand_offset_m: [f64; 3],
    /// Why the run stopped, if it has.
    pub stopped: Option<String>,
    debt_s: f64,
}

impl WorldState {
    /// The scope on a three-axis scene file.
    pub fn open(path: &Path) -> Result<Self, String> {
        let scene = Scene::load(path, &[]).map_err(|e| e.to_string())?;
        Self::new(scene)
    }

    /// The scope on `scene`.
    pub fn new(scene: Scene) -> Result<Self, String> {
        let n = (HISTORY_S * 1000.0) as usize;
        let sim = Simulation::with_axes(scene)?;
        Ok(WorldState {
            world: sim.servo().blocks(),
            sim,
            forces: [Ring::new(n), Ring::new(n), Ring::new(n)],
            last: None,
            hand_offset_m: [0.0; 3],
            stopped: None,
            debt_s: 0.0,
        })
    }

    /// The scene's name.
    pub fn name(&self) -> &str {
        &self.sim.scene().name
    }

    /// Run the simulation for `wall_s` seconds of wall time, in real time,
    /// until the scene's end.
    pub fn advance(&mut self, wall_s: f64) {
        self.debt_s = (self.debt_s + wall_s).min(0.2);
        while self.debt_s >= 1e-3 && self.stopped.is_none() {
            self.debt_s -= 1e-3;
            if self.sim.ticks() >= self.sim.total_ticks() {
                self.stopped = Some("the scene's time is up".into());
                break;
            }
            self.sim.set_hand_offset(self.hand_offset_m);
            let s = self.sim.step();
            for (ring, f) in self.forces.iter_mut().zip(s.actuator_n) {
                ring.push(s.t_s, f);
            }
            if s.handle_m.iter().any(|x| !x.is_finite()) {
                self.stopped = Some("the handle left the workspace".into());
            }
            self.last = Some(s);
            self.world = self.sim.servo().blocks();
        }
    }

    /// Drag the hand by `d_m` (m) along each axis.
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

    /// The block the cursor holds.
    pub fn held(&self) -> Option<usize> {
        self.world.as_ref().and_then(|w| w.held)
    }

    /// The cursor (m).
    pub fn cursor_m(&self) -> [f64; 3] {
        self.last.map_or([0.0; 3], |s| s.ve_m)
    }
}
