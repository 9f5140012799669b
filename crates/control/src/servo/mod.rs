//! One control tick of either display on a device of `N` axes, as the
//! board runs it and the simulator runs it: sensors in, laws, VE, safety
//! layer, held actuator forces out.

mod frame;
mod gains;
mod laws;
mod layer;
mod tick;

pub use frame::{SensorFrame, ServoOutput};
pub use gains::{AdmittanceGains, Display, Gains, GainsError, ImpedanceGains};
pub use laws::LawsRef;
pub use layer::{Direct, OnDemand, PortLayer};

use crate::safety::{AxisError, Faults, SafetyConfig, SafetyLayer};
use crate::world::World;
use crate::{Encoder, EncoderError, Position, Real};
use laws::{Axis, Laws};
use tick::Frontend;

/// A haptic display's servo on `N` Cartesian axes (one unless named),
/// either display (impedance, paper Fig. 5: measure motion, command force
/// through `Z_cI`; admittance, Fig. 6: measure force, command motion
/// through `Z_cA`, the velocity integrated to a position command and the
/// regulator `K_p`), computing in `R` (`f32` on the board, `f64` in the
/// simulator on request).
///
/// Each axis has its own encoder, velocity estimate and laws, with its own
/// gains (each proven for its axis). The axes couple to one [`World`] `W`
/// that answers every axis's coupling in the same tick; on one axis any
/// [`VirtualEnvironment`](crate::ve::VirtualEnvironment) is a world. One
/// [`SafetyLayer`] watches the force vector: a peak limit and an I²t
/// budget per motor, and one tick counter, dead-man switch and latch, so
/// that a fault on any axis gives zero force on every axis in the tick
/// that finds it.
///
/// A servo starts disabled: it outputs zero force until [`Servo::enable`],
/// then ramps in. Any fault latches zero force until [`Servo::clear`].
///
/// Between each axis's port and its laws sits a [`PortLayer`] `L`:
/// [`Direct`] (nothing) unless [`Servo::with_layers`] puts a passivity
/// controller there.
///
/// # Examples
///
/// One axis:
///
/// ```
/// use twoport_control::servo::{ImpedanceGains, SensorFrame, Servo};
/// use twoport_control::ve::BilateralConstraint;
/// use twoport_control::{Encoder, Position, SafetyConfig};
/// let enc = Encoder::new(16, 1_000_000, 0, Position::ZERO).unwrap(); // 1 µm counts
/// let ve = BilateralConstraint::new(Position::ZERO);
/// let gains = ImpedanceGains::new(51_000.0, 90.0).into();
/// let mut servo = Servo::new([gains], [enc], [SafetyConfig::new(1e-3, 200.0, 100.0)], ve)?;
/// // Disabled: zero force. Enabled, it ramps in.
/// assert_eq!(servo.tick(&SensorFrame::held(0, [0], [0.0])).actuator_force_n, [0.0]);
/// servo.enable().unwrap();
/// assert!(servo.tick(&SensorFrame::held(1, [0], [0.0])).actuator_force_n[0].is_finite());
/// # Ok::<(), twoport_control::AxisError<twoport_control::GainsError>>(())
/// ```
///
/// Three axes, a constraint on each:
///
/// ```
/// use twoport_control::servo::{ImpedanceGains, SensorFrame, Servo};
/// use twoport_control::ve::BilateralConstraint;
/// use twoport_control::world::PerAxis;
/// use twoport_control::{Encoder, Position, SafetyConfig};
/// let enc = Encoder::new(16, 1_000_000, 0, Position::ZERO).unwrap();
/// let gains = ImpedanceGains::new(51_000.0, 90.0).into();
/// let world = PerAxis([BilateralConstraint::new(Position::ZERO); 3]);
/// let mut s = Servo::new([gains; 3], [enc; 3], [SafetyConfig::excalibur(); 3], world)?;
/// s.enable().unwrap();
/// // 1 mm along y, the other axes at the constraint: only y pushes back.
/// let frame = |tick| SensorFrame::held(tick, [0, 1_000, 0], [0.0; 3]);
/// let mut out = s.tick(&frame(0));
/// for k in 1..200 {
///     out = s.tick(&frame(k));
/// }
/// assert_eq!(out.actuator_force_n[0], 0.0);
/// assert!((out.actuator_force_n[1] - 51.0).abs() < 0.01);
/// # Ok::<(), twoport_control::AxisError<twoport_control::GainsError>>(())
/// ```
#[derive(Clone, Copy, Debug)]
pub struct Servo<W, R = f32, const N: usize = 1, L = Direct> {
    front: Frontend<R, N>,
    laws: Laws<R, N>,
    world: W,
    layers: [L; N],
}

