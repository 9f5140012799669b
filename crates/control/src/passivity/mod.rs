//! Time-domain passivity: what a port really exchanged, tick by tick.
//!
//! The designer proves the coupling for a passive virtual environment. What
//! the proof does not cover (an explicitly integrated VE, a wall stiffer
//! than the proven coupling, a delayed loop) can still be watched at run
//! time: an observer books the energy that crossed a port, and a passivity
//! controller dissipates whatever the port put out beyond what it took in.
//!
//! # The pairing that matters
//!
//! A sampled controller holds each force over a whole tick (zero-order
//! hold). The energy a port exchanged over tick `k` is the force *held over
//! that tick* times the displacement *during that tick*:
//!
//! ```text
//! W(k) = Σ_{j<k} f(j) (x(j+1) - x(j))
//! ```
//!
//! Many implementations pair `f(k)` with the backward-difference velocity
//! of the same tick, `(x(k) - x(k-1)) / T`, whose displacement happened
//! while `f(k-1)` was held. For a spring `f = -K x` that sum is, exactly,
//! the spring's energy plus `K/2 Σ Δx²`: never negative, even while the
//! sampled spring pumps energy into a mass and the loop diverges. The
//! correct pairing subtracts that `K/2 Σ Δx²` instead, and sees it.
//! [`EnergyObserver`] books the correct pairing; displacements come from
//! [`Position`](crate::Position) differences in integer nanometres, so they
//! are exact.
//!
//! # Rounding
//!
//! A port's energy is a sum of millions of tiny terms. A plain `f32` sum
//! stops growing once the terms fall below half an ulp of the total, so the
//! observer accumulates with compensated summation ([`CompensatedSum`]):
//! on the M4F that is seven `f32` additions and a comparison per tick in
//! hardware, where an `f64` sum would call the soft-float library.

mod brake;
mod observer;
mod parallel;
mod series;
mod sum;
mod ve_port;

pub(crate) use brake::Brake;
pub use observer::EnergyObserver;
pub use parallel::{ParallelDamper, ParallelLimits};
pub use series::{PassivityLimits, SeriesDamper};
pub use sum::CompensatedSum;
pub use ve_port::PassiveVe;
