//! One control tick of each display, as the board runs it and the simulator
//! runs it: sensors in, law, VE, safety layer, held actuator force out.

use crate::coupling::{AdmittanceCoupling, ImpedanceCoupling};
use crate::estimator::FirstDifference;
use crate::regulator::PositionRegulator;
use crate::safety::{Faults, SafetyConfig, SafetyInputs, SafetyLayer};
use crate::ve::VirtualEnvironment;
use crate::{Encoder, Integrator, ParamError, Position};

/// The sensors of one tick.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SensorFrame {
    /// Timer tick number (must increase by one every tick).
    pub tick: u32,
    /// Raw hardware encoder counter.
    pub encoder_raw: u32,
    /// Load-cell force on the handle along +x (N); only the admittance
    /// display reads it.
    pub load_cell_n: f32,
    /// Dead-man switch closed (operator present).
    pub dead_man_closed: bool,
}

/// The result of one tick.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ServoOutput {
    /// Force to hold on the actuator (N), after the safety layer; positive
    /// resists positive actuator motion (the paper's `f_a`).
    pub actuator_force_n: f32,
    /// What the law asked for before the safety layer (N).
    pub commanded_force_n: f32,
    /// Actuator position from the encoder.
    pub position: Position,
    /// First-difference actuator velocity (m/s).
    pub velocity_mps: f32,
    /// VE velocity `v_e` (m/s).
    pub ve_velocity_mps: f32,
    /// Force on the VE `f_e` (N).
    pub ve_force_n: f32,
    /// Force in the virtual coupling (N).
    pub coupling_force_n: f32,
    /// Impedance display: the coupling's VE-side position; admittance
    /// display: the position command `x_cmd`.
    pub reference: Position,
    /// Latched faults.
    pub faults: Faults,
    /// Whether the safety layer clipped the force.
    pub limited: bool,
}

/// Encoder, velocity estimate and safety layer: the part both displays share.
#[derive(Clone, Copy, Debug)]
struct Frontend {
    encoder: Encoder,
    estimator: FirstDifference,
    safety: SafetyLayer,
    position: Position,
}

impl Frontend {
    fn new(encoder: Encoder, safety: SafetyConfig) -> Result<Self, ParamError> {
        let position = encoder.position();
        Ok(Frontend {
            estimator: FirstDifference::new(safety.period_s, position)?,
            safety: SafetyLayer::new(safety)?,
            encoder,
            position,
        })
    }

    /// Read the encoder; returns the velocity and the sensor faults.
    fn sense(&mut self, frame: &SensorFrame) -> (f32, Faults) {
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

    fn finish(&mut self, frame: &SensorFrame, v: f32, faults: Faults, out: &mut ServoOutput) {
        let safe = self.safety.step(
            &SafetyInputs {
                tick: frame.tick,
                dead_man_closed: frame.dead_man_closed,
                velocity_mps: v,
                sensor_faults: faults,
            },
            out.commanded_force_n,
        );
        out.actuator_force_n = safe.force_n;
        out.faults = safe.faults;
        out.limited = safe.limited;
        out.position = self.position;
        out.velocity_mps = v;
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
        pub fn safety(&self) -> &SafetyLayer {
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
pub struct ImpedanceServo<V> {
    front: Frontend,
    coupling: ImpedanceCoupling,
    ve: V,
}

impl<V: VirtualEnvironment> ImpedanceServo<V> {
    /// A disabled servo with coupling gains `k_npm` (N/m), `b_nspm` (N s/m).
    pub fn new(
        k_npm: f32,
        b_nspm: f32,
        encoder: Encoder,
        safety: SafetyConfig,
        ve: V,
    ) -> Result<Self, ParamError> {
        let front = Frontend::new(encoder, safety)?;
        let coupling = ImpedanceCoupling::new(k_npm, b_nspm, safety.period_s, front.position)?;
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
    pub fn coupling(&self) -> &ImpedanceCoupling {
        &self.coupling
    }

    /// Change the coupling gains between ticks.
    pub fn set_gains(&mut self, k_npm: f32, b_nspm: f32) -> Result<(), ParamError> {
        self.coupling.set_gains(k_npm, b_nspm)
    }

    fn realign(&mut self) {
        let x = self.front.position;
        self.front.estimator.reset(x);
        self.coupling.reset(x);
        self.ve.reset(x);
    }

    /// One control tick.
    pub fn tick(&mut self, frame: &SensorFrame) -> ServoOutput {
        let (v, faults) = self.front.sense(frame);
        let mut out = ServoOutput::default();
        if self.front.runnable(faults) {
            let s = self.coupling.step(self.front.position, v, &mut self.ve);
            out.commanded_force_n = s.force_n;
            out.coupling_force_n = s.force_n;
            out.ve_force_n = s.force_n;
            out.ve_velocity_mps = s.ve_velocity_mps;
        }
        out.reference = self.coupling.ve_side();
        self.front.finish(frame, v, faults, &mut out);
        out
    }
}

/// The admittance display (paper Fig. 6): measure force, command motion,
/// through the mass-damper coupling `Z_cA`, the velocity integrated to a
/// position command and the regulator `K_p`.
#[derive(Clone, Copy, Debug)]
pub struct AdmittanceServo<V> {
    front: Frontend,
    coupling: AdmittanceCoupling,
    command: Integrator,
    regulator: PositionRegulator,
    ve: V,
}

impl<V: VirtualEnvironment> AdmittanceServo<V> {
    /// A disabled servo with regulator `kp_npm`, `bp_nspm` and coupling
    /// `m_kg`, `b_nspm`.
    pub fn new(
        (kp_npm, bp_nspm): (f32, f32),
        (m_kg, b_nspm): (f32, f32),
        encoder: Encoder,
        safety: SafetyConfig,
        ve: V,
    ) -> Result<Self, ParamError> {
        let t = safety.period_s;
        let front = Frontend::new(encoder, safety)?;
        let mut s = AdmittanceServo {
            command: Integrator::new(t, front.position),
            coupling: AdmittanceCoupling::new(m_kg, b_nspm, t)?,
            regulator: PositionRegulator::new(kp_npm, bp_nspm, t)?,
            front,
            ve,
        };
        s.realign();
        Ok(s)
    }

    servo_controls!();

    /// The coupling (gains, z-domain form).
    pub fn coupling(&self) -> &AdmittanceCoupling {
        &self.coupling
    }

    /// The position regulator (gains, z-domain form).
    pub fn regulator(&self) -> &PositionRegulator {
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
    pub fn tick(&mut self, frame: &SensorFrame) -> ServoOutput {
        let (v, mut faults) = self.front.sense(frame);
        let f_c = frame.load_cell_n;
        if !f_c.is_finite() {
            faults = faults.with(Faults::SENSOR_NOT_FINITE);
        } else if f_c.abs() > self.front.safety.config().max_sensor_force_n {
            faults = faults.with(Faults::SENSOR_OUT_OF_RANGE);
        }
        let mut out = ServoOutput::default();
        if self.front.runnable(faults) {
            let s = self.coupling.step(f_c, &mut self.ve);
            self.command.step(s.velocity_mps);
            out.commanded_force_n = self.regulator.step(self.front.position, &self.command);
            out.coupling_force_n = s.coupling_force_n;
            out.ve_force_n = s.ve_force_n;
            out.ve_velocity_mps = s.velocity_mps;
        }
        out.reference = self.command.position();
        self.front.finish(frame, v, faults, &mut out);
        out
    }
}
