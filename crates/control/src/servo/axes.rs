//! The servo of a device with `N` Cartesian axes (the paper's Excalibur has
//! three): one encoder, velocity estimate and coupling (with its regulator,
//! on the admittance display) per axis, one [`World`] that answers every
//! axis's coupling in the same tick, and one safety layer over the force
//! vector.

use super::{
    impedance_gains, load_cell_faults, AdmittanceLaws, Axis, Display, Gains, GainsError, LawsRef,
    SensorFrame, ServoOutput,
};
use crate::coupling::ImpedanceCoupling;
use crate::safety::{AxesInputs, AxisError, Faults, SafeForces, SafetyConfig, SafetyLayer};
use crate::world::World;
use crate::{Encoder, EncoderError, Position, Real};

/// The sensors of one tick of an `N`-axis device, all sampled at one
/// instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AxesFrame<R, const N: usize> {
    /// Timer tick number (must increase by one every tick).
    pub tick: u32,
    /// Each axis's raw hardware encoder counter.
    pub encoder_raw: [u32; N],
    /// Each axis's load-cell force on the handle along the axis (N); only
    /// the admittance display reads them.
    pub load_cell_n: [R; N],
    /// Dead-man switch closed (operator present); one for the device.
    pub dead_man_closed: bool,
}

impl<R> From<SensorFrame<R>> for AxesFrame<R, 1> {
    /// The one-axis servo's frame, as the one axis of an `N = 1` frame.
    fn from(f: SensorFrame<R>) -> Self {
        AxesFrame {
            tick: f.tick,
            encoder_raw: [f.encoder_raw],
            load_cell_n: [f.load_cell_n],
            dead_man_closed: f.dead_man_closed,
        }
    }
}

impl<R: Copy> From<AxesFrame<R, 1>> for SensorFrame<R> {
    /// An `N = 1` frame's one axis, as the one-axis servo's frame.
    fn from(f: AxesFrame<R, 1>) -> Self {
        SensorFrame {
            tick: f.tick,
            encoder_raw: f.encoder_raw[0],
            load_cell_n: f.load_cell_n[0],
            dead_man_closed: f.dead_man_closed,
        }
    }
}

impl<R> From<ServoOutput<R>> for AxesOutput<R, 1> {
    /// The one-axis servo's output, as the one axis of an `N = 1` output.
    fn from(o: ServoOutput<R>) -> Self {
        AxesOutput {
            actuator_force_n: [o.actuator_force_n],
            commanded_force_n: [o.commanded_force_n],
            position: [o.position],
            velocity_mps: [o.velocity_mps],
            ve_velocity_mps: [o.ve_velocity_mps],
            ve_force_n: [o.ve_force_n],
            coupling_force_n: [o.coupling_force_n],
            reference: [o.reference],
            faults: o.faults,
            limited: [o.limited],
        }
    }
}

/// The result of one tick of every axis; each field is the one-axis
/// [`ServoOutput`](super::ServoOutput)'s, per axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AxesOutput<R, const N: usize> {
    /// Force to hold on each axis's actuator (N), after the safety layer;
    /// positive resists positive motion along the axis (the paper's `f_a`).
    pub actuator_force_n: [R; N],
    /// What the laws asked for before the safety layer (N).
    pub commanded_force_n: [R; N],
    /// Each axis's position from its encoder.
    pub position: [Position; N],
    /// Each axis's first-difference velocity (m/s).
    pub velocity_mps: [R; N],
    /// The world's velocity along each axis (m/s).
    pub ve_velocity_mps: [R; N],
    /// The force on the world along each axis (N).
    pub ve_force_n: [R; N],
    /// The force in each axis's virtual coupling (N).
    pub coupling_force_n: [R; N],
    /// Impedance display: the world point each coupling holds; admittance
    /// display: each axis's position command.
    pub reference: [Position; N],
    /// Latched faults, whichever axis found them: any gives zero force on
    /// every axis.
    pub faults: Faults,
    /// Whether the safety layer clipped each axis's force.
    pub limited: [bool; N],
}

