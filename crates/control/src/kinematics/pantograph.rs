//! The five-bar pantograph (the Haply 2DIY): two motors side by side, each
//! turning a proximal link, whose distal links meet at the handle.

use super::{finite, Jointed, Kinematics, KinematicsFault};
use crate::param::{non_negative, positive};
use crate::{ParamError, Real};

/// Motor 1 at the origin and motor 2 at `(d, 0)`, proximal links of
/// length `l` at angles `q1`, `q2` from the x axis, distal links of length
/// `L` meeting at the handle above the motors (the upper of the two circle
/// intersections, `y` growing away from the motors).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pantograph {
    l_m: f32,
    big_l_m: f32,
    d_m: f32,
    /// `|a_1 × a_2|` below this (m²) is a fault: the distal links nearly
    /// aligned, where a bounded force needs unbounded torques.
    det_floor: f32,
}

impl Pantograph {
    /// The linkage with proximal links `l_m`, distal links `big_l_m` and
    /// motors `d_m` apart (m; the links finite and > 0, `d_m` finite and
    /// at least 0). Where the distal links come within `|sin φ| < 0.01`
    /// of lying along one line (the singularity at which the motors lose
    /// hold of the handle), [`Kinematics::forward`] faults.
    pub fn new(l_m: f32, big_l_m: f32, d_m: f32) -> Result<Self, ParamError> {
        let l_m = positive("kinematics.l_m (m)", l_m)?;
        let big_l_m = positive("kinematics.big_l_m (m)", big_l_m)?;
        let d_m = non_negative("kinematics.d_m (m)", d_m)?;
        Ok(Pantograph {
            l_m,
            big_l_m,
            d_m,
            det_floor: 0.01 * big_l_m * big_l_m,
        })
    }
}

impl<R: Real> Kinematics<R, 2> for Pantograph {
    // (Inlined into the servo's tick: out of line, the pose returns
    // through memory, about 30 of the board tick's instructions.)
    #[inline(always)]
    fn forward(&self, q: &[R; 2]) -> Result<Jointed<R, 2>, KinematicsFault> {
        finite(q)?;
        let (l, big_l, d) = (R::of(self.l_m), R::of(self.big_l_m), R::of(self.d_m));
        let ((s1, c1), (s2, c2)) = (q[0].sin_cos(), q[1].sin_cos());
        // The distal joints.
        let (p1x, p1y) = (l * c1, l * s1);
        let (p2x, p2y) = (d + l * c2, l * s2);
        let (dx, dy) = (p2x - p1x, p2y - p1y);
        let dist2 = dx * dx + dy * dy;
        let dist = dist2.sqrt();
        let two = R::ONE + R::ONE;
        // Equal distal links: the handle is above the midpoint, `h` along
        // the normal to the line between the joints.
        let h2 = big_l * big_l - dist2 / (two * two);
        // (NaN fails both comparisons, as an unreachable pose.)
        let reachable = h2 > R::ZERO && dist > R::ZERO;
        if !reachable {
            return Err(KinematicsFault::Unreachable);
        }
        let h = h2.sqrt();
        // The upper intersection: the normal (-dy, dx)/dist when the
        // second joint lies to the right of the first.
        let (nx, ny) = (-dy / dist, dx / dist);
        let x = [p1x + dx / two + h * nx, p1y + dy / two + h * ny];
        // J by differentiating the loop closure: the handle x satisfies
        // |x - p_i|² = L², so (x - p_i)·(ẋ - ṗ_i) = 0 for each i, with
        // ṗ_1 = l (-s1, c1) q1' and ṗ_2 = l (-s2, c2) q2'.
        let (a1x, a1y) = (x[0] - p1x, x[1] - p1y);
        let (a2x, a2y) = (x[0] - p2x, x[1] - p2y);
        let det = a1x * a2y - a1y * a2x;
        // Written as a clearance, as every check here is: the designer
        // runs this code over a whole box of poses, where a comparison
        // holds if it may hold, and a box that may be clear must go on.
        let clear_of_singularity = det.abs() >= R::of(self.det_floor);
        if !clear_of_singularity {
            return Err(KinematicsFault::Singular);
        }
        // Rows of A = [a1; a2], right-hand sides b_i = a_i·ṗ_i per unit q_i'.
        let b1 = l * (a1y * c1 - a1x * s1);
        let b2 = l * (a2y * c2 - a2x * s2);
        // ẋ = A^-1 diag(b1, b2) q'.
        let inv = [[a2y / det, -a1y / det], [-a2x / det, a1x / det]];
        Ok(Jointed {
            position_m: x,
            jacobian: [
                [inv[0][0] * b1, inv[0][1] * b2],
                [inv[1][0] * b1, inv[1][1] * b2],
            ],
        })
    }
}
