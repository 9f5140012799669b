//! One tick of each display over every axis: sense, the laws against the
//! world, the safety layer.

use super::laws::{load_cell_faults, AdmittanceLaws, Axis};
use super::{PortLayer, SensorFrame, ServoOutput};
use crate::coupling::{AdmittanceStep, ImpedanceCoupling};
use crate::safety::{AxesInputs, Faults, SafeForces, SafetyLayer};
use crate::ve::VeOutput;
use crate::world::World;
use crate::{Position, Real};

/// Encoders, velocity estimates and the safety layer: the part both
/// displays share.
#[derive(Clone, Copy, Debug)]
pub(super) struct Frontend<R, const N: usize> {
    pub(super) axes: [Axis<R>; N],
    pub(super) safety: SafetyLayer<R, N>,
}

impl<R: Real, const N: usize> Frontend<R, N> {
    /// Each axis's position.
    #[inline(always)]
    pub(super) fn position(&self) -> [Position; N] {
        core::array::from_fn(|i| self.axes[i].position)
    }

    /// Every axis's encoder: the velocities and the faults they found.
    #[inline(always)]
    pub(super) fn sense(&mut self, frame: &SensorFrame<R, N>) -> ([R; N], Faults) {
        let mut v = [R::ZERO; N];
        let mut faults = Faults::NONE;
        for ((a, v), raw) in self.axes.iter_mut().zip(&mut v).zip(frame.encoder_raw) {
            let (vel, f) = a.sense(raw);
            *v = vel;
            faults = faults.with(f);
        }
        (v, faults)
    }

    /// Every axis at the positions `x` found by other means: the
    /// velocities, and no sensor faults (the finder reports its own).
    #[inline(always)]
    pub(super) fn sense_at(&mut self, x: &[Position; N]) -> ([R; N], Faults) {
        let mut v = [R::ZERO; N];
        for ((a, v), x) in self.axes.iter_mut().zip(&mut v).zip(x) {
            *v = a.sense_at(*x);
        }
        (v, Faults::NONE)
    }

    /// Whether the laws may run this tick.
    #[inline(always)]
    pub(super) fn runnable(&self, sensor_faults: Faults) -> bool {
        sensor_faults.is_empty() && self.safety.faults().is_empty()
    }

    /// The safety layer's answer to each axis's `command_n` (N).
    // (Always inlined, as the layer's step is: out of line, the answer
    // passes through memory, 15 of the board tick's instructions.)
    #[inline(always)]
    pub(super) fn limit(
        &mut self,
        frame: &SensorFrame<R, N>,
        v: &[R; N],
        faults: Faults,
        command_n: [R; N],
    ) -> SafeForces<R, N> {
        self.safety.step_axes(
            &AxesInputs {
                tick: frame.tick,
                dead_man_closed: frame.dead_man_closed,
                velocity_mps: *v,
                sensor_faults: faults,
            },
            command_n,
        )
    }

    /// One tick with `law` (axis, position, velocity in m/s → force in N)
    /// in place of the display's laws; `law` is not called on a faulted
    /// tick.
    #[inline(always)]
    pub(super) fn tick_with(
        &mut self,
        frame: &SensorFrame<R, N>,
        (v, faults): ([R; N], Faults),
        mut law: impl FnMut(usize, Position, R) -> R,
    ) -> ServoOutput<R, N> {
        let x = self.position();
        let mut out = ServoOutput::at_rest(x, v);
        if self.runnable(faults) {
            for (i, f) in out.commanded_force_n.iter_mut().enumerate() {
                *f = law(i, x[i], v[i]);
            }
        }
        let safe = self.limit(frame, &v, faults, out.commanded_force_n);
        out.actuator_force_n = safe.force_n;
        out.faults = safe.faults;
        out.limited = safe.limited;
        out
    }
}

