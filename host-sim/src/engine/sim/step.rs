//! One control tick of a simulation, a whole run, and its report.

use super::{round_counts, EffectCost, PassivityReport, Report, Sample, Simulation};
use crate::engine::effects::Effect;
use crate::engine::human::HandState;
use crate::engine::plant::Stepper;
use crate::engine::servo::{frame_f32, output_f64};
use crate::engine::stability::StabilityVerdict;
use std::time::Instant;
use twoport_control::servo::{SensorFrame, ServoOutput};

/// A controller outside the simulation: the tick's sensor frame in, the
/// forces to hold out (see [`Simulation::step_external`]).
pub type External<'a, const N: usize> =
    &'a mut dyn FnMut(&SensorFrame<f32, N>) -> ServoOutput<f32, N>;

impl<const N: usize> Simulation<N> {
    fn sense(&mut self, timing: bool) -> SensorFrame<f64, N> {
        let n = self.device.n;
        let t0 = (timing && self.effects.encoder_timed()).then(Instant::now);
        let raw = core::array::from_fn(|a| {
            let x_a = self.actuator.of(&self.axes[a].x[..n]);
            let counts = round_counts(x_a * self.counts_per_m);
            // The counter keeps the low `bits` of the count: for a
            // power-of-two modulus that is a mask of the two's-complement
            // value.
            (counts as u32) & self.encoder_mask
        });
        self.effects.costs.charge(&[Effect::Encoder], t0);
        let load_cell_n = core::array::from_fn(|a| {
            let f_m = if self.load_cell {
                self.axes[a].x[2 * n]
            } else {
                0.0
            };
            self.effects.adc(a, f_m, timing)
        });
        SensorFrame {
            tick: self.tick as u32,
            encoder_raw: raw,
            load_cell_n,
            dead_man_closed: true,
        }
    }

    /// Advance one control tick with the scene's own servo.
    pub fn step(&mut self) -> Sample<N> {
        self.step_inner(None)
    }

    /// Advance one control tick with the controller outside this process
    /// (a board over a serial link, or the board loop in-process): it gets
    /// the tick's sensor frame as the board reads it and answers with the
    /// forces to hold. Only its `actuator_force_n` drives the plant; the
    /// VE position shown is its `reference`.
    pub fn step_external(&mut self, controller: External<'_, N>) -> Sample<N> {
        self.step_inner(Some(controller))
    }

    fn step_inner(&mut self, external: Option<External<'_, N>>) -> Sample<N> {
        if self.linkage.is_some() && external.is_none() {
            return self.step_linkage();
        }
        let t = self.time_of(self.tick);
        let timing = self.timing();
        let frame = self.sense(timing);
        let frame = self.effects.delay(frame, timing);
        let is_external = external.is_some();
        let out = match external {
            Some(c) => output_f64(c(&frame_f32(&frame))),
            None => self.servo.tick(&frame),
        };
        let delivered: [f64; N] =
            core::array::from_fn(|a| self.effects.saturate(out.actuator_force_n[a], timing));
        if !out.faults.is_empty() && self.failure.is_none() {
            self.failure = Some(format!("the safety layer tripped: {}", out.faults));
        }
        // Each actuator's force, with the part of the others' that couples
        // across where the scene names it.
        let applied = match self.cross_coupling {
            0.0 => delivered,
            c => {
                let total: f64 = delivered.iter().sum();
                delivered.map(|f| f + c * (total - f))
            }
        };
        let mut s = Sample::<N>::default();
        let t0 = timing.then(Instant::now);
        for i in 0..N {
            let hand = self.hand_of(i, t);
            self.integrate(i, &hand, applied[i], timing);
            let (x_h, v_h, f_h) = self.at_handle(i, &hand);
            self.account(i, (x_h, v_h, f_h), delivered[i]);
            let axis = &self.axes[i];
            (s.handle_m[i], s.handle_mps[i], s.human_n[i]) = (x_h, v_h, f_h);
            s.energy_in_j += axis.energy_in;
            if self.track_energy {
                s.energy_stored_j += self.device.energy(&axis.x);
            }
            (s.layer_energy_j[i], s.layer_added[i]) = match self.servo.layer(i) {
                Some(l) if !is_external => {
                    // (The scene has a layer: the common case has none.)
                    let (e, a) = (l.energy_in_j(), l.added());
                    let axis = &mut self.axes[i];
                    axis.layer_active += u64::from(a > 0.0);
                    axis.layer_lowest = axis.layer_lowest.min(e);
                    (e, a)
                }
                _ => (f64::NAN, f64::NAN),
            };
        }
        // On a timed tick, the sub-stepping's cost is shared among the
        // nonlinear effects that ran (they are evaluated together).
        if let Some((forces, costs)) = self.effects.forces() {
            costs.charge(forces.effects(), t0);
        }
        self.tick += 1;
        if !self.track_energy {
            s.energy_stored_j = f64::NAN;
        }
        let ve_m = if is_external {
            out.reference
        } else {
            self.servo.ve_position()
        };
        s.t_s = self.time_of(self.tick);
        s.commanded_n = out.commanded_force_n;
        s.actuator_n = delivered;
        s.ve_m = ve_m.map(|p| p.m() as f64);
        s.ve_n = out.ve_force_n;
        s.coupling_n = out.coupling_force_n;
        s
    }