impl<W: World<f32, N>, const N: usize> Servo<W, f32, N> {
    /// A disabled f32 servo: each axis's gains, encoder and limits, and the
    /// world they all couple to. Every axis runs the same display; the
    /// error names the axis and what is wrong with it.
    pub fn new(
        gains: [Gains; N],
        encoders: [Encoder; N],
        safety: [SafetyConfig; N],
        world: W,
    ) -> Result<Self, AxisError<GainsError>> {
        Self::new_in(gains, encoders, safety, world)
    }
}

impl<W: World<R, N>, R: Real, const N: usize> Servo<W, R, N> {
    /// [`Servo::new`] computing in `R` (the world's float).
    pub fn new_in(
        gains: [Gains; N],
        encoders: [Encoder; N],
        safety: [SafetyConfig; N],
        world: W,
    ) -> Result<Self, AxisError<GainsError>> {
        let param = |axis, e| AxisError::new(axis, GainsError::Param(e));
        let layer = SafetyLayer::for_axes(safety).map_err(|e| param(e.axis, e.error))?;
        // (`for_axes` refused N = 0, so there is an axis 0.)
        let t = safety[0].period_s;
        let mut axes = [Axis::<R>::new(encoders[0], t).map_err(|e| param(0, e))?; N];
        for (i, (a, enc)) in axes.iter_mut().zip(encoders).enumerate() {
            *a = Axis::new(enc, t).map_err(|e| param(i, e))?;
        }
        let front = Frontend {
            axes,
            safety: layer,
        };
        let laws = Laws::new(&gains, &front.position(), t)?;
        let mut s = Servo {
            front,
            laws,
            world,
            layers: [Direct; N],
        };
        s.realign();
        Ok(s)
    }
}

impl<W: World<R, N>, R: Real, const N: usize, L: PortLayer<R>> Servo<W, R, N, L> {
    /// This servo with `layers[i]` between axis `i`'s port and its laws;
    /// refused, naming the axis, when a layer serves the other display.
    ///
    /// # Examples
    ///
    /// ```
    /// use twoport_control::passivity::{PassivityLimits, SeriesDamper};
    /// use twoport_control::servo::{ImpedanceGains, Servo};
    /// use twoport_control::ve::BilateralConstraint;
    /// use twoport_control::{Encoder, Position, SafetyConfig};
    /// let enc = Encoder::new(16, 1_000_000, 0, Position::ZERO).unwrap();
    /// let ve = BilateralConstraint::new(Position::ZERO);
    /// let gains = ImpedanceGains::new(51_000.0, 90.0).into();
    /// let servo = Servo::new([gains], [enc], [SafetyConfig::new(1e-3, 200.0, 100.0)], ve)?;
    /// let pc = SeriesDamper::new(PassivityLimits::for_device(0.7, 1e-3, 200.0)?)?;
    /// let servo = servo.with_layers([pc])?;
    /// assert_eq!(servo.layers()[0].damping_nspm(), 0.0);
    /// # Ok::<(), Box<dyn core::error::Error>>(())
    /// ```
    pub fn with_layers<M: PortLayer<R>>(
        self,
        layers: [M; N],
    ) -> Result<Servo<W, R, N, M>, AxisError<GainsError>> {
        let servo = self.display();
        for (axis, l) in layers.iter().enumerate() {
            match l.display() {
                Some(d) if d != servo => {
                    return Err(AxisError::new(
                        axis,
                        GainsError::WrongDisplay { servo, gains: d },
                    ))
                }
                _ => {}
            }
        }
        let mut s = Servo {
            front: self.front,
            laws: self.laws,
            world: self.world,
            layers,
        };
        let x = s.position();
        for (l, x) in s.layers.iter_mut().zip(x) {
            l.reset(x);
        }
        Ok(s)
    }

    /// Each axis's layer between the device's port and the laws.
    pub fn layers(&self) -> &[L; N] {
        &self.layers
    }

    /// Engage every axis's layer at the port's position now (a layer on
    /// demand; see [`PortLayer::engage`]).
    pub fn engage_layers(&mut self) {
        let x = self.position();
        for (l, x) in self.layers.iter_mut().zip(x) {
            l.engage(x);
        }
    }

