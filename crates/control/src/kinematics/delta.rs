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
    /// `lower_m²` (m²).
    lower_sq_m2: f32,
    /// `|det A|` below this (m³) is a fault: 1% of `lower_m³`.
    det_floor_m3: f32,
}

/// `sin 120°`: the second and third legs' directions are `(-1/2, ±H)`.
const H: f32 = 0.866_025_4;

/// Leg `i`'s direction (0°, 120°, 240° about the base's axis) times `len`,
/// in x and y; the first leg's y is an exact zero.
#[inline(always)]
fn along<R: Real>(i: usize, len: R) -> [R; 2] {
    match i {
        0 => [len, R::ZERO],
        1 => [-R::HALF * len, R::of(H) * len],
        _ => [-R::HALF * len, -R::of(H) * len],
    }
}

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
            lower_sq_m2: lower_m * lower_m,
            det_floor_m3: 0.01 * lower_m * lower_m * lower_m,
        })
    }
}

fn sub<R: Real>(a: &[R; 3], b: &[R; 3]) -> [R; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot<R: Real>(a: &[R; 3], b: &[R; 3]) -> R {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross<R: Real>(a: &[R; 3], b: &[R; 3]) -> [R; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

impl<R: Real> Kinematics<R, 3> for Delta {
    #[inline(always)]
    fn forward(&self, q: &[R; 3]) -> Result<Jointed<R, 3>, KinematicsFault> {
        finite(q)?;
        let (r, a) = (R::of(self.offset_m), R::of(self.upper_m));
        // Each elbow (the upper arm's end) is `ρ_i = r + a cos q_i` from the
        // base's axis along its leg, and `a sin q_i` below the base.
        // (Written out: `map`'s closure stays out of line on the board.)
        let sc = [q[0].sin_cos(), q[1].sin_cos(), q[2].sin_cos()];
        let rho = [r + a * sc[0].1, r + a * sc[1].1, r + a * sc[2].1];
        let e: [[R; 3]; 3] = core::array::from_fn(|i| {
            let [x, y] = along(i, rho[i]);
            [x, y, -a * sc[i].0]
        });
        // The handle is where three spheres of radius b about the elbows
        // meet. Their differences are two planes, `d_j · p = w_j` with
        // `d_j = e_j - e_1` and `w_j = (|e_j|² - |e_1|²) / 2`, which is
        // `r (ρ_j - ρ_1)`. The planes give x and y as lines in z; the first
        // sphere then gives z, and the handle is the lower root.
        let (d2, d3) = (sub(&e[1], &e[0]), sub(&e[2], &e[0]));
        let (w2, w3) = (r * (rho[1] - rho[0]), r * (rho[2] - rho[0]));
        let den = d2[0] * d3[1] - d2[1] * d3[0];
        // (A NaN or zero determinant fails the comparison too: the planes
        // vertical, which the joint limits keep away.)
        let planes_cross = den.abs() > R::ZERO;
        if !planes_cross {
            return Err(KinematicsFault::Singular);
        }
        let inv = R::ONE / den;
        // x = x0 + xz z and y = y0 + yz z, less the first elbow.
        let x0 = (w2 * d3[1] - w3 * d2[1]) * inv - e[0][0];
        let xz = (d3[2] * d2[1] - d2[2] * d3[1]) * inv;
        let y0 = (d2[0] * w3 - d3[0] * w2) * inv;
        let yz = (d3[0] * d2[2] - d2[0] * d3[2]) * inv;
        // (x0 + xz z)² + (y0 + yz z)² + (z - e1_z)² = b².
        let qa = xz * xz + yz * yz + R::ONE;
        let qb = x0 * xz + y0 * yz - e[0][2];
        let qc = x0 * x0 + y0 * y0 + e[0][2] * e[0][2] - R::of(self.lower_sq_m2);
        let disc = qb * qb - qa * qc;
        let legs_meet = disc >= R::ZERO;
        if !legs_meet {
            return Err(KinematicsFault::Unreachable);
        }
        let z = (-qb - disc.sqrt()) / qa;
        let p = [x0 + xz * z + e[0][0], y0 + yz * z, z];
        // Differentiating each closure, (p - e_i)·(ṗ - ė_i) = 0: with A's
        // rows r_i = (p - e_i)^T and β_i = r_i · ∂e_i/∂q_i, A ṗ = diag(β) q̇,
        // so J = A^-1 diag(β), and A^-1's columns are r_2 × r_3, r_3 × r_1
        // and r_1 × r_2 over det A.
        let r = e.map(|e| sub(&p, &e));
        let cols = [
            cross(&r[1], &r[2]),
            cross(&r[2], &r[0]),
            cross(&r[0], &r[1]),
        ];
        let det = dot(&r[0], &cols[0]);
        // |det A| against b³: the parallelograms nearly in one plane.
        let clear_of_singularity = det.abs() >= R::of(self.det_floor_m3);
        if !clear_of_singularity {
            return Err(KinematicsFault::Singular);
        }
        // ∂e_i/∂q_i is `-a sin q_i` along the leg and `-a cos q_i` in z.
        let scale: [R; 3] = core::array::from_fn(|j| {
            let [x, y] = along(j, sc[j].0);
            -a * (r[j][0] * x + r[j][1] * y + r[j][2] * sc[j].1) / det
        });
        let jacobian = core::array::from_fn(|i| core::array::from_fn(|j| cols[j][i] * scale[j]));
        Ok(Jointed {
            position_m: p,
            jacobian,
        })
    }
}