// Each display's tick takes what the axes sensed this tick: their encoders'
// reading, or the positions a linkage's kinematics found.
//
// The impedance display's tick is the board's hot path. Each display's
// tick builds its output at the end, from locals: an output filled in
// first and then changed is written twice through the caller's pointer
// (about ten of the M4F tick's instructions on one axis).
#[inline(always)]
pub(super) fn impedance<R: Real, W: World<R, N>, L: PortLayer<R>, const N: usize>(
    front: &mut Frontend<R, N>,
    couplings: &mut [ImpedanceCoupling<R>; N],
    world: &mut W,
    layers: &mut [L; N],
    frame: &SensorFrame<R, N>,
    sense: impl FnOnce(&mut Frontend<R, N>) -> ([R; N], Faults),
) -> ServoOutput<R, N> {
    let (v, faults) = sense(front);
    let runnable = front.runnable(faults);
    let x = front.position();
    let (answers, command_n) = if runnable {
        let (mut x_e, mut v_e) = (x, v);
        for i in 0..N {
            (x_e[i], v_e[i]) = layers[i].element_motion(x[i], v[i]);
        }
        let stretch = world.offsets_m(&x_e);
        let ports = core::array::from_fn(|i| couplings[i].port(-stretch[i], v_e[i]));
        let answers = world.step_axes(&ports);
        let command_n =
            core::array::from_fn(|i| layers[i].impedance_force(x[i], v[i], answers[i].force_n));
        (answers, command_n)
    } else {
        ([VeOutput::default(); N], [R::ZERO; N])
    };
    let safe = front.limit(frame, &v, faults, command_n);
    if runnable {
        for (l, f) in layers.iter_mut().zip(safe.force_n) {
            l.held(f);
        }
    }
    // (The VE's answer is on the port's line: the coupling's force and the
    // VE's are one number.)
    let ve_force_n = answers.map(|a| a.force_n);
    ServoOutput {
        actuator_force_n: safe.force_n,
        commanded_force_n: command_n,
        position: x,
        velocity_mps: v,
        ve_velocity_mps: answers.map(|a| a.velocity_mps),
        ve_force_n,
        coupling_force_n: ve_force_n,
        reference: world.positions(),
        faults: safe.faults,
        limited: safe.limited,
    }
}

#[inline(always)]
pub(super) fn admittance<R: Real, W: World<R, N>, L: PortLayer<R>, const N: usize>(
    front: &mut Frontend<R, N>,
    laws: &mut [AdmittanceLaws<R>; N],
    world: &mut W,
    layers: &mut [L; N],
    frame: &SensorFrame<R, N>,
    sense: impl FnOnce(&mut Frontend<R, N>) -> ([R; N], Faults),
) -> ServoOutput<R, N> {
    let (v, mut faults) = sense(front);
    let f_c = frame.load_cell_n;
    for (f, c) in f_c.iter().zip(front.safety.configs()) {
        faults = faults.with(load_cell_faults(*f, c.max_sensor_force_n));
    }
    let x = front.position();
    let mut command_n = [R::ZERO; N];
    let mut steps = [AdmittanceStep::<R>::default(); N];
    if front.runnable(faults) {
        let ports = core::array::from_fn(|i| laws[i].coupling.port(f_c[i]));
        let answers = world.step_axes(&ports);
        for i in 0..N {
            let l = &mut laws[i];
            steps[i] = l.coupling.finish(f_c[i], answers[i]);
            let v_cmd = layers[i].admittance_velocity(f_c[i], steps[i].velocity_mps);
            let x_cmd = l.command.step_unsplit(v_cmd);
            command_n[i] = l.regulator.step(x[i], x_cmd);
        }
    }
    let safe = front.limit(frame, &v, faults, command_n);
    ServoOutput {
        actuator_force_n: safe.force_n,
        commanded_force_n: command_n,
        position: x,
        velocity_mps: v,
        ve_velocity_mps: steps.map(|s| s.velocity_mps),
        ve_force_n: steps.map(|s| s.ve_force_n),
        coupling_force_n: steps.map(|s| s.coupling_force_n),
        reference: core::array::from_fn(|i| laws[i].command.position()),
        faults: safe.faults,
        limited: safe.limited,
    }
}
