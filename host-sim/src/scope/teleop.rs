//! The scope of a teleoperation scene: its state, kept apart from
//! drawing. Both devices run in real time; the last seconds of each
//! side's position and forces are kept for the plots; the mouse pushes
//! the master's handle, as an operator's finger would.

use crate::engine::teleop::{TeleopSample, TeleopScene, Teleoperation};
use crate::scope::rings::Ring;
use crate::Error;
use std::path::Path;

/// Seconds of history per signal.
const HISTORY_S: f64 = 10.0;

/// One side's recorded signals.
pub struct SideRings {
    /// Its handle's position (m).
    pub position_m: Ring,
    /// The force its actuator delivered (N).
    pub actuator_n: Ring,
    /// The force its hand put on it (N): the operator's on the master,
    /// the environment's hand on the slave.
    pub hand_n: Ring,
}

impl SideRings {
    fn new(n: usize) -> Self {
        SideRings {
            position_m: Ring::new(n),
            actuator_n: Ring::new(n),
            hand_n: Ring::new(n),
        }
    }

    fn push(&mut self, s: &crate::Sample) {
        self.position_m.push(s.t_s, s.handle_m[0]);
        self.actuator_n.push(s.t_s, s.actuator_n[0]);
        self.hand_n.push(s.t_s, s.human_n[0]);
    }
}

/// What the teleoperation view shows and controls.
pub struct TeleopState {
    run: Teleoperation,
    /// The master's signals, then the slave's.
    pub sides: [SideRings; 2],
    /// The last sample.
    pub last: Option<TeleopSample>,
    /// Running or paused.
    pub running: bool,
    /// The mouse's push on the master's handle (N).
    pub push_n: f64,
    /// Why the run stopped, if it has.
    pub stopped: Option<String>,
    pace: crate::scope::pace::Pacer,
}

impl TeleopState {
    /// The scope on a teleoperation scene file.
    pub fn open(path: &Path) -> Result<Self, Error> {
        Self::new(TeleopScene::load(path, &[])?)
    }

    /// The scope on `scene`.
    pub fn new(scene: TeleopScene) -> Result<Self, Error> {
        let n = (HISTORY_S / scene.period()) as usize;
        Ok(TeleopState {
            run: Teleoperation::new(scene)?,
            sides: [SideRings::new(n), SideRings::new(n)],
            last: None,
            running: true,
            push_n: 0.0,
            stopped: None,
            pace: Default::default(),
        })
    }

    /// The scene running.
    pub fn scene(&self) -> &TeleopScene {
        self.run.scene()
    }

    /// Simulated time (s).
    pub fn time_s(&self) -> f64 {
        self.last.map_or(0.0, |s| s.master.t_s)
    }

    /// Push the master's handle with `force_n` (N), beside the script.
    pub fn set_push(&mut self, force_n: f64) {
        self.push_n = force_n;
        self.run.set_push(force_n);
    }

    /// Start the scene again.
    pub fn reset(&mut self) -> Result<(), Error> {
        let push = self.push_n;
        *self = TeleopState::new(self.run.scene().clone())?;
        self.set_push(push);
        Ok(())
    }

    /// Run both devices for `wall_s` seconds of wall time, in real time,
    /// until the scene's end or a failure.
    pub fn advance(&mut self, wall_s: f64) {
        if !self.running || self.stopped.is_some() {
            return;
        }
        let period = self.scene().period();
        for _ in 0..self.pace.due(wall_s, period) {
            if self.run.ticks() >= self.run.total_ticks() {
                self.stopped = Some("the scene's time is up".into());
                break;
            }
            let s = self.run.step();
            for (rings, side) in self.sides.iter_mut().zip([&s.master, &s.slave]) {
                rings.push(side);
            }
            self.last = Some(s);
            if let Some(why) = self.run.failure() {
                self.stopped = Some(why.to_string());
                break;
            }
        }
    }
}
