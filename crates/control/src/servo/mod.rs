//! One control tick of either display, as the board runs it and the
//! simulator runs it: sensors in, law, VE, safety layer, held actuator force
//! out.

mod axes;
mod gains;
mod layer;

pub use axes::{AxesFrame, AxesOutput, AxesServo};
pub use gains::{AdmittanceGains, Display, Gains, GainsError, ImpedanceGains};
pub use layer::{Direct, PortLayer};

use crate::coupling::{AdmittanceCoupling, AdmittanceStep, ImpedanceCoupling, ImpedanceStep};
use crate::estimator::FirstDifference;
use crate::regulator::PositionRegulator;
use crate::safety::{Faults, SafeForce, SafetyConfig, SafetyInputs, SafetyLayer};
use crate::ve::VirtualEnvironment;
use crate::{Encoder, EncoderError, Integrator, ParamError, Position, Real};

/// The sensors of one tick.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SensorFrame<R = f32> {
    /// Timer tick number (must increase by one every tick).
    pub tick: u32,
    /// Raw hardware encoder counter.
    pub encoder_raw: u32,
    /// Load-cell force on the handle along +x (N); only the admittance
    /// display reads it.
    pub load_cell_n: R,
    /// Dead-man switch closed (operator present).
    pub dead_man_closed: bool,
}

impl<R> SensorFrame<R> {
    /// Tick `tick`'s encoder count and load-cell force (N), with the
    /// dead-man switch closed: the operator holds the handle.
    pub const fn held(tick: u32, encoder_raw: u32, load_cell_n: R) -> Self {
        SensorFrame {
            tick,
            encoder_raw,
            load_cell_n,
            dead_man_closed: true,
        }
    }
}

/// The result of one tick.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ServoOutput<R = f32> {
    /// Force to hold on the actuator (N), after the safety layer; positive
    /// resists positive actuator motion (the paper's `f_a`).
    pub actuator_force_n: R,
    /// What the law asked for before the safety layer (N).
    pub commanded_force_n: R,
    /// Actuator position from the encoder.
    pub position: Position,
    /// First-difference actuator velocity (m/s).
    pub velocity_mps: R,
    /// VE velocity `v_e` (m/s).
    pub ve_velocity_mps: R,
    /// Force on the VE `f_e` (N).
    pub ve_force_n: R,
    /// Force in the virtual coupling (N).
    pub coupling_force_n: R,
    /// Impedance display: the VE point the coupling holds; admittance
    /// display: the position command `x_cmd`.
    pub reference: Position,
    /// Latched faults.
    pub faults: Faults,
    /// Whether the safety layer clipped the force.
    pub limited: bool,
}

/// One axis's sensing: its encoder and velocity estimate.
#[derive(Clone, Copy, Debug)]
struct Axis<R> {
    encoder: Encoder,
    estimator: FirstDifference<R>,
    position: Position,
}

impl<R: Real> Axis<R> {
    fn new(encoder: Encoder, period_s: f32) -> Result<Self, ParamError> {
        let position = encoder.position();
        Ok(Axis {
            estimator: FirstDifference::new_in(period_s, position)?,
            encoder,
            position,
        })
    }

    /// Read the encoder's `raw` count; returns the velocity and the sensor
    /// faults.
    #[inline(always)]
    fn sense(&mut self, raw: u32) -> (R, Faults) {
        let mut faults = Faults::NONE;
        match self.encoder.update(raw) {
            Ok(p) => self.position = p,
            Err(_) => faults = Faults::ENCODER_INVALID,
        }
        (self.estimator.step(self.position), faults)
    }
}

/// The faults of a load-cell reading `f_c` (N) on a cell of range
/// `max_n` (N).
#[inline(always)]
fn load_cell_faults<R: Real>(f_c: R, max_n: f32) -> Faults {
    if !f_c.is_finite() {
        Faults::SENSOR_NOT_FINITE
    } else if f_c.abs() > R::of(max_n) {
        Faults::SENSOR_OUT_OF_RANGE
    } else {
        Faults::NONE
    }
}

/// Encoder, velocity estimate and safety layer: the part both displays share.
#[derive(Clone, Copy, Debug)]
struct Frontend<R> {
    axis: Axis<R>,
    safety: SafetyLayer<R>,
}