    /// Let every axis's layer on demand go idle again.
    pub fn disengage_layers(&mut self) {
        for l in &mut self.layers {
            l.disengage();
        }
    }

    /// Enable force output on every axis (ramping in), re-aligning the laws
    /// to the device if it was disabled. Refused while a fault is latched.
    pub fn enable(&mut self) -> Result<(), Faults> {
        let safety = &self.front.safety;
        if !safety.faults().is_empty() {
            return Err(safety.faults());
        }
        if !safety.is_enabled() {
            self.realign();
        }
        self.front.safety.enable()
    }

    /// Disable force output on every axis.
    pub fn disable(&mut self) {
        self.front.safety.disable();
    }

    /// Clear latched faults and re-align the laws to the device.
    pub fn clear(&mut self) {
        self.front.safety.clear();
        self.realign();
    }

    /// A link heartbeat arrived.
    pub fn heartbeat(&mut self) {
        self.front.safety.heartbeat();
    }

    /// Latch a fault found outside the tick (e.g. by the link).
    pub fn trip(&mut self, f: Faults) {
        self.front.safety.trip(f);
    }

    /// Calibrate every axis's encoder: where the device is now reads as
    /// `position` from this tick on (homing's result), and the laws
    /// re-align to it. Meant for a disabled servo; an enabled one would see
    /// its position jump.
    pub fn calibrate(&mut self, position: [Position; N]) {
        for (a, x) in self.front.axes.iter_mut().zip(position) {
            a.encoder.rezero(x);
            a.position = x;
        }
        self.realign();
    }

    /// Calibrate axis `axis` alone: where it is now reads as `position`
    /// (its homing's result), and the laws re-align. Refused, changing
    /// nothing, for an axis the servo lacks.
    pub fn calibrate_axis(&mut self, axis: usize, position: Position) -> Result<(), AxisError<()>> {
        let a = self
            .front
            .axes
            .get_mut(axis)
            .ok_or(AxisError::new(axis, ()))?;
        a.encoder.rezero(position);
        a.position = position;
        self.realign();
        Ok(())
    }

    /// Calibrate axis `axis` from an index pulse: its counter read `raw` at
    /// `position` (see [`Encoder::rezero_at`]); the laws re-align to where
    /// the device is now. Refused, changing nothing, for an axis the servo
    /// lacks or a raw value the counter cannot hold.
    pub fn calibrate_axis_at(
        &mut self,
        axis: usize,
        raw: u32,
        position: Position,
    ) -> Result<(), AxisError<EncoderError>> {
        let at = |error| AxisError::new(axis, error);
        let a = self
            .front
            .axes
            .get_mut(axis)
            .ok_or(at(EncoderError::RawOutOfRange(raw)))?;
        a.position = a.encoder.rezero_at(raw, position).map_err(at)?;
        self.realign();
        Ok(())
    }

    /// New safety limits for every axis, while disabled (see
    /// [`SafetyLayer::reconfigure_axes`]).
    pub fn set_limits(&mut self, cfg: [SafetyConfig; N]) -> Result<(), AxisError> {
        self.front.safety.reconfigure_axes(cfg)
    }

    /// The safety layer (limits, latched faults, thermal state per motor).
    pub fn safety(&self) -> &SafetyLayer<R, N> {
        &self.front.safety
    }

    /// The world (on one axis, the virtual environment).
    pub fn world(&self) -> &W {
        &self.world
    }

    /// The world, to change it between ticks.
    pub fn world_mut(&mut self) -> &mut W {
        &mut self.world
    }

    /// Each axis's position.
    pub fn position(&self) -> [Position; N] {
        self.front.position()
    }

    /// The display every axis runs.
    pub fn display(&self) -> Display {
        self.laws.display()
    }

