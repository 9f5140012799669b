//! A shipped linkage's kinematics in f32, as the board runs them, for a
//! simulation of any joint count: the device file's geometry, and the
//! Cartesian origin moved to where the scene's world starts.

use twoport_control::kinematics::{
    Capstan, Delta, Jointed, Kinematics, KinematicsFault, Pantograph, SerialArm,
};
use twoport_design::linkage::Geometry;

/// The file's kinematics, whatever its kind.
#[derive(Clone, Copy, Debug)]
pub enum AnyKinematics {
    /// 1 joint.
    Capstan(Capstan),
    /// 2 joints.
    Pantograph(Pantograph),
    /// 3 joints.
    SerialArm(SerialArm),
    /// 3 joints.
    Delta(Delta),
}

/// [`AnyKinematics`] with the handle's position measured from `origin_m`.
#[derive(Clone, Copy, Debug)]
pub struct Shifted {
    /// The kinematics.
    pub kinematics: AnyKinematics,
    /// Where the Cartesian frame's zero is, in the kinematics' (m).
    pub origin_m: [f32; 3],
}

impl AnyKinematics {
    /// The geometry's kinematics in f32, or why its lengths are refused.
    pub fn new(g: &Geometry) -> Result<Self, String> {
        let f = |x: f64| x as f32;
        let bad = |e: twoport_control::ParamError| e.to_string();
        Ok(match *g {
            Geometry::Capstan {
                r_h_m,
                r_p_m,
                r_s_m,
            } => Self::Capstan(Capstan::new(f(r_h_m), f(r_p_m), f(r_s_m)).map_err(bad)?),
            Geometry::Pantograph { l_m, big_l_m, d_m } => {
                Self::Pantograph(Pantograph::new(f(l_m), f(big_l_m), f(d_m)).map_err(bad)?)
            }
            Geometry::SerialArm { l1_m, l2_m } => {
                Self::SerialArm(SerialArm::new(f(l1_m), f(l2_m)).map_err(bad)?)
            }
            Geometry::Delta {
                base_m,
                effector_m,
                upper_m,
                lower_m,
            } => Self::Delta(
                Delta::new(f(base_m), f(effector_m), f(upper_m), f(lower_m)).map_err(bad)?,
            ),
        })
    }

    /// The joints it has.
    pub fn joints(&self) -> usize {
        match self {
            Self::Capstan(_) => 1,
            Self::Pantograph(_) => 2,
            Self::SerialArm(_) | Self::Delta(_) => 3,
        }
    }
}

/// `k`'s answer at `q` for `M` joints, as an answer for `N` (the same
/// count: a simulation checks it).
fn through<K: Kinematics<f32, M>, const M: usize, const N: usize>(
    k: &K,
    q: &[f32; N],
) -> Result<Jointed<f32, N>, KinematicsFault> {
    let q: [f32; M] = q[..].try_into().map_err(|_| KinematicsFault::NotFinite)?;
    let j = k.forward(&q)?;
    if M != N {
        return Err(KinematicsFault::NotFinite);
    }
    Ok(Jointed {
        position_m: core::array::from_fn(|i| j.position_m[i]),
        jacobian: core::array::from_fn(|r| core::array::from_fn(|c| j.jacobian[r][c])),
    })
}

impl<const N: usize> Kinematics<f32, N> for Shifted {
    fn forward(&self, q: &[f32; N]) -> Result<Jointed<f32, N>, KinematicsFault> {
        let mut j = match &self.kinematics {
            AnyKinematics::Capstan(k) => through::<_, 1, N>(k, q),
            AnyKinematics::Pantograph(k) => through::<_, 2, N>(k, q),
            AnyKinematics::SerialArm(k) => through::<_, 3, N>(k, q),
            AnyKinematics::Delta(k) => through::<_, 3, N>(k, q),
        }?;
        for (x, o) in j.position_m.iter_mut().zip(self.origin_m) {
            *x -= o;
        }
        Ok(j)
    }
}