    /// Axis `i`'s hand at `t`: the script's, with the scope's grasp, push
    /// and drag on it.
    fn hand_of(&self, i: usize, t: f64) -> HandState {
        let axis = &self.axes[i];
        let mut hand = axis.human.at(t);
        if let Some(g) = self.grasp_override {
            hand.grasp = g;
        }
        hand.push_n += axis.push_n;
        hand.position_m += axis.offset_m;
        hand
    }

    /// Axis `i`'s plant through one tick, pushed by `hand` and the
    /// actuator's `force_n`, on the stepper of the hand's grasp.
    fn integrate(&mut self, i: usize, hand: &HandState, force_n: f64, timing: bool) {
        let n = self.device.n;
        let axis = &mut self.axes[i];
        // Behind an arm the hand is still: only pushes reach the handle.
        let u = [
            if axis.human.has_arm() {
                hand.push_n
            } else {
                hand.input_force()
            },
            force_n,
        ];
        let at = match axis.current {
            Some((g, at)) if g == hand.grasp => at,
            _ => {
                let at = self
                    .steppers
                    .iter()
                    .position(|(g, _)| *g == hand.grasp)
                    .expect("a stepper for every grasp in the script");
                axis.current = Some((hand.grasp, at));
                at
            }
        };
        let steppers = &mut self.steppers[at].1;
        let dirs = [&self.actuator_dir[..], &self.device.handle[..]];
        let substeps = self.substeps;
        let held = std::mem::replace(&mut axis.held_n, force_n);
        let (forces, costs) = self.effects.parts();
        let x = &mut axis.x;
        let mut run = |stepper: &mut Stepper, f: f64| match forces {
            Some(forces) => {
                let mut nl = |x: &[f64], f: &mut [f64]| forces.add(n, dirs, x, f);
                for _ in 0..substeps {
                    stepper.step(x, [u[0], f], Some(&mut nl));
                }
            }
            None => {
                for _ in 0..substeps {
                    stepper.step(x, [u[0], f], None);
                }
            }
        };
        match &mut steppers.split {
            // With a latency the amplifier holds the last tick's force until
            // the hold switches, then this tick's; the first part is the
            // latency's cost.
            Some([before, after]) => {
                let t0 = timing.then(Instant::now);
                run(before, held);
                costs.charge(&[Effect::Latency], t0);
                run(after, force_n);
            }
            None => run(&mut steppers.tick, force_n),
        }
    }

