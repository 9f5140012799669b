//! Each axis's sensing and laws: encoder and velocity estimate, and the
//! display's coupling (with the admittance display's command integrator
//! and position regulator).

use super::{AdmittanceGains, Display, Gains, GainsError, ImpedanceGains};
use crate::coupling::{AdmittanceCoupling, ImpedanceCoupling};
use crate::estimator::FirstDifference;
use crate::regulator::PositionRegulator;
use crate::safety::{AxisError, Faults};
use crate::{Encoder, Integrator, ParamError, Position, Real};

/// One axis's sensing: its encoder and velocity estimate.
#[derive(Clone, Copy, Debug)]
pub(super) struct Axis<R> {
    pub(super) encoder: Encoder,
    pub(super) estimator: FirstDifference<R>,
    pub(super) position: Position,
}

impl<R: Real> Axis<R> {
    pub(super) fn new(encoder: Encoder, period_s: f32) -> Result<Self, ParamError> {
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
    pub(super) fn sense(&mut self, raw: u32) -> (R, Faults) {
        let mut faults = Faults::NONE;
        match self.encoder.update(raw) {
            Ok(p) => self.position = p,
            Err(_) => faults = Faults::ENCODER_INVALID,
        }
        (self.estimator.step(self.position), faults)
    }

    /// Take the position `x` found by other means (a linkage's
    /// kinematics); returns the velocity.
    #[inline(always)]
    pub(super) fn sense_at(&mut self, x: Position) -> R {
        self.position = x;
        self.estimator.step(x)
    }
}

/// The faults of a load-cell reading `f_c` (N) on a cell of range
/// `max_n` (N).
#[inline(always)]
pub(super) fn load_cell_faults<R: Real>(f_c: R, max_n: f32) -> Faults {
    if !f_c.is_finite() {
        Faults::SENSOR_NOT_FINITE
    } else if f_c.abs() > R::of(max_n) {
        Faults::SENSOR_OUT_OF_RANGE
    } else {
        Faults::NONE
    }
}

/// The admittance display's laws on one axis: coupling,
/// velocity-to-position command and position regulator.
#[derive(Clone, Copy, Debug)]
pub(super) struct AdmittanceLaws<R> {
    pub(super) coupling: AdmittanceCoupling<R>,
    pub(super) command: Integrator<R>,
    pub(super) regulator: PositionRegulator<R>,
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
    pub(super) fn reset(&mut self, x: Position) {
        self.coupling.reset();
        self.command.reset(x);
        self.regulator.reset();
    }
}

/// Every axis's laws: all axes run one display.
#[derive(Clone, Copy, Debug)]
pub(super) enum Laws<R, const N: usize> {
    Impedance([ImpedanceCoupling<R>; N]),
    Admittance([AdmittanceLaws<R>; N]),
}

/// One axis's laws, to read their gains and z-domain forms.
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

impl<R: Real, const N: usize> Laws<R, N> {
    /// Each axis's laws for its `gains`, the device at `x`; the error names
    /// the first axis that is wrong, or whose display differs from axis
    /// 0's.
    pub(super) fn new(
        gains: &[Gains; N],
        x: &[Position; N],
        period_s: f32,
    ) -> Result<Self, AxisError<GainsError>> {
        one_display(gains)?;
        let at = |axis| move |e: ParamError| AxisError::new(axis, GainsError::Param(e));
        // Each axis's law is first the placeholder built for axis 0 and is
        // then replaced by its own.
        Ok(match gains[0] {
            Gains::Impedance(g) => {
                let first =
                    ImpedanceCoupling::new_in(g.k_npm, g.b_nspm, period_s).map_err(at(0))?;
                let mut c = [first; N];
                for (i, (c, g)) in c.iter_mut().zip(gains).enumerate() {
                    if let Gains::Impedance(g) = g {
                        c.set_gains(g.k_npm, g.b_nspm).map_err(at(i))?;
                    }
                }
                Laws::Impedance(c)
            }
            Gains::Admittance(g) => {
                let first = AdmittanceLaws::new(g, period_s, x[0]).map_err(at(0))?;
                let mut laws = [first; N];
                for (i, (l, g)) in laws.iter_mut().zip(gains).enumerate() {
                    if let Gains::Admittance(g) = g {
                        *l = AdmittanceLaws::new(*g, period_s, x[i]).map_err(at(i))?;
                    }
                }
                Laws::Admittance(laws)
            }
        })
    }

    pub(super) fn display(&self) -> Display {
        match self {
            Laws::Impedance(_) => Display::Impedance,
            Laws::Admittance(_) => Display::Admittance,
        }
    }

    pub(super) fn get(&self, axis: usize) -> Option<LawsRef<'_, R>> {
        Some(match self {
            Laws::Impedance(c) => LawsRef::Impedance(c.get(axis)?),
            Laws::Admittance(a) => {
                let a = a.get(axis)?;
                LawsRef::Admittance {
                    coupling: &a.coupling,
                    regulator: &a.regulator,
                }
            }
        })
    }

    pub(super) fn gains(&self) -> [Gains; N] {
        core::array::from_fn(|i| match self {
            Laws::Impedance(c) => {
                let (k_npm, b_nspm) = c[i].gains();
                Gains::Impedance(ImpedanceGains { k_npm, b_nspm })
            }
            Laws::Admittance(a) => Gains::Admittance(a[i].gains()),
        })
    }

    /// Every axis's gains change or, on an error (naming the axis), none
    /// do.
    pub(super) fn set_gains(&mut self, gains: [Gains; N]) -> Result<(), AxisError<GainsError>> {
        let mut laws = *self;
        let servo = self.display();
        for (axis, g) in gains.into_iter().enumerate() {
            let at = |error| AxisError::new(axis, error);
            match (&mut laws, g) {
                (Laws::Impedance(c), Gains::Impedance(g)) => c[axis]
                    .set_gains(g.k_npm, g.b_nspm)
                    .map_err(|e| at(e.into()))?,
                (Laws::Admittance(a), Gains::Admittance(g)) => {
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
        *self = laws;
        Ok(())
    }
}

/// The display every axis of `gains` runs, or the first axis that differs
/// from axis 0.
fn one_display<const N: usize>(gains: &[Gains; N]) -> Result<Display, AxisError<GainsError>> {
    let Some(first) = gains.first().map(Gains::display) else {
        return Err(AxisError::new(
            0,
            GainsError::Param(ParamError {
                name: "axes",
                value: 0.0,
                problem: "must be at least one",
            }),
        ));
    };
    match gains.iter().position(|g| g.display() != first) {
        None => Ok(first),
        Some(axis) => Err(AxisError::new(
            axis,
            GainsError::WrongDisplay {
                servo: first,
                gains: gains[axis].display(),
            },
        )),
    }
}