impl<R: Real> Frontend<R> {
    fn new(encoder: Encoder, safety: SafetyConfig) -> Result<Self, ParamError> {
        Ok(Frontend {
            axis: Axis::new(encoder, safety.period_s)?,
            safety: SafetyLayer::new_in(safety)?,
        })
    }

    /// Read the encoder; returns the velocity and the sensor faults.
    #[inline(always)]
    fn sense(&mut self, frame: &SensorFrame<R>) -> (R, Faults) {
        self.axis.sense(frame.encoder_raw)
    }

    /// Whether the laws may run this tick.
    fn runnable(&self, sensor_faults: Faults) -> bool {
        sensor_faults.is_empty() && self.safety.faults().is_empty()
    }

    /// The safety layer's answer to the law's `command_n` (N).
    // (Always inlined, as the layer's step is: out of line, the answer
    // passes through memory, 15 of the board tick's instructions.)
    #[inline(always)]
    fn limit(
        &mut self,
        frame: &SensorFrame<R>,
        v: R,
        faults: Faults,
        command_n: R,
    ) -> SafeForce<R> {
        self.safety.step(
            &SafetyInputs {
                tick: frame.tick,
                dead_man_closed: frame.dead_man_closed,
                velocity_mps: v,
                sensor_faults: faults,
            },
            command_n,
        )
    }
}

/// The admittance display's laws: coupling, velocity-to-position command
/// and position regulator.
#[derive(Clone, Copy, Debug)]
struct AdmittanceLaws<R> {
    coupling: AdmittanceCoupling<R>,
    command: Integrator<R>,
    regulator: PositionRegulator<R>,
}

impl<R: Real> AdmittanceLaws<R> {
    fn new(g: AdmittanceGains, period_s: f32, x: Position) -> Result<Self, ParamError> {
        Ok(AdmittanceLaws {
            coupling: AdmittanceCoupling::new_in(g.m_kg, g.b_nspm, period_s)?,
            command: Integrator::new_in(period_s, x),
            regulator: PositionRegulator::new_in(g.kp_npm, g.bp_nspm, period_s)?,
        })
    }

    fn gains(&self) -> AdmittanceGains {
        let (kp_npm, bp_nspm) = self.regulator.gains();
        let (m_kg, b_nspm) = self.coupling.gains();
        AdmittanceGains {
            kp_npm,
            bp_nspm,
            m_kg,
            b_nspm,
        }
    }

    /// All the gains change or, on an error, none do.
    fn set_gains(&mut self, g: AdmittanceGains) -> Result<(), ParamError> {
        let (mut coupling, mut regulator) = (self.coupling, self.regulator);
        coupling.set_gains(g.m_kg, g.b_nspm)?;
        regulator.set_gains(g.kp_npm, g.bp_nspm)?;
        (self.coupling, self.regulator) = (coupling, regulator);
        Ok(())
    }

    /// Re-align to the device at `x`.
    fn reset(&mut self, x: Position) {
        self.coupling.reset();
        self.command.reset(x);
        self.regulator.reset();
    }
}

fn impedance_gains<R: Real>(c: &ImpedanceCoupling<R>) -> ImpedanceGains {
    let (k_npm, b_nspm) = c.gains();
    ImpedanceGains { k_npm, b_nspm }
}

#[derive(Clone, Copy, Debug)]
enum Laws<R> {
    Impedance(ImpedanceCoupling<R>),
    Admittance(AdmittanceLaws<R>),
}

/// The laws a servo runs, to read their gains and z-domain forms.
#[derive(Clone, Copy, Debug)]
pub enum LawsRef<'a, R> {
    /// The impedance display's coupling `Z_cI`.
    Impedance(&'a ImpedanceCoupling<R>),
    /// The admittance display's coupling `Z_cA` and regulator `K_p`.
    Admittance {
        /// `Z_cA`.
        coupling: &'a AdmittanceCoupling<R>,
        /// `K_p`.
        regulator: &'a PositionRegulator<R>,
    },
}