impl<R: Real, const N: usize> AxesOutput<R, N> {
    /// No force on any axis, the device at `position` moving at
    /// `velocity_mps` (m/s): a disarmed board's last output before its
    /// first tick, and a faulted tick's.
    #[inline(always)]
    pub fn at_rest(position: [Position; N], velocity_mps: [R; N]) -> Self {
        AxesOutput {
            actuator_force_n: [R::ZERO; N],
            commanded_force_n: [R::ZERO; N],
            position,
            velocity_mps,
            ve_velocity_mps: [R::ZERO; N],
            ve_force_n: [R::ZERO; N],
            coupling_force_n: [R::ZERO; N],
            reference: position,
            faults: Faults::NONE,
            limited: [false; N],
        }
    }
}

#[derive(Clone, Copy, Debug)]
enum AxesLaws<R, const N: usize> {
    Impedance([ImpedanceCoupling<R>; N]),
    Admittance([AdmittanceLaws<R>; N]),
}

/// A haptic display of `N` Cartesian axes, one display for all of them:
/// each axis runs the one-axis [`Servo`](super::Servo)'s laws with its own
/// gains (each proven for its axis), against one [`World`] that solves
/// every axis's coupling in the same tick, and one [`SafetyLayer`] over the
/// force vector: a peak limit and an I²t budget per motor, and one tick
/// counter, dead-man switch and latch, so that a fault on any axis gives
/// zero force on every axis in the tick that finds it.
///
/// With `N = 1` and a [`PerAxis`](crate::world::PerAxis) world it computes
/// bit for bit what the one-axis servo computes.
///
/// # Examples
///
/// ```
/// use twoport_control::servo::{AxesFrame, AxesServo, ImpedanceGains};
/// use twoport_control::ve::BilateralConstraint;
/// use twoport_control::world::PerAxis;
/// use twoport_control::{Encoder, Position, SafetyConfig};
/// let enc = Encoder::new(16, 1_000_000, 0, Position::ZERO).unwrap(); // 1 µm counts
/// let gains = ImpedanceGains::new(51_000.0, 90.0).into();
/// let world = PerAxis([BilateralConstraint::new(Position::ZERO); 3]);
/// // (A bilateral constraint computes in any float: name the servo's.)
/// let mut s = AxesServo::<_, f32, 3>::new([gains; 3], [enc; 3], [SafetyConfig::excalibur(); 3], world)?;
/// s.enable().unwrap();
/// // 1 mm along y, the other axes at the constraint: only y pushes back.
/// let frame = |tick| AxesFrame {
///     tick,
///     encoder_raw: [0, 1_000, 0],
///     load_cell_n: [0.0; 3],
///     dead_man_closed: true,
/// };
/// let mut out = s.tick(&frame(0));
/// for k in 1..200 {
///     out = s.tick(&frame(k));
/// }
/// assert_eq!(out.actuator_force_n[0], 0.0);
/// assert!((out.actuator_force_n[1] - 51.0).abs() < 0.01);
/// # Ok::<(), twoport_control::safety::AxisError<twoport_control::GainsError>>(())
/// ```
#[derive(Clone, Copy, Debug)]
pub struct AxesServo<W, R = f32, const N: usize = 3> {
    axes: [Axis<R>; N],
    safety: SafetyLayer<R, N>,
    laws: AxesLaws<R, N>,
    world: W,
}

impl<W: World<R, N>, R: Real, const N: usize> AxesServo<W, R, N> {
    /// A disabled servo: each axis's gains, encoder and limits, and the
    /// world they all couple to, computing in `R` (the world's float:
    /// `f32` on the board). Every axis runs the same display; the error
    /// names the axis and what is wrong with it.
    pub fn new(
        gains: [Gains; N],
        encoders: [Encoder; N],
        safety: [SafetyConfig; N],
        world: W,
    ) -> Result<Self, AxisError<GainsError>> {
        let param = |axis, e| AxisError {
            axis,
            error: GainsError::Param(e),
        };
        let layer = SafetyLayer::for_axes(safety).map_err(|e| param(e.axis, e.error))?;
        // (`for_axes` refused N = 0, so there is an axis 0.)
        let t = safety[0].period_s;
        let mut axes = [Axis::<R>::new(encoders[0], t).map_err(|e| param(0, e))?; N];
        for (i, (a, enc)) in axes.iter_mut().zip(encoders).enumerate() {
            *a = Axis::new(enc, t).map_err(|e| param(i, e))?;
        }
        let laws = Self::build_laws(&gains, &axes, t)?;
        let mut s = AxesServo {
            axes,
            safety: layer,
            laws,
            world,
        };
        s.realign();
        Ok(s)
    }

