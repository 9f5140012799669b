//! Gravity compensation: the torques that hold a linkage's moving masses
//! up, from the device file's masses (gravity along `-z`).

use crate::kinematics::Jointed;
use crate::Real;

/// What the motors add to hold the moving masses up: the potential
/// energy's gradient `G(q)`, which the servo subtracts from its resisting
/// torques. It acts only while the servo is enabled and no fault is
/// latched, like every other torque.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Gravity {
    /// Nothing compensated.
    #[default]
    Off,
    /// A point mass at the handle: its weight (N), `G = J^T (0, 0, w)`.
    Handle {
        /// The handle's weight, `m g` (N).
        weight_n: f32,
    },
    /// The PHANToM-type arm's links: the upper arm's and the forearm's
    /// first moments of mass times `g` (N m), `G = (0, a cos q2, b sin q3)`.
    SerialArm {
        /// The upper arm's, `g (l1 m_a + l5 m_be + l1 m_c/2)` (N m).
        upper_nm: f32,
        /// The forearm's, `g (l2 m_a/2 + l3 m_c - l6 m_df)` (N m).
        fore_nm: f32,
    },
}

impl Gravity {
    /// `G(q)` at the joint angles `q` (rad) and the pose served there
    /// (N m).
    #[inline(always)]
    pub fn torques_nm<R: Real, const N: usize>(&self, q: &[R; N], pose: &Jointed<R, N>) -> [R; N] {
        let mut g = [R::ZERO; N];
        match *self {
            Gravity::Off => {}
            // (Height is the third axis: a linkage of fewer has none.)
            Gravity::Handle { weight_n } => {
                if let Some(z) = pose.jacobian.get(2) {
                    for (g, row) in g.iter_mut().zip(z) {
                        *g = *row * R::of(weight_n);
                    }
                }
            }
            Gravity::SerialArm { upper_nm, fore_nm } => {
                if let ([_, g2, g3], [_, q2, q3]) = (&mut g[..], &q[..]) {
                    *g2 = R::of(upper_nm) * q2.sin_cos().1;
                    *g3 = R::of(fore_nm) * q3.sin_cos().0;
                }
            }
        }
        g
    }

    /// Whether every value is finite.
    pub fn is_finite(&self) -> bool {
        match *self {
            Gravity::Off => true,
            Gravity::Handle { weight_n } => weight_n.is_finite(),
            Gravity::SerialArm { upper_nm, fore_nm } => upper_nm.is_finite() && fore_nm.is_finite(),
        }
    }
}
