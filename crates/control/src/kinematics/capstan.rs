//! A one-axis capstan or sector drive (the Hapkit, the haptic paddles):
//! the motor's pulley drives a sector that carries the handle.

use super::{finite, Jointed, Kinematics, KinematicsFault};
use crate::param::positive;
use crate::{ParamError, Real};

/// A sector of radius `r_s` driven by a motor pulley of radius `r_p`,
/// with the handle `r_h` from the sector's axis. The joint is the motor
/// shaft's angle; the handle's position is the arc `x = r_h θ_s`, with the
/// sector turning `θ_s = θ_m r_p / r_s`, so the motor torque for a handle
/// force `F` is `τ = r_h r_p / r_s F`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Capstan {
    /// `r_h r_p / r_s` (m/rad): metres of handle per radian of motor.
    ratio_m_per_rad: f32,
}

impl Capstan {
    /// The drive with handle radius `r_h_m`, pulley radius `r_p_m` and
    /// sector radius `r_s_m` (m, each finite and > 0).
    pub fn new(r_h_m: f32, r_p_m: f32, r_s_m: f32) -> Result<Self, ParamError> {
        let r_h_m = positive("kinematics.r_h_m (m)", r_h_m)?;
        let r_p_m = positive("kinematics.r_p_m (m)", r_p_m)?;
        let r_s_m = positive("kinematics.r_s_m (m)", r_s_m)?;
        Ok(Capstan {
            ratio_m_per_rad: r_h_m * r_p_m / r_s_m,
        })
    }

    /// Metres of handle travel per radian of motor.
    pub fn ratio_m_per_rad(&self) -> f32 {
        self.ratio_m_per_rad
    }
}

impl<R: Real> Kinematics<R, 1> for Capstan {
    // (Inlined into the servo's tick: out of line, the pose returns
    // through memory, about 30 of the board tick's instructions.)
    #[inline(always)]
    fn forward(&self, q: &[R; 1]) -> Result<Jointed<R, 1>, KinematicsFault> {
        finite(q)?;
        let r = R::of(self.ratio_m_per_rad);
        Ok(Jointed {
            position_m: [r * q[0]],
            jacobian: [[r]],
        })
    }
}