    /// Axis `i`'s handle: position (m), velocity (m/s) and the force the
    /// hand puts on it (N).
    fn at_handle(&self, i: usize, hand: &HandState) -> (f64, f64, f64) {
        let n = self.device.n;
        let axis = &self.axes[i];
        let x_h = self.handle.of(&axis.x[..n]);
        let v_h = self.handle.of(&axis.x[n..2 * n]);
        let f_h = match axis.human.grasp_of(hand.grasp).arm {
            Some(_) => {
                let g = hand.grasp.grasp();
                let at = 2 * n + usize::from(self.load_cell);
                g.stiffness_npm * (axis.x[at] - x_h)
                    + g.damping_nspm * (axis.x[at + 1] - v_h)
                    + hand.push_n
            }
            None => hand.force_on(x_h, v_h),
        };
        (x_h, v_h, f_h)
    }

    /// The energy the hand put into axis `i`, the force it was given, and
    /// a handle that ran away.
    fn account(&mut self, i: usize, (x_h, v_h, f_h): (f64, f64, f64), delivered_n: f64) {
        let axis = &mut self.axes[i];
        let p = f_h * v_h;
        axis.energy_in += 0.5 * (p + axis.last_power) * self.period;
        axis.last_power = p;
        self.peak_force = self.peak_force.max(delivered_n.abs());
        axis.detector.push(delivered_n);
        if self.failure.is_none() && (!x_h.is_finite() || x_h.abs() > 10.0 || !v_h.is_finite()) {
            let on = if N == 1 {
                String::new()
            } else {
                format!(" (axis {i})")
            };
            self.failure = Some(match &self.warning {
                Some(w) => format!("diverged{on}: the integrator is unstable ({w})"),
                None => format!("diverged{on}: the device ran 10 m away"),
            });
        }
    }

    /// Run to the scene's end (or the first failure), passing each sample
    /// to `sink`.
    pub fn run(&mut self, mut sink: impl FnMut(&Sample<N>)) -> Report {
        let start = Instant::now();
        while self.tick < self.total_ticks && self.failure.is_none() {
            let s = self.step();
            sink(&s);
        }
        self.report(start.elapsed().as_secs_f64())
    }

    /// The report so far, given the wall time spent.
    pub fn report(&self, wall: f64) -> Report {
        let verdicts: Vec<StabilityVerdict> =
            self.axes.iter().map(|a| a.detector.verdict()).collect();
        let unstable = verdicts.iter().position(|v| !v.stable);
        let reason = self.failure.clone().or_else(|| {
            unstable.map(|a| {
                let why = verdicts[a].reason.clone().unwrap_or_default();
                if N == 1 {
                    why
                } else {
                    format!("axis {a}: {why}")
                }
            })
        });
        let ticks = self.tick.max(1) as f64;
        let sim_seconds = self.tick as f64 * self.period;
        let layers: Vec<_> = (0..N)
            .filter_map(|a| self.servo.layer(a))
            .filter(|l| !l.energy_in_j().is_nan())
            .collect();
        Report {
            scene: self.scene.name.clone(),
            stable: self.failure.is_none() && unstable.is_none(),
            reason,
            peak_force_n: self.peak_force,
            energy_in_j: self.axes.iter().map(|a| a.energy_in).sum(),
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
            late_rms_n: verdicts.iter().map(|v| v.late_rms_n).collect(),
            passivity: (!layers.is_empty()).then(|| PassivityReport {
                dissipated_j: layers.iter().map(|l| l.dissipated_j()).sum(),
                active_ticks: self.axes.iter().map(|a| a.layer_active).sum(),
                lowest_energy_j: self.axes.iter().map(|a| a.layer_lowest).fold(0.0, f64::min),
            }),
            blocks_m: self
                .servo
                .blocks()
                .map(|w| {
                    w.blocks
                        .iter()
                        .map(|b| b.min.map(|p| p.nm() as f64 * 1e-9))
                        .collect()
                })
                .unwrap_or_default(),
        }
    }
}