    fn build_laws(
        gains: &[Gains; N],
        axes: &[Axis<R>; N],
        t: f32,
    ) -> Result<AxesLaws<R, N>, AxisError<GainsError>> {
        let param = |axis| {
            move |e| AxisError {
                axis,
                error: GainsError::Param(e),
            }
        };
        // Each axis's law is first the placeholder built for axis 0 and is
        // then replaced by its own (every axis has this display).
        Self::one_display(gains)?;
        Ok(match gains[0] {
            Gains::Impedance(g) => {
                let mut c = [ImpedanceCoupling::new_in(g.k_npm, g.b_nspm, t).map_err(param(0))?; N];
                for (i, (c, g)) in c.iter_mut().zip(gains).enumerate() {
                    if let Gains::Impedance(g) = g {
                        c.set_gains(g.k_npm, g.b_nspm).map_err(param(i))?;
                    }
                }
                AxesLaws::Impedance(c)
            }
            Gains::Admittance(g) => {
                let mut laws = [AdmittanceLaws::new(g, t, axes[0].position).map_err(param(0))?; N];
                for (i, ((l, g), axis)) in laws.iter_mut().zip(gains).zip(axes).enumerate() {
                    if let Gains::Admittance(g) = g {
                        *l = AdmittanceLaws::new(*g, t, axis.position).map_err(param(i))?;
                    }
                }
                AxesLaws::Admittance(laws)
            }
        })
    }

    /// The display every axis of `gains` runs, or the first axis that
    /// differs from axis 0.
    fn one_display(gains: &[Gains; N]) -> Result<Display, AxisError<GainsError>> {
        let Some(first) = gains.first().map(Gains::display) else {
            return Err(AxisError {
                axis: 0,
                error: GainsError::Param(crate::ParamError {
                    name: "axes",
                    value: 0.0,
                    problem: "must be at least one",
                }),
            });
        };
        match gains.iter().position(|g| g.display() != first) {
            None => Ok(first),
            Some(axis) => Err(AxisError {
                axis,
                error: GainsError::WrongDisplay {
                    servo: first,
                    gains: gains[axis].display(),
                },
            }),
        }
    }

    /// Enable force output on every axis (ramping in), re-aligning the laws
    /// to the device if it was disabled. Refused while a fault is latched.
    pub fn enable(&mut self) -> Result<(), Faults> {
        if !self.safety.faults().is_empty() {
            return Err(self.safety.faults());
        }
        if !self.safety.is_enabled() {
            self.realign();
        }
        self.safety.enable()
    }

    /// Disable force output on every axis.
    pub fn disable(&mut self) {
        self.safety.disable();
    }

    /// Clear latched faults and re-align the laws to the device.
    pub fn clear(&mut self) {
        self.safety.clear();
        self.realign();
    }

    /// A link heartbeat arrived.
    pub fn heartbeat(&mut self) {
        self.safety.heartbeat();
    }

    /// Latch a fault found outside the tick (e.g. by the link).
    pub fn trip(&mut self, f: Faults) {
        self.safety.trip(f);
    }

    /// Calibrate every axis's encoder: where the device is now reads as
    /// `position` (homing's result), and the laws re-align to it.
    pub fn calibrate(&mut self, position: [Position; N]) {
        for (a, x) in self.axes.iter_mut().zip(position) {
            a.encoder.rezero(x);
            a.position = x;
        }
        self.realign();
    }

    /// Calibrate axis `axis` from an index pulse: its counter read `raw` at
    /// `position` (see [`Encoder::rezero_at`]). Refused, changing nothing,
    /// for an axis the servo lacks or a raw value the counter cannot hold.
    pub fn calibrate_axis_at(
        &mut self,
        axis: usize,
        raw: u32,
        position: Position,
    ) -> Result<(), AxisError<EncoderError>> {
        let Some(a) = self.axes.get_mut(axis) else {
            return Err(AxisError {
                axis,
                error: EncoderError::RawOutOfRange(raw),
            });
        };
        a.position = a
            .encoder
            .rezero_at(raw, position)
            .map_err(|error| AxisError { axis, error })?;
        self.realign();
        Ok(())
    }

