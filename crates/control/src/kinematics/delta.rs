//! The delta with rotary inputs (Clavel's; the Falcon and the Force
//! Dimension deltas are of this kind): three motors on a base, each
//! swinging an upper arm, each arm carrying a parallelogram down to the
//! effector, which stays parallel to the base.

use super::{finite, Jointed, Kinematics, KinematicsFault};
use crate::param::{non_negative, positive};
use crate::{ParamError, Real};

/// The motors sit at angles 0°, 120° and 240° about the base's axis (`z`,
/// up), `base_m` from it; the parallelograms meet the effector
/// `effector_m` from its centre. Each upper arm (`upper_m` long) turns
/// down from the horizontal by its joint angle `q_i`; each parallelogram
/// is `lower_m` long. The handle is the effector's centre, below the base
/// (`z < 0`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Delta {
    /// The base's radius less the effector's (m): the effector folded to
    /// a point, as the parallelograms keep it parallel.
    offset_m: f32,
    upper_m: f32,
    lower_m: f32,
}

/// The legs' directions: cos and sin of 0°, 120°, 240°.
const LEGS: [(f32, f32); 3] = [(1.0, 0.0), (-0.5, 0.866_025_4), (-0.5, -0.866_025_4)];

/// Newton steps of the forward solve (it converges in 4 to 6 from the
/// workspace's centre; more is a pose it cannot reach).
const NEWTON_STEPS: usize = 12;

impl Delta {
    /// The delta with base radius `base_m`, effector radius `effector_m`,
    /// upper arms `upper_m` and parallelograms `lower_m` (m; finite, the
    /// arms > 0, the radii >= 0).
    pub fn new(
        base_m: f32,
        effector_m: f32,
        upper_m: f32,
        lower_m: f32,
    ) -> Result<Self, ParamError> {
        let base_m = non_negative("kinematics.base_m (m)", base_m)?;
        let effector_m = non_negative("kinematics.effector_m (m)", effector_m)?;
        let upper_m = positive("kinematics.upper_m (m)", upper_m)?;
        let lower_m = positive("kinematics.lower_m (m)", lower_m)?;
        Ok(Delta {
            offset_m: base_m - effector_m,
            upper_m,
            lower_m,
        })
    }

    /// Each elbow (the upper arm's end, m) at joint angles `q`, and its
    /// derivative along its own joint (m/rad).
    fn elbows<R: Real>(&self, q: &[R; 3]) -> [([R; 3], [R; 3]); 3] {
        let (r, a) = (R::of(self.offset_m), R::of(self.upper_m));
        core::array::from_fn(|i| {
            let (c, s) = (R::of(LEGS[i].0), R::of(LEGS[i].1));
            let (sq, cq) = q[i].sin_cos();
            let radial = r + a * cq;
            (
                [c * radial, s * radial, -a * sq],
                [-c * a * sq, -s * a * sq, -a * cq],
            )
        })
    }
}

/// `A x = b` for a 3 x 3 `A` by Cramer's rule, with `det A`.
fn solve3<R: Real>(a: &[[R; 3]; 3], b: &[R; 3]) -> ([R; 3], R) {
    let det3 = |m: &[[R; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det3(a);
    let x = core::array::from_fn(|col| {
        let mut m = *a;
        for (row, bi) in m.iter_mut().zip(b) {
            row[col] = *bi;
        }
        det3(&m) / d
    });
    (x, d)
}

impl<R: Real> Kinematics<R, 3> for Delta {
    fn forward(&self, q: &[R; 3]) -> Result<Jointed<R, 3>, KinematicsFault> {
        finite(q)?;
        let elbows = self.elbows(q);
        let (a, b) = (R::of(self.upper_m), R::of(self.lower_m));
        let two = R::ONE + R::ONE;
        // Newton on |p - e_i|² = b², always from the same point on the
        // axis below the base, where the legs' rows are independent.
        let mut p = [R::ZERO, R::ZERO, -(a + b) / two];
        let scale = a + b;
        let mut converged = false;
        let mut rows = [[R::ZERO; 3]; 3];
        for _ in 0..NEWTON_STEPS {
            let mut g = [R::ZERO; 3];
            for (i, (e, _)) in elbows.iter().enumerate() {
                let d = [p[0] - e[0], p[1] - e[1], p[2] - e[2]];
                g[i] = d[0] * d[0] + d[1] * d[1] + d[2] * d[2] - b * b;
                rows[i] = [two * d[0], two * d[1], two * d[2]];
            }
            let (step, det) = solve3(&rows, &g);
            // (A NaN determinant fails the comparison too.)
            let solvable = det.abs() > R::ZERO && step.iter().all(|s| s.is_finite());
            if !solvable {
                return Err(KinematicsFault::Singular);
            }
            for (pi, s) in p.iter_mut().zip(step) {
                *pi = *pi - s;
            }
            let size = step[0].abs() + step[1].abs() + step[2].abs();
            if size < R::of(1e-6) * scale {
                converged = true;
                break;
            }
        }
        if !converged {
            return Err(KinematicsFault::Unreachable);
        }
        // Differentiating each closure, (p - e_i)·(ṗ - ė_i) = 0: with A's
        // rows (p - e_i)^T and β_i = (p - e_i)·∂e_i/∂q_i, A ṗ = diag(β) q̇,
        // so J = A^-1 diag(β).
        let mut a_rows = [[R::ZERO; 3]; 3];
        let mut beta = [R::ZERO; 3];
        for (i, (e, de)) in elbows.iter().enumerate() {
            let d = [p[0] - e[0], p[1] - e[1], p[2] - e[2]];
            a_rows[i] = d;
            beta[i] = d[0] * de[0] + d[1] * de[1] + d[2] * de[2];
        }
        // |det A| against b³: the parallelograms nearly in one plane.
        let floor = R::of(0.01) * b * b * b;
        let mut jacobian = [[R::ZERO; 3]; 3];
        for j in 0..3 {
            let mut rhs = [R::ZERO; 3];
            rhs[j] = beta[j];
            let (col, det) = solve3(&a_rows, &rhs);
            if det.abs() < floor {
                return Err(KinematicsFault::Singular);
            }
            for (row, c) in jacobian.iter_mut().zip(col) {
                row[j] = c;
            }
        }
        Ok(Jointed {
            position_m: p,
            jacobian,
        })
    }
}