/// A haptic display's servo, either display (impedance, paper Fig. 5:
/// measure motion, command force through `Z_cI`; admittance, Fig. 6:
/// measure force, command motion through `Z_cA`, the velocity integrated to
/// a position command and the regulator `K_p`), computing in `R` (`f32` on
/// the board, `f64` in the simulator on request).
///
/// A servo starts disabled: it outputs zero force until [`Servo::enable`],
/// then ramps in. Any fault latches zero force until [`Servo::clear`].
///
/// Between the device's port and the laws sits a [`PortLayer`] `L`:
/// [`Direct`] (nothing) unless [`Servo::with_layer`] puts a passivity
/// controller there.
#[derive(Clone, Copy, Debug)]
pub struct Servo<V, R = f32, L = Direct> {
    front: Frontend<R>,
    laws: Laws<R>,
    ve: V,
    layer: L,
}

impl<V: VirtualEnvironment> Servo<V> {
    /// A disabled f32 servo running `gains`' display.
    ///
    /// # Examples
    ///
    /// ```
    /// use twoport_control::servo::{ImpedanceGains, SensorFrame, Servo};
    /// use twoport_control::ve::BilateralConstraint;
    /// use twoport_control::{Encoder, Position, SafetyConfig};
    /// let enc = Encoder::new(16, 1_000_000, 0, Position::ZERO).unwrap(); // 1 µm counts
    /// let ve = BilateralConstraint::new(Position::ZERO);
    /// let gains = ImpedanceGains { k_npm: 51_000.0, b_nspm: 90.0 };
    /// let mut servo = Servo::new(gains.into(), enc, SafetyConfig::new(1e-3, 200.0, 100.0), ve)?;
    /// let frame = |tick| SensorFrame { tick, encoder_raw: 0, load_cell_n: 0.0, dead_man_closed: true };
    /// // Disabled: zero force. Enabled, it ramps in.
    /// assert_eq!(servo.tick(&frame(0)).actuator_force_n, 0.0);
    /// servo.enable().unwrap();
    /// assert!(servo.tick(&frame(1)).actuator_force_n.is_finite());
    /// # Ok::<(), twoport_control::ParamError>(())
    /// ```
    pub fn new(
        gains: Gains,
        encoder: Encoder,
        safety: SafetyConfig,
        ve: V,
    ) -> Result<Self, ParamError> {
        Self::new_in(gains, encoder, safety, ve)
    }
}

impl<V: VirtualEnvironment<R>, R: Real> Servo<V, R> {
    /// [`Servo::new`] computing in `R`.
    pub fn new_in(
        gains: Gains,
        encoder: Encoder,
        safety: SafetyConfig,
        ve: V,
    ) -> Result<Self, ParamError> {
        let t = safety.period_s;
        let front = Frontend::new(encoder, safety)?;
        let laws = match gains {
            Gains::Impedance(g) => {
                Laws::Impedance(ImpedanceCoupling::new_in(g.k_npm, g.b_nspm, t)?)
            }
            Gains::Admittance(g) => {
                Laws::Admittance(AdmittanceLaws::new(g, t, front.axis.position)?)
            }
        };
        let mut s = Servo {
            front,
            laws,
            ve,
            layer: Direct,
        };
        s.realign();
        Ok(s)
    }
}

impl<V: VirtualEnvironment<R>, R: Real, L: PortLayer<R>> Servo<V, R, L> {
    /// This servo with `layer` between the device's port and its laws;
    /// refused when the layer serves the other display.
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
    /// let gains = ImpedanceGains { k_npm: 51_000.0, b_nspm: 90.0 };
    /// let servo = Servo::new(gains.into(), enc, SafetyConfig::new(1e-3, 200.0, 100.0), ve)?;
    /// let pc = SeriesDamper::new(PassivityLimits::for_device(0.7, 1e-3, 200.0)?)?;
    /// let servo = servo.with_layer(pc).unwrap();
    /// assert_eq!(servo.layer().damping_nspm(), 0.0);
    /// # Ok::<(), twoport_control::ParamError>(())
    /// ```
    pub fn with_layer<M: PortLayer<R>>(self, layer: M) -> Result<Servo<V, R, M>, GainsError> {
        if let Some(d) = layer.display() {
            if d != self.display() {
                return Err(GainsError::WrongDisplay {
                    servo: self.display(),
                    gains: d,
                });
            }
        }
        let mut s = Servo {
            front: self.front,
            laws: self.laws,
            ve: self.ve,
            layer,
        };
        let x = s.front.axis.position;
        s.layer.reset(x);
        Ok(s)
    }

    /// The layer between the device's port and the laws.
    pub fn layer(&self) -> &L {
        &self.layer
    }