    /// Calibrate axis `axis` alone: where it is now reads as `position`
    /// (its homing's result), and the laws re-align. Refused, changing
    /// nothing, for an axis the servo lacks.
    pub fn calibrate_axis(&mut self, axis: usize, position: Position) -> Result<(), AxisError<()>> {
        let a = self
            .axes
            .get_mut(axis)
            .ok_or(AxisError { axis, error: () })?;
        a.encoder.rezero(position);
        a.position = position;
        self.realign();
        Ok(())
    }

    /// New safety limits for every axis, while disabled (see
    /// [`SafetyLayer::reconfigure_axes`]).
    pub fn set_limits(&mut self, cfg: [SafetyConfig; N]) -> Result<(), AxisError> {
        self.safety.reconfigure_axes(cfg)
    }

    /// The safety layer (limits, latched faults, thermal state per motor).
    pub fn safety(&self) -> &SafetyLayer<R, N> {
        &self.safety
    }

    /// The world.
    pub fn world(&self) -> &W {
        &self.world
    }

    /// The world, to change it between ticks.
    pub fn world_mut(&mut self) -> &mut W {
        &mut self.world
    }

    /// Each axis's position.
    pub fn position(&self) -> [Position; N] {
        core::array::from_fn(|i| self.axes[i].position)
    }

    /// The display every axis runs.
    pub fn display(&self) -> Display {
        match self.laws {
            AxesLaws::Impedance(_) => Display::Impedance,
            AxesLaws::Admittance(_) => Display::Admittance,
        }
    }

