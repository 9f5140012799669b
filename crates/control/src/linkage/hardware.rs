//! A linkage's drive train as its board holds it: the encoders, the
//! transmissions, the joints' limits and the motors.

use super::{JointEncoder, JointLimits, LinkageError, MotorConfig};

/// A linkage's `N` joints as the board drives them (f32, as it runs).
///
/// One value serves the board's image, the simulator's model of the
/// same encoders, and the servo built on them
/// ([`LinkageServo::on`](super::LinkageServo::on)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hardware<const N: usize> {
    /// Encoder counts per motor revolution (quadrature).
    pub counts_per_rev: f32,
    /// Each joint's transmission ratio (motor turns per joint turn).
    pub ratios: [f32; N],
    /// Each joint's limits (rad), as the proof covered them.
    pub limits_rad: JointLimits<N>,
    /// Each motor's largest torque at any instant, at the motor (N m).
    pub peak_torque_nm: f32,
    /// Each motor's largest torque held indefinitely, at the motor (N m).
    pub continuous_torque_nm: f32,
}

impl<const N: usize> Hardware<N> {
    /// Encoder counts per turn of `joint` (the motor's counts times the
    /// transmission ratio).
    pub fn counts_per_joint_rev(&self, joint: usize) -> f32 {
        self.counts_per_rev * self.ratios[joint]
    }

    /// Each joint's encoder on a `bits`-wide counter that reads
    /// `zero_rad[i]` (rad) where it counts 0.
    pub fn encoders(
        &self,
        bits: u8,
        zero_rad: [f32; N],
    ) -> Result<[JointEncoder; N], LinkageError> {
        let mut out = [None; N];
        for (i, slot) in out.iter_mut().enumerate() {
            let e = JointEncoder::new(bits, self.counts_per_joint_rev(i), 0, zero_rad[i])
                .map_err(|e| LinkageError::Joint(i, e))?;
            *slot = Some(e);
        }
        Ok(out.map(|e| e.expect("every joint was built")))
    }

    /// Each motor's limits at its joint (after the transmission).
    pub fn motors(&self) -> [MotorConfig; N] {
        self.ratios
            .map(|n| MotorConfig::new(self.peak_torque_nm * n, self.continuous_torque_nm * n))
    }
}