    /// The layer, to change it between ticks.
    pub fn layer_mut(&mut self) -> &mut L {
        &mut self.layer
    }

    /// Enable force output (ramping in), re-aligning the laws to the device
    /// if it was disabled. Refused while a fault is latched.
    pub fn enable(&mut self) -> Result<(), Faults> {
        if !self.front.safety.faults().is_empty() {
            return Err(self.front.safety.faults());
        }
        if !self.front.safety.is_enabled() {
            self.realign();
        }
        self.front.safety.enable()
    }

    /// Disable force output.
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

    /// Calibrate the encoder: where the device is now reads as `position`
    /// from this tick on (homing's result), and the laws re-align to it.
    /// Meant for a disabled servo; an enabled one would see its position
    /// jump.
    pub fn calibrate(&mut self, position: Position) {
        self.front.axis.encoder.rezero(position);
        self.front.axis.position = position;
        self.realign();
    }

    /// Latch a fault found outside the tick (e.g. by the link).
    pub fn trip(&mut self, f: Faults) {
        self.front.safety.trip(f);
    }

    /// New safety limits, while disabled (see [`SafetyLayer::reconfigure`]).
    pub fn set_limits(&mut self, cfg: SafetyConfig) -> Result<(), ParamError> {
        self.front.safety.reconfigure(cfg)
    }

    /// The safety layer (limits, latched faults, thermal state).
    pub fn safety(&self) -> &SafetyLayer<R> {
        &self.front.safety
    }

    /// The virtual environment.
    pub fn ve(&self) -> &V {
        &self.ve
    }

    /// The virtual environment, to change it between ticks.
    pub fn ve_mut(&mut self) -> &mut V {
        &mut self.ve
    }

    /// The current actuator position.
    pub fn position(&self) -> Position {
        self.front.axis.position
    }

    /// The display this servo runs.
    pub fn display(&self) -> Display {
        match self.laws {
            Laws::Impedance(_) => Display::Impedance,
            Laws::Admittance(_) => Display::Admittance,
        }
    }

    /// The laws, for their gains and z-domain forms.
    pub fn laws(&self) -> LawsRef<'_, R> {
        match &self.laws {
            Laws::Impedance(c) => LawsRef::Impedance(c),
            Laws::Admittance(a) => LawsRef::Admittance {
                coupling: &a.coupling,
                regulator: &a.regulator,
            },
        }
    }

    /// The gains in force.
    pub fn gains(&self) -> Gains {
        match &self.laws {
            Laws::Impedance(c) => Gains::Impedance(impedance_gains(c)),
            Laws::Admittance(a) => Gains::Admittance(a.gains()),
        }
    }

    /// Change the gains between ticks. All of them change or, on an error,
    /// none do.
    pub fn set_gains(&mut self, gains: Gains) -> Result<(), GainsError> {
        match (&mut self.laws, gains) {
            (Laws::Impedance(c), Gains::Impedance(g)) => Ok(c.set_gains(g.k_npm, g.b_nspm)?),
            (Laws::Admittance(a), Gains::Admittance(g)) => Ok(a.set_gains(g)?),
            _ => Err(GainsError::WrongDisplay {
                servo: self.display(),
                gains: gains.display(),
            }),
        }
    }

    fn realign(&mut self) {
        let x = self.front.axis.position;
        self.front.axis.estimator.reset(x);
        if let Laws::Admittance(a) = &mut self.laws {
            a.reset(x);
        }
        self.ve.reset(x);
        self.layer.reset(x);
    }

    /// Calibrate from an index pulse: the counter read `raw` at `position`
    /// (see [`Encoder::rezero_at`]); the laws re-align to where the device
    /// is now. Refused, changing nothing, for a raw value the counter
    /// cannot hold.
    pub fn calibrate_at(&mut self, raw: u32, position: Position) -> Result<(), EncoderError> {
        let now = self.front.axis.encoder.rezero_at(raw, position)?;
        self.front.axis.position = now;
        self.realign();
        Ok(())
    }

    /// One control tick with `law` in place of the display's laws and the
    /// VE: the same encoder, velocity estimate and safety layer, so every
    /// limit and fault check holds for it too. `law` gets the position and
    /// the velocity (m/s) and answers with the actuator force (N, the
    /// paper's `f_a`: positive resists positive motion); it is not called
    /// on a faulted tick. Homing runs through this.
    pub fn tick_with(
        &mut self,
        frame: &SensorFrame<R>,
        law: impl FnOnce(Position, R) -> R,
    ) -> ServoOutput<R> {
        let (v, faults) = self.front.sense(frame);
        let command_n = if self.front.runnable(faults) {
            law(self.front.axis.position, v)
        } else {
            R::ZERO
        };
        let safe = self.front.limit(frame, v, faults, command_n);
        ServoOutput {
            actuator_force_n: safe.force_n,
            commanded_force_n: command_n,
            position: self.front.axis.position,
            velocity_mps: v,
            ve_velocity_mps: R::ZERO,
            ve_force_n: R::ZERO,
            coupling_force_n: R::ZERO,
            reference: self.front.axis.position,
            faults: safe.faults,
            limited: safe.limited,
        }
    }

    /// One control tick.
    pub fn tick(&mut self, frame: &SensorFrame<R>) -> ServoOutput<R> {
        let (front, ve, layer) = (&mut self.front, &mut self.ve, &mut self.layer);
        match &mut self.laws {
            Laws::Impedance(c) => impedance_tick(front, c, ve, layer, frame),
            Laws::Admittance(a) => admittance_tick(front, a, ve, layer, frame),
        }
    }
}