    /// Axis `axis`'s laws, for their gains and z-domain forms; `None` for
    /// an axis the servo lacks.
    pub fn laws(&self, axis: usize) -> Option<LawsRef<'_, R>> {
        Some(match &self.laws {
            AxesLaws::Impedance(c) => LawsRef::Impedance(c.get(axis)?),
            AxesLaws::Admittance(a) => {
                let a = a.get(axis)?;
                LawsRef::Admittance {
                    coupling: &a.coupling,
                    regulator: &a.regulator,
                }
            }
        })
    }

    /// Each axis's gains in force.
    pub fn gains(&self) -> [Gains; N] {
        core::array::from_fn(|i| match &self.laws {
            AxesLaws::Impedance(c) => Gains::Impedance(impedance_gains(&c[i])),
            AxesLaws::Admittance(a) => Gains::Admittance(a[i].gains()),
        })
    }

    /// Change every axis's gains between ticks: all of them change or, on
    /// an error (naming the axis), none do.
    pub fn set_gains(&mut self, gains: [Gains; N]) -> Result<(), AxisError<GainsError>> {
        let mut laws = self.laws;
        let servo = self.display();
        for (axis, g) in gains.into_iter().enumerate() {
            let at = |error| AxisError { axis, error };
            match (&mut laws, g) {
                (AxesLaws::Impedance(c), Gains::Impedance(g)) => c[axis]
                    .set_gains(g.k_npm, g.b_nspm)
                    .map_err(|e| at(e.into()))?,
                (AxesLaws::Admittance(a), Gains::Admittance(g)) => {
                    a[axis].set_gains(g).map_err(|e| at(e.into()))?
                }
                _ => {
                    return Err(at(GainsError::WrongDisplay {
                        servo,
                        gains: g.display(),
                    }))
                }
            }
        }
        self.laws = laws;
        Ok(())
    }

    fn realign(&mut self) {
        let x = self.position();
        for a in &mut self.axes {
            a.estimator.reset(a.position);
        }
        if let AxesLaws::Admittance(laws) = &mut self.laws {
            for (l, x) in laws.iter_mut().zip(x) {
                l.reset(x);
            }
        }
        self.world.reset(&x);
    }

    /// Every axis's encoder: the velocities and the faults they found.
    #[inline(always)]
    fn sense(&mut self, frame: &AxesFrame<R, N>) -> ([R; N], Faults) {
        let mut v = [R::ZERO; N];
        let mut faults = Faults::NONE;
        for ((a, v), raw) in self.axes.iter_mut().zip(&mut v).zip(frame.encoder_raw) {
            let (vel, f) = a.sense(raw);
            *v = vel;
            faults = faults.with(f);
        }
        (v, faults)
    }

    /// The safety layer's answer to the commands in `out`, filled in.
    #[inline(always)]
    fn limit(&mut self, frame: &AxesFrame<R, N>, faults: Faults, out: &mut AxesOutput<R, N>) {
        let safe: SafeForces<R, N> = self.safety.step_axes(
            &AxesInputs {
                tick: frame.tick,
                dead_man_closed: frame.dead_man_closed,
                velocity_mps: out.velocity_mps,
                sensor_faults: faults,
            },
            out.commanded_force_n,
        );
        out.actuator_force_n = safe.force_n;
        out.faults = safe.faults;
        out.limited = safe.limited;
    }

    /// One control tick of every axis with `law` in place of the laws and
    /// the world: the same encoders, velocity estimates and safety layer,
    /// so every limit and fault check holds for it too. `law` gets each
    /// axis's index, position and velocity (m/s) and answers with its
    /// actuator force (N, positive resists positive motion); it is not
    /// called on a faulted tick. Homing runs through this, every axis
    /// homing at once.
    pub fn tick_with(
        &mut self,
        frame: &AxesFrame<R, N>,
        mut law: impl FnMut(usize, Position, R) -> R,
    ) -> AxesOutput<R, N> {
        let (v, faults) = self.sense(frame);
        let x = self.position();
        let mut out = AxesOutput::at_rest(x, v);
        if faults.is_empty() && self.safety.faults().is_empty() {
            for (i, f) in out.commanded_force_n.iter_mut().enumerate() {
                *f = law(i, x[i], v[i]);
            }
        }
        self.limit(frame, faults, &mut out);
        out
    }

    /// One control tick of every axis.
    pub fn tick(&mut self, frame: &AxesFrame<R, N>) -> AxesOutput<R, N> {
        let (v, mut faults) = self.sense(frame);
        let x = self.position();
        let mut out = AxesOutput::at_rest(x, v);
        match &mut self.laws {
            AxesLaws::Impedance(c) => {
                if faults.is_empty() && self.safety.faults().is_empty() {
                    let stretch = self.world.offset_m(&x);
                    let ports = core::array::from_fn(|i| c[i].port(-stretch[i], v[i]));
                    for (i, ve) in self.world.step(&ports).into_iter().enumerate() {
                        out.commanded_force_n[i] = ve.force_n;
                        out.ve_force_n[i] = ve.force_n;
                        out.coupling_force_n[i] = ve.force_n;
                        out.ve_velocity_mps[i] = ve.velocity_mps;
                    }
                }
                out.reference = self.world.position();
            }
            AxesLaws::Admittance(laws) => {
                for (i, f) in frame.load_cell_n.iter().enumerate() {
                    let max = self.safety.configs()[i].max_sensor_force_n;
                    faults = faults.with(load_cell_faults(*f, max));
                }
                if faults.is_empty() && self.safety.faults().is_empty() {
                    let f_c = frame.load_cell_n;
                    let ports = core::array::from_fn(|i| laws[i].coupling.port(f_c[i]));
                    let answers = self.world.step(&ports);
                    for (i, (l, ve)) in laws.iter_mut().zip(answers).enumerate() {
                        let s = l.coupling.finish(f_c[i], ve);
                        let x_cmd = l.command.step_unsplit(s.velocity_mps);
                        out.commanded_force_n[i] = l.regulator.step(x[i], x_cmd);
                        out.ve_velocity_mps[i] = s.velocity_mps;
                        out.ve_force_n[i] = s.ve_force_n;
                        out.coupling_force_n[i] = s.coupling_force_n;
                    }
                }
                for (r, l) in out.reference.iter_mut().zip(laws.iter()) {
                    *r = l.command.position();
                }
            }
        }
        self.limit(frame, faults, &mut out);
        out
    }
}
