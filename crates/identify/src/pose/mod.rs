//! A linkage at one pose: the mass and damping matrices the hand feels
//! there, `M_x` and `D_x` (kg, N s/m, Cartesian), from one experiment per
//! axis.
//!
//! At a pose, for small motions, a rigid linkage is `M_x x'' + D_x x' = f`
//! at the handle, `f` the motors' force `J^-T τ` as the board commands it.
//! Its axes are coupled: a push along `x` moves the handle along `y` and
//! `z` too. One experiment excites one axis while the board's hold pushes
//! back on every axis, so the force is a vector in every experiment. With
//! one experiment per axis, at each harmonic the averaged positions and
//! forces stack into square matrices, `X = H F`, and `H = X F^-1` is the
//! response matrix, measured in closed loop against the forces the
//! motors were asked for ([`PoseMeasured`]).
//!
//! The fit ([`fit`]) is the symmetric `M_x` and `D_x` whose exact
//! sampled response (zero-order hold, [`response::sampled`]) matches `H`
//! at every harmonic, each entry weighted by its measured variance. The
//! parameters' covariance bounds it, and [`PoseFit::span`] gives the
//! models at the edges of that bound: the poses a robust design proves.
//!
//! What the fit leaves out: the joints' Coulomb friction (a nonlinear
//! force the linear model sees as damping at low harmonics), the
//! Coriolis terms (second order in the speed) and how `M_x` changes over
//! the few millimetres the handle moves. Each shows in the misfit, which
//! widens the bound; past [`fit::MOST_MISFIT`] the records are refused.
//!
//! Where the joints stick, [`losses`] takes the damping from sines played
//! at several levels: the energy each period dissipates gives every
//! joint's viscous damping and Coulomb friction, and
//! [`JointLosses::damping_nspm`] the damping at the handle; [`fit::mass`]
//! gives `M_x` from the same sines.

pub mod fit;
pub mod losses;
mod measured;
pub mod response;

/// The Cartesian axes' names in a pose's record files.
pub const AXES: [&str; 3] = ["x", "y", "z"];

/// The file that keeps axis `axis`'s record of the experiment that
/// pushed axis `pushed`, in a folder of one level's experiments:
/// `PUSHED-AXIS.csv` (`x-y.csv`: the push along `x`, the record of `y`).
/// None past the three Cartesian axes.
pub fn record_file(pushed: usize, axis: usize) -> Option<String> {
    Some(format!("{}-{}.csv", AXES.get(pushed)?, AXES.get(axis)?))
}

pub use fit::PoseFit;
pub use losses::JointLosses;
pub use measured::PoseMeasured;
