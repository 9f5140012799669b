//! Device kinematics: from the motors' joint angles to the handle's
//! Cartesian position, and from a Cartesian handle force to the motors'
//! torques through the Jacobian's transpose.
//!
//! The coupling, the VE and the designer's proof live in Cartesian space;
//! a linkage (a pantograph, a serial arm, a delta) or a capstan drive sits
//! between them and the motors. Each device kind implements
//! [`Kinematics`], and [`Cartesian`] is the identity for the devices with
//! one linear motor per axis.
//!
//! Conventions: joint angles `q` in rad at the motor shafts (after any
//! transmission, see each kind), handle positions in m, the Jacobian
//! `J = ∂x/∂q` in m/rad, forces in N, torques in N m. A pose the device
//! cannot reach, or one so near a singularity that a bounded handle force
//! would need an unbounded torque, is a [`KinematicsFault`]: the servo
//! answers it with zero force.

mod capstan;
mod cartesian;
mod delta;
mod pantograph;
mod serial_arm;

pub use capstan::Capstan;
pub use cartesian::Cartesian;
pub use delta::Delta;
pub use pantograph::Pantograph;
pub use serial_arm::SerialArm;

use crate::Real;

/// Why a pose has no usable kinematics.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum KinematicsFault {
    /// The joint angles put the handle where the linkage cannot close (a
    /// pantograph whose distal joints are further apart than its two
    /// outer links reach).
    Unreachable,
    /// `|det J|` below the kind's floor: near a singularity, where the
    /// torques for a bounded force grow without bound.
    Singular,
    /// A joint angle that is not finite.
    NotFinite,
    /// A joint beyond the limits the proof of the gains covered.
    OutsideLimits,
}

/// The handle's position and the Jacobian at one pose.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Jointed<R, const N: usize> {
    /// Handle position (m).
    pub position_m: [R; N],
    /// `J[i][j] = ∂x_i/∂q_j` (m/rad).
    pub jacobian: [[R; N]; N],
}

impl<R: Real, const N: usize> Jointed<R, N> {
    /// The joint torques (N m) that put the handle force `force_n` (N) on
    /// the hand: `τ = J^T f`, by virtual work.
    pub fn torques_nm(&self, force_n: &[R; N]) -> [R; N] {
        core::array::from_fn(|j| {
            let mut t = R::ZERO;
            for (row, f) in self.jacobian.iter().zip(force_n) {
                t += row[j] * *f;
            }
            t
        })
    }

    /// The handle velocity (m/s) at joint rates `rate_radps` (rad/s):
    /// `v = J q'`.
    pub fn velocity_mps(&self, rate_radps: &[R; N]) -> [R; N] {
        core::array::from_fn(|i| {
            let mut v = R::ZERO;
            for (j, r) in self.jacobian[i].iter().zip(rate_radps) {
                v += *j * *r;
            }
            v
        })
    }
}

/// A device's kinematics over `N` joints and `N` Cartesian axes.
pub trait Kinematics<R: Real, const N: usize> {
    /// The handle's position and the Jacobian at joint angles `q_rad`.
    fn forward(&self, q_rad: &[R; N]) -> Result<Jointed<R, N>, KinematicsFault>;
}

/// `Err(NotFinite)` where any angle is NaN or infinite.
#[inline(always)]
fn finite<R: Real, const N: usize>(q: &[R; N]) -> Result<(), KinematicsFault> {
    // `x · 0` is 0 for a finite x and NaN for an infinite or NaN one: one
    // multiply-add an angle, where testing each angle's bits is four
    // instructions and a branch on the board.
    let zero = q.iter().fold(R::ZERO, |acc, x| acc + *x * R::ZERO);
    if zero == R::ZERO {
        Ok(())
    } else {
        Err(KinematicsFault::NotFinite)
    }
}

#[cfg(test)]
mod tests;
