//! One control tick of each display, as the board runs it and the simulator
//! runs it: sensors in, law, VE, safety layer, held actuator force out.

use crate::coupling::{AdmittanceCoupling, AdmittanceStep, ImpedanceCoupling, ImpedanceStep};
use crate::estimator::FirstDifference;
use crate::regulator::PositionRegulator;
use crate::safety::{Faults, SafeForce, SafetyConfig, SafetyInputs, SafetyLayer};
use crate::ve::VirtualEnvironment;
use crate::{Encoder, Integrator, ParamError, Position, Real};

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

/// Encoder, velocity estimate and safety layer: the part both displays share.
#[derive(Clone, Copy, Debug)]
struct Frontend<R> {
    encoder: Encoder,
    estimator: FirstDifference<R>,
    safety: SafetyLayer<R>,
    position: Position,
}

impl<R: Real> Frontend<R> {
    fn new(encoder: Encoder, safety: SafetyConfig) -> Result<Self, ParamError> {
        let position = encoder.position();
        Ok(Frontend {
            estimator: FirstDifference::new_in(safety.period_s, position)?,
            safety: SafetyLayer::new_in(safety)?,
            encoder,
            position,
        })
    }

    /// Read the encoder; returns the velocity and the sensor faults.
    fn sense(&mut self, frame: &SensorFrame<R>) -> (R, Faults) {
        let mut faults = Faults::NONE;
        match self.encoder.update(frame.encoder_raw) {
            Ok(p) => self.position = p,
            Err(_) => faults = Faults::ENCODER_INVALID,
        }
        (self.estimator.step(self.position), faults)
    }

    /// Whether the laws may run this tick.
    fn runnable(&self, sensor_faults: Faults) -> bool {
        sensor_faults.is_empty() && self.safety.faults().is_empty()
    }

    /// The safety layer's answer to the law's `command_n` (N).
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

macro_rules! servo_controls {
    () => {
        /// Enable force output (ramping in), re-aligning the laws to the
        /// device if it was disabled. Refused while a fault is latched.
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

        /// Latch a fault found outside the tick (e.g. by the link).
        pub fn trip(&mut self, f: Faults) {
            self.front.safety.trip(f);
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
            self.front.position
        }
    };
}

/// The impedance display (paper Fig. 5): measure motion, command force,
/// through the spring-damper coupling `Z_cI` to the VE.
#[derive(Clone, Copy, Debug)]
pub struct ImpedanceServo<V, R = f32> {
    front: Frontend<R>,
    coupling: ImpedanceCoupling<R>,
    ve: V,
}

impl<V: VirtualEnvironment> ImpedanceServo<V> {
    /// A disabled servo with coupling gains `k_npm` (N/m), `b_nspm` (N s/m).
    ///
    /// # Examples
    ///
    /// ```
    /// use twoport_control::ve::BilateralConstraint;
    /// use twoport_control::{Encoder, ImpedanceServo, Position, SafetyConfig, SensorFrame};
    /// let enc = Encoder::new(16, 1_000_000, 0, Position::ZERO).unwrap(); // 1 µm counts
    /// let ve = BilateralConstraint::new(Position::ZERO);
    /// let mut servo = ImpedanceServo::new(51_000.0, 90.0, enc, SafetyConfig::new(1e-3, 200.0, 100.0), ve)?;
    /// let frame = |tick| SensorFrame { tick, encoder_raw: 0, load_cell_n: 0.0, dead_man_closed: true };
    /// // Disabled: zero force. Enabled, it ramps in.
    /// assert_eq!(servo.tick(&frame(0)).actuator_force_n, 0.0);
    /// servo.enable().unwrap();
    /// assert!(servo.tick(&frame(1)).actuator_force_n.is_finite());
    /// # Ok::<(), twoport_control::ParamError>(())
    /// ```
    pub fn new(
        k_npm: f32,
        b_nspm: f32,
        encoder: Encoder,
        safety: SafetyConfig,
        ve: V,
    ) -> Result<Self, ParamError> {
        Self::new_in(k_npm, b_nspm, encoder, safety, ve)
    }
}

impl<V: VirtualEnvironment<R>, R: Real> ImpedanceServo<V, R> {
    /// [`ImpedanceServo::new`] computing in `R`.
    pub fn new_in(
        k_npm: f32,
        b_nspm: f32,
        encoder: Encoder,
        safety: SafetyConfig,
        ve: V,
    ) -> Result<Self, ParamError> {
        let front = Frontend::new(encoder, safety)?;
        let coupling = ImpedanceCoupling::new_in(k_npm, b_nspm, safety.period_s)?;
        let mut s = ImpedanceServo {
            front,
            coupling,
            ve,
        };
        s.realign();
        Ok(s)
    }

    servo_controls!();

    /// The coupling (gains, z-domain form).
    pub fn coupling(&self) -> &ImpedanceCoupling<R> {
        &self.coupling
    }

    /// Change the coupling gains between ticks.
    pub fn set_gains(&mut self, k_npm: f32, b_nspm: f32) -> Result<(), ParamError> {
        self.coupling.set_gains(k_npm, b_nspm)
    }

