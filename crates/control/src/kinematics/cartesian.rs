//! One linear motor per axis: the identity.

use super::{finite, Jointed, Kinematics, KinematicsFault};
use crate::Real;

/// A Cartesian device: each "joint" is its axis's position (m), and the
/// Jacobian is the identity (so its unit is m/m here, not m/rad).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Cartesian;

impl<R: Real, const N: usize> Kinematics<R, N> for Cartesian {
    // (Inlined into the servo's tick: out of line, the pose returns
    // through memory, about 30 of the board tick's instructions.)
    #[inline(always)]
    fn forward(&self, q: &[R; N]) -> Result<Jointed<R, N>, KinematicsFault> {
        finite(q)?;
        Ok(Jointed {
            position_m: *q,
            jacobian: core::array::from_fn(|i| {
                core::array::from_fn(|j| if i == j { R::ONE } else { R::ZERO })
            }),
        })
    }
}
