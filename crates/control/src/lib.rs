//! # twoport-control
//!
//! The discrete control laws of a haptic display, written once and run
//! unchanged on the board (Cortex-M4F) and in the simulator: `no_std`, no
//! allocation, f32, every `step` bounded and panic-free.
//!
//! The laws are those of Adams & Hannaford (2002), "Control law design for
//! haptic interfaces to virtual reality":
//!
//! | law | paper | type |
//! | --- | --- | --- |
//! | encoder unwrapping | sec. IV-A | [`Encoder`] |
//! | first-difference velocity | Fig. 5 | [`FirstDifference`] |
//! | impedance-display coupling `Z_cI` | eq 20, Fig. 7(a)(b) | [`ImpedanceCoupling`] |
//! | admittance-display coupling `Z_cA` | eq 21, Fig. 7(c)(d) | [`AdmittanceCoupling`] |
//! | velocity-to-position command `T/(1 - z^-1)` | Fig. 6 | [`Integrator`] |
//! | position regulator `K_p` | eq 30 | [`PositionRegulator`] |
//! | VEs: cursor mass, wall, bilateral constraint | sec. V-C | [`ve`] |
//! | limits, guards, watchdog, latch, ramp-in | | [`SafetyLayer`] |
//! | a whole tick of each display | Figs. 5, 6 | [`ImpedanceServo`], [`AdmittanceServo`] |
//! | measuring a law's response (test aid) | | [`SineProbe`] |
//!
//! Every linear law exposes its z-domain form ([`ZTransfer`], through a
//! `tf()` method) so the designer evaluates exactly what runs here; the unit
//! tests drive each law with sinusoids and match that form.
//!
//! Units are SI throughout (N, m, s, kg); positions are integer nanometres
//! ([`Position`]) so that no position ever accumulates f32 rounding.
//! Sign convention (the paper's, see `docs/two-port.md`):
//! the actuator force is positive when it resists positive actuator motion;
//! forces on the VE and all velocities are positive along +x.

#![no_std]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

#[cfg(test)]
extern crate std;

pub mod coupling;
mod encoder;
mod estimator;
mod param;
mod position;
mod probe;
mod real;
mod regulator;
pub mod safety;
pub mod servo;
mod tf;
pub mod ve;

#[cfg(test)]
mod response_tests;

pub use coupling::{AdmittanceCoupling, ImpedanceCoupling};
pub use encoder::{Encoder, EncoderError};
pub use estimator::FirstDifference;
pub use num_complex::Complex64;
pub use param::ParamError;
pub use position::{Integrator, Position, NM_PER_M};
pub use probe::SineProbe;
pub use real::Real;
pub use regulator::PositionRegulator;
pub use safety::{Faults, SafetyConfig, SafetyLayer};
pub use servo::{AdmittanceServo, ImpedanceServo, SensorFrame, ServoOutput};
pub use tf::ZTransfer;
