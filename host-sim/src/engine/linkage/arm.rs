//! A linkage as a simulated device: the nonlinear plant, its joint
//! encoders counted as the board counts them, and its handle.
//!
//! The scenes' loop, processor-in-the-loop and the tests each stand on
//! this one arm: they differ only in what turns its counts into torques.

use super::plant::{HandForce, LinkagePlant};
use crate::Error;
use twoport_board::linkage::COUNTER_BITS;
use twoport_control::kinematics::Kinematics;
use twoport_control::linkage::{Hardware, LinkageError, LinkageServo};
use twoport_control::servo::Gains;
use twoport_control::world::World;
use twoport_control::SafetyConfig;
use twoport_design::linkage::LinkageFile;

/// A linkage's plant and the encoders on its joints.
#[derive(Clone, Debug)]
pub struct LinkageArm<const N: usize> {
    /// The nonlinear joint-space dynamics and state.
    pub plant: LinkagePlant,
    /// The encoders, transmissions, limits and motors (the board's f32).
    pub hardware: Hardware<N>,
    /// Joint angles where each counter reads 0 (rad).
    zero_rad: [f64; N],
}

impl<const N: usize> LinkageArm<N> {
    /// The linkage `file` at rest at `q0_rad`, each counter reading 0
    /// there; no gravity, no friction until asked for on the plant.
    pub fn at_rest(file: &LinkageFile, q0_rad: [f64; N]) -> Result<Self, Error> {
        let hardware = file.hardware::<N>().ok_or(Error::Joints {
            file: file.geometry.joints(),
            run: N,
        })?;
        let plant = LinkagePlant::at_rest(file, &q0_rad);
        plant.kinematics(&plant.q)?;
        Ok(LinkageArm {
            plant,
            hardware,
            zero_rad: q0_rad,
        })
    }

    /// Joint angles where each counter reads 0 (rad).
    pub fn zero_rad(&self) -> [f64; N] {
        self.zero_rad
    }

    /// The board's servo on this arm, disabled: `kinematics`, each joint's
    /// encoder (on the board's counter) reading the arm's zero pose where
    /// its counter reads 0, the
    /// file's joint limits and motors, and the given gains, limits and
    /// world.
    pub fn servo<K: Kinematics<f32, N>, W: World<f32, N>>(
        &self,
        kinematics: K,
        gains: [Gains; N],
        safety: [SafetyConfig; N],
        world: W,
    ) -> Result<LinkageServo<K, W, f32, N>, LinkageError> {
        let zero = self.zero_rad.map(|q| q as f32);
        LinkageServo::on(
            kinematics,
            &self.hardware,
            COUNTER_BITS,
            zero,
            gains,
            safety,
            world,
        )
    }

    /// Each joint's counter now: the angle from its zero in whole counts
    /// (rounded, as a quadrature encoder's edges fall), on a 32-bit
    /// counter that wraps.
    pub fn counts(&self) -> [u32; N] {
        core::array::from_fn(|i| {
            let per_rad = f64::from(self.hardware.counts_per_joint_rev(i)) / std::f64::consts::TAU;
            let c = ((self.plant.q[i] - self.zero_rad[i]) * per_rad).round();
            c as i64 as i32 as u32
        })
    }

    /// The handle's position (m) and velocity (m/s), in the kinematics'
    /// frame.
    pub fn handle(&self) -> Result<([f64; N], [f64; N]), Error> {
        let (x, j) = self.plant.kinematics(&self.plant.q)?;
        let v = &j * &self.plant.qd;
        Ok((
            core::array::from_fn(|i| x[i]),
            core::array::from_fn(|i| v[i]),
        ))
    }

    /// Advance one period `dt_s` (s) in `substeps` Runge-Kutta steps, the
    /// motors holding `torque_nm` (N m, resisting) and the hand's force
    /// on the handle given by `hand`.
    pub fn step(
        &mut self,
        torque_nm: &[f64; N],
        hand: &HandForce,
        dt_s: f64,
        substeps: u32,
    ) -> Result<(), Error> {
        self.plant.step_with(torque_nm, hand, dt_s, substeps)
    }
}