// The impedance display's tick is the board's hot path: inlined into
// `tick`, with the admittance display's kept out of line on the board so
// that its registers do not crowd the impedance tick (the M4F tick count).
// On the host, with registers to spare, both inline.
#[inline(always)]
fn impedance_tick<R: Real, V: VirtualEnvironment<R>, L: PortLayer<R>>(
    front: &mut Frontend<R>,
    coupling: &mut ImpedanceCoupling<R>,
    ve: &mut V,
    layer: &mut L,
    frame: &SensorFrame<R>,
) -> ServoOutput<R> {
    let (v, faults) = front.sense(frame);
    let runnable = front.runnable(faults);
    let (s, command_n) = if runnable {
        let x = front.axis.position;
        let (x_e, v_e) = layer.element_motion(x, v);
        let s = coupling.step(x_e, v_e, ve);
        (s, layer.impedance_force(x, v, s.force_n))
    } else {
        (ImpedanceStep::default(), R::ZERO)
    };
    let safe = front.limit(frame, v, faults, command_n);
    if runnable {
        layer.held(safe.force_n);
    }
    ServoOutput {
        actuator_force_n: safe.force_n,
        commanded_force_n: command_n,
        position: front.axis.position,
        velocity_mps: v,
        ve_velocity_mps: s.ve_velocity_mps,
        ve_force_n: s.force_n,
        coupling_force_n: s.force_n,
        reference: ve.position(),
        faults: safe.faults,
        limited: safe.limited,
    }
}

#[cfg_attr(target_arch = "arm", inline(never))]
fn admittance_tick<R: Real, V: VirtualEnvironment<R>, L: PortLayer<R>>(
    front: &mut Frontend<R>,
    laws: &mut AdmittanceLaws<R>,
    ve: &mut V,
    layer: &mut L,
    frame: &SensorFrame<R>,
) -> ServoOutput<R> {
    let (v, faults) = front.sense(frame);
    let f_c = frame.load_cell_n;
    let faults = faults.with(load_cell_faults(
        f_c,
        front.safety.config().max_sensor_force_n,
    ));
    let (s, command_n) = if front.runnable(faults) {
        let s = laws.coupling.step(f_c, ve);
        let v_cmd = layer.admittance_velocity(f_c, s.velocity_mps);
        let x_cmd = laws.command.step_unsplit(v_cmd);
        (s, laws.regulator.step(front.axis.position, x_cmd))
    } else {
        (AdmittanceStep::default(), R::ZERO)
    };
    let safe = front.limit(frame, v, faults, command_n);
    ServoOutput {
        actuator_force_n: safe.force_n,
        commanded_force_n: command_n,
        position: front.axis.position,
        velocity_mps: v,
        ve_velocity_mps: s.velocity_mps,
        ve_force_n: s.ve_force_n,
        coupling_force_n: s.coupling_force_n,
        reference: laws.command.position(),
        faults: safe.faults,
        limited: safe.limited,
    }
}