    /// Axis `axis`'s laws, for their gains and z-domain forms; `None` for
    /// an axis the servo lacks.
    pub fn laws(&self, axis: usize) -> Option<LawsRef<'_, R>> {
        self.laws.get(axis)
    }

    /// Each axis's gains in force.
    pub fn gains(&self) -> [Gains; N] {
        self.laws.gains()
    }

    /// Change every axis's gains between ticks: all of them change or, on
    /// an error (naming the axis), none do.
    pub fn set_gains(&mut self, gains: [Gains; N]) -> Result<(), AxisError<GainsError>> {
        self.laws.set_gains(gains)
    }

    fn realign(&mut self) {
        let x = self.position();
        for a in &mut self.front.axes {
            a.estimator.reset(a.position);
        }
        if let Laws::Admittance(laws) = &mut self.laws {
            for (l, x) in laws.iter_mut().zip(x) {
                l.reset(x);
            }
        }
        self.world.reset_axes(&x);
        for (l, x) in self.layers.iter_mut().zip(x) {
            l.reset(x);
        }
    }

    /// One control tick of every axis with `law` in place of the laws and
    /// the world: the same encoders, velocity estimates and safety layer,
    /// so every limit and fault check holds for it too. `law` gets each
    /// axis's index, position and velocity (m/s) and answers with its
    /// actuator force (N, the paper's `f_a`: positive resists positive
    /// motion); it is not called on a faulted tick. Homing runs through
    /// this, every axis homing at once.
    pub fn tick_with(
        &mut self,
        frame: &SensorFrame<R, N>,
        law: impl FnMut(usize, Position, R) -> R,
    ) -> ServoOutput<R, N> {
        let front = &mut self.front;
        let sensed = front.sense(frame);
        front.tick_with(frame, sensed, law)
    }

    /// [`tick_with`](Self::tick_with) at handle positions `x` found by
    /// other means (a linkage's kinematics).
    pub(crate) fn tick_with_at(
        &mut self,
        frame: &SensorFrame<R, N>,
        x: &[Position; N],
        law: impl FnMut(usize, Position, R) -> R,
    ) -> ServoOutput<R, N> {
        let front = &mut self.front;
        let sensed = front.sense_at(x);
        front.tick_with(frame, sensed, law)
    }

    /// One control tick of every axis.
    pub fn tick(&mut self, frame: &SensorFrame<R, N>) -> ServoOutput<R, N> {
        self.run(frame, |front| front.sense(frame))
    }

    /// One tick at handle positions `x` found by other means (a linkage's
    /// kinematics), in place of the encoders' reading; `frame`'s raw
    /// counts are not read. Always inlined into the linkage's tick, where
    /// passing the output through memory is a tenth of the cost.
    #[inline(always)]
    pub(crate) fn tick_at(
        &mut self,
        frame: &SensorFrame<R, N>,
        x: &[Position; N],
    ) -> ServoOutput<R, N> {
        self.run(frame, |front| front.sense_at(x))
    }

    /// One control tick of every axis against `world` in place of the
    /// servo's own, which does not step: the host's VE, held between its
    /// updates ([`Held`](crate::world::Held)). The laws, the port layers
    /// and the safety layer are the servo's.
    pub fn tick_on<V: World<R, N>>(
        &mut self,
        frame: &SensorFrame<R, N>,
        world: &mut V,
    ) -> ServoOutput<R, N> {
        let (front, layers) = (&mut self.front, &mut self.layers);
        display(&mut self.laws, front, world, layers, frame, |f| {
            f.sense(frame)
        })
    }

    /// [`tick_on`](Self::tick_on) at handle positions `x` found by other
    /// means (a linkage's kinematics).
    pub(crate) fn tick_at_on<V: World<R, N>>(
        &mut self,
        frame: &SensorFrame<R, N>,
        x: &[Position; N],
        world: &mut V,
    ) -> ServoOutput<R, N> {
        let (front, layers) = (&mut self.front, &mut self.layers);
        display(&mut self.laws, front, world, layers, frame, |f| {
            f.sense_at(x)
        })
    }

    /// The display's tick, its axes sensed by `sense`.
    #[inline(always)]
    fn run(
        &mut self,
        frame: &SensorFrame<R, N>,
        sense: impl FnOnce(&mut Frontend<R, N>) -> ([R; N], Faults),
    ) -> ServoOutput<R, N> {
        let (front, world, layers) = (&mut self.front, &mut self.world, &mut self.layers);
        display(&mut self.laws, front, world, layers, frame, sense)
    }
}

/// The display's tick on `world`, its axes sensed by `sense`.
#[inline(always)]
fn display<R: Real, V: World<R, N>, L: PortLayer<R>, const N: usize>(
    laws: &mut Laws<R, N>,
    front: &mut Frontend<R, N>,
    world: &mut V,
    layers: &mut [L; N],
    frame: &SensorFrame<R, N>,
    sense: impl FnOnce(&mut Frontend<R, N>) -> ([R; N], Faults),
) -> ServoOutput<R, N> {
    match laws {
        Laws::Impedance(c) => tick::impedance(front, c, world, layers, frame, sense),
        Laws::Admittance(a) => tick::admittance(front, a, world, layers, frame, sense),
    }
}