    fn realign(&mut self) {
        let x = self.front.position;
        self.front.estimator.reset(x);
        self.ve.reset(x);
    }

    /// One control tick.
    pub fn tick(&mut self, frame: &SensorFrame<R>) -> ServoOutput<R> {
        let (v, faults) = self.front.sense(frame);
        let s = if self.front.runnable(faults) {
            self.coupling.step(self.front.position, v, &mut self.ve)
        } else {
            ImpedanceStep::default()
        };
        let safe = self.front.limit(frame, v, faults, s.force_n);
        ServoOutput {
            actuator_force_n: safe.force_n,
            commanded_force_n: s.force_n,
            position: self.front.position,
            velocity_mps: v,
            ve_velocity_mps: s.ve_velocity_mps,
            ve_force_n: s.force_n,
            coupling_force_n: s.force_n,
            reference: self.ve.position(),
            faults: safe.faults,
            limited: safe.limited,
        }
    }
}

/// The admittance display (paper Fig. 6): measure force, command motion,
/// through the mass-damper coupling `Z_cA`, the velocity integrated to a
/// position command and the regulator `K_p`.
#[derive(Clone, Copy, Debug)]
pub struct AdmittanceServo<V, R = f32> {
    front: Frontend<R>,
    coupling: AdmittanceCoupling<R>,
    command: Integrator<R>,
    regulator: PositionRegulator<R>,
    ve: V,
}

impl<V: VirtualEnvironment> AdmittanceServo<V> {
    /// A disabled servo with regulator `kp_npm`, `bp_nspm` and coupling
    /// `m_kg`, `b_nspm`.
    pub fn new(
        regulator: (f32, f32),
        coupling: (f32, f32),
        encoder: Encoder,
        safety: SafetyConfig,
        ve: V,
    ) -> Result<Self, ParamError> {
        Self::new_in(regulator, coupling, encoder, safety, ve)
    }
}

impl<V: VirtualEnvironment<R>, R: Real> AdmittanceServo<V, R> {
    /// [`AdmittanceServo::new`] computing in `R`.
    pub fn new_in(
        (kp_npm, bp_nspm): (f32, f32),
        (m_kg, b_nspm): (f32, f32),
        encoder: Encoder,
        safety: SafetyConfig,
        ve: V,
    ) -> Result<Self, ParamError> {
        let t = safety.period_s;
        let front = Frontend::new(encoder, safety)?;
        let mut s = AdmittanceServo {
            command: Integrator::new_in(t, front.position),
            coupling: AdmittanceCoupling::new_in(m_kg, b_nspm, t)?,
            regulator: PositionRegulator::new_in(kp_npm, bp_nspm, t)?,
            front,
            ve,
        };
        s.realign();
        Ok(s)
    }

    servo_controls!();

    /// The coupling (gains, z-domain form).
    pub fn coupling(&self) -> &AdmittanceCoupling<R> {
        &self.coupling
    }

    /// The position regulator (gains, z-domain form).
    pub fn regulator(&self) -> &PositionRegulator<R> {
        &self.regulator
    }

    /// Change the coupling gains between ticks.
    pub fn set_coupling_gains(&mut self, m_kg: f32, b_nspm: f32) -> Result<(), ParamError> {
        self.coupling.set_gains(m_kg, b_nspm)
    }

    /// Change the regulator gains between ticks.
    pub fn set_regulator_gains(&mut self, kp_npm: f32, bp_nspm: f32) -> Result<(), ParamError> {
        self.regulator.set_gains(kp_npm, bp_nspm)
    }

    fn realign(&mut self) {
        let x = self.front.position;
        self.front.estimator.reset(x);
        self.coupling.reset();
        self.command.reset(x);
        self.regulator.reset();
        self.ve.reset(x);
    }

    /// One control tick.
    pub fn tick(&mut self, frame: &SensorFrame<R>) -> ServoOutput<R> {
        let (v, mut faults) = self.front.sense(frame);
        let f_c = frame.load_cell_n;
        if !f_c.is_finite() {
            faults = faults.with(Faults::SENSOR_NOT_FINITE);
        } else if f_c.abs() > R::of(self.front.safety.config().max_sensor_force_n) {
            faults = faults.with(Faults::SENSOR_OUT_OF_RANGE);
        }
        let (s, command_n) = if self.front.runnable(faults) {
            let s = self.coupling.step(f_c, &mut self.ve);
            let x_cmd = self.command.step_unsplit(s.velocity_mps);
            (s, self.regulator.step(self.front.position, x_cmd))
        } else {
            (AdmittanceStep::default(), R::ZERO)
        };
        let safe = self.front.limit(frame, v, faults, command_n);
        ServoOutput {
            actuator_force_n: safe.force_n,
            commanded_force_n: command_n,
            position: self.front.position,
            velocity_mps: v,
            ve_velocity_mps: s.velocity_mps,
            ve_force_n: s.ve_force_n,
            coupling_force_n: s.coupling_force_n,
            reference: self.command.position(),
            faults: safe.faults,
            limited: safe.limited,
        }
    }
}
