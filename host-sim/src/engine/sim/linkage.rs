//! A linkage scene's tick: the device file's nonlinear arm in place of
//! the axes' models, its joint encoders read as the board reads them, the
//! board's linkage servo (a [`SceneServo::Linkage`]) holding its joint
//! torques over the tick, and each axis's hand on the handle's Cartesian
//! coordinate, measured from where the handle starts.
//!
//! [`SceneServo::Linkage`]: crate::engine::servo::SceneServo::Linkage

use super::{Sample, Simulation};
use crate::engine::linkage::LinkageArm;
use crate::engine::scene::Scene;
use crate::Error;
use nalgebra::DVector;
use twoport_control::servo::SensorFrame;

/// The scene's arm and where its handle started.
#[derive(Clone, Debug)]
pub(super) struct SceneArm<const N: usize> {
    pub(super) arm: LinkageArm<N>,
    /// The handle's position at the start (m).
    x0: [f64; N],
    /// Where the scene's frame has its zero, in the kinematics' (m): the
    /// handle's start less where the world starts its point.
    origin: [f64; 3],
}

impl<const N: usize> SceneArm<N> {
    /// The scene's arm at its start pose, at rest, under the scene's
    /// gravity and friction.
    pub(super) fn at_rest(
        scene: &Scene,
        file: &twoport_design::linkage::LinkageFile,
    ) -> Result<LinkageArm<N>, Error> {
        let q = &scene.plant.pose_rad;
        let q0: [f64; N] = q[..]
            .try_into()
            .map_err(|_| sim_err!("plant.pose_rad: {} angles for {N} joints", q.len()))?;
        let mut arm = LinkageArm::at_rest(file, q0).map_err(|e| sim_err!("plant.pose_rad: {e}"))?;
        arm.plant.gravity_mps2 = scene.plant.gravity_mps2;
        arm.plant.friction = scene.plant.friction.unwrap_or(true);
        Ok(arm)
    }

    /// `arm` in a scene whose world starts its point at `start_m` (m).
    pub(super) fn new(arm: LinkageArm<N>, start_m: &[f64]) -> Result<Self, Error> {
        let (x0, _) = arm.handle().map_err(|e| sim_err!("plant.pose_rad: {e}"))?;
        let origin = core::array::from_fn(|i| {
            x0.get(i).copied().unwrap_or(0.0) - start_m.get(i).copied().unwrap_or(0.0)
        });
        Ok(SceneArm { arm, x0, origin })
    }
}

impl<const N: usize> Simulation<N> {
    /// A linkage scene's arm as it stands, drawn in the scene's frame (the
    /// world's): polylines through its joints to the handle (m).
    pub fn linkage_skeleton(&self) -> Option<Vec<Vec<[f64; 3]>>> {
        let arm = self.linkage.as_ref()?;
        let lines = arm.arm.plant.file().skeleton(arm.arm.plant.q.as_slice());
        Some(
            lines
                .into_iter()
                .map(|l| {
                    l.into_iter()
                        .map(|p| core::array::from_fn(|i| p[i] - arm.origin[i]))
                        .collect()
                })
                .collect(),
        )
    }

    /// One tick of a linkage scene.
    pub(super) fn step_linkage(&mut self) -> Sample<N> {
        let t = self.time_of(self.tick);
        let mut s = Sample::<N>::default();
        let Some(arm) = self.linkage.as_mut() else {
            return s;
        };
        let frame = SensorFrame {
            tick: self.tick as u32,
            encoder_raw: arm.arm.counts(),
            load_cell_n: [0.0; N],
            dead_man_closed: true,
        };
        let (out, torque) = self.servo.tick_driven(&frame);
        if !out.faults.is_empty() && self.failure.is_none() {
            self.failure = Some(format!("the safety layer tripped: {}", out.faults));
        }
        // Each axis's hand at this tick, as a force on the handle's
        // coordinate along that axis.
        let hands: Vec<_> = self
            .axes
            .iter()
            .map(|a| {
                let mut h = a.human.at(t);
                if let Some(g) = self.grasp_override {
                    h.grasp = g;
                }
                h.push_n += a.push_n;
                h.position_m += a.offset_m;
                h
            })
            .collect();
        let x0 = arm.x0;
        let hand = |x: &[f64], v: &[f64]| -> DVector<f64> {
            DVector::from_fn(N, |i, _| hands[i].force_on(x[i] - x0[i], v[i]))
        };
        let stepped = arm.arm.step(&torque, &hand, self.period, self.substeps);
        let handle = arm.arm.handle().map(|(x, v)| {
            let dx: [f64; N] = core::array::from_fn(|i| x[i] - x0[i]);
            (dx, v)
        });
        match (stepped, handle) {
            (Ok(()), Ok((x, v))) => {
                for (i, axis) in self.axes.iter_mut().enumerate() {
                    let f_h = hands[i].force_on(x[i], v[i]);
                    let p = f_h * v[i];
                    axis.energy_in += 0.5 * (p + axis.last_power) * self.period;
                    axis.last_power = p;
                    axis.detector.push(out.actuator_force_n[i]);
                    (s.handle_m[i], s.handle_mps[i], s.human_n[i]) = (x[i], v[i], f_h);
                    s.energy_in_j += axis.energy_in;
                    self.peak_force = self.peak_force.max(out.actuator_force_n[i].abs());
                }
            }
            (Err(e), _) | (_, Err(e)) => {
                self.failure
                    .get_or_insert(format!("the arm left what it can reach: {e}"));
            }
        }
        self.tick += 1;
        s.t_s = self.time_of(self.tick);
        s.commanded_n = out.commanded_force_n;
        s.actuator_n = out.actuator_force_n;
        s.ve_m = self.servo.ve_position().map(|p| p.m() as f64);
        s.ve_n = out.ve_force_n;
        s.coupling_n = out.coupling_force_n;
        s.energy_stored_j = f64::NAN;
        s.layer_energy_j = [f64::NAN; N];
        s.layer_added = [f64::NAN; N];
        s
    }
}
