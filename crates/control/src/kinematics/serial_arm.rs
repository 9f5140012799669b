//! The PHANToM-type serial arm: a base turning about the vertical axis and
//! two links driven through a parallelogram, so that the second and third
//! joint angles are absolute (each measured from the horizontal or the
//! vertical, not from the link before).

use super::{finite, Jointed, Kinematics, KinematicsFault};
use crate::param::positive;
use crate::{ParamError, Real};

/// Links `l1` (upper arm) and `l2` (forearm); joint 1 the base's yaw,
/// joint 2 the upper arm's elevation, joint 3 the forearm's angle from
/// the vertical (absolute, through the parallelogram). The handle is at
///
/// ```text
/// x = cos q1 (l1 cos q2 + l2 sin q3)
/// y = sin q1 (l1 cos q2 + l2 sin q3)
/// z = l1 sin q2 - l2 cos q3
/// ```
///
/// (Cavusoglu, Feygin & Tendick 2002, for the PHANToM Premium 1.5; `z`
/// up, the base axis along `z`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SerialArm {
    l1_m: f32,
    l2_m: f32,
    /// `|det J|` below this (m³) is a fault.
    det_floor: f32,
}

impl SerialArm {
    /// The arm with links `l1_m` and `l2_m` (m, finite and > 0). Near a
    /// singularity, where `|det J|` falls below 1% of `l1 l2 (l1 + l2)`
    /// (the handle on the base's axis, or the forearm along the upper
    /// arm), [`Kinematics::forward`] faults.
    pub fn new(l1_m: f32, l2_m: f32) -> Result<Self, ParamError> {
        let l1_m = positive("kinematics.l1_m (m)", l1_m)?;
        let l2_m = positive("kinematics.l2_m (m)", l2_m)?;
        Ok(SerialArm {
            l1_m,
            l2_m,
            det_floor: 0.01 * l1_m * l2_m * (l1_m + l2_m),
        })
    }
}

impl<R: Real> Kinematics<R, 3> for SerialArm {
    // (Inlined into the servo's tick: out of line, the pose returns
    // through memory, about 30 of the board tick's instructions.)
    #[inline(always)]
    fn forward(&self, q: &[R; 3]) -> Result<Jointed<R, 3>, KinematicsFault> {
        finite(q)?;
        let (l1, l2) = (R::of(self.l1_m), R::of(self.l2_m));
        let (s1, c1) = q[0].sin_cos();
        let (s2, c2) = q[1].sin_cos();
        let (s3, c3) = q[2].sin_cos();
        // The handle's distance from the base's axis.
        let reach = l1 * c2 + l2 * s3;
        let jacobian = [
            [-s1 * reach, -c1 * l1 * s2, c1 * l2 * c3],
            [c1 * reach, -s1 * l1 * s2, s1 * l2 * c3],
            [R::ZERO, l1 * c2, l2 * s3],
        ];
        // det J = reach · l1 l2 (s2 s3 + c2 c3) = reach l1 l2 cos(q2 - q3).
        let det = reach * l1 * l2 * (s2 * s3 + c2 * c3);
        // Written as a clearance, as every check here is: the designer
        // runs this code over a whole box of poses, where a comparison
        // holds if it may hold, and a box that may be clear must go on.
        let clear_of_singularity = det.abs() >= R::of(self.det_floor);
        if !clear_of_singularity {
            return Err(KinematicsFault::Singular);
        }
        Ok(Jointed {
            position_m: [c1 * reach, s1 * reach, l1 * s2 - l2 * c3],
            jacobian,
        })
    }
}
