//! A linkage image for the PC's loop: a device whose own board only reads
//! the encoders and drives the motors, the loop on the PC over USB. Each
//! carries its region, the designer's workspace proof at the PC's latency
//! budget, as a table a test holds to the designer.

use super::{board_with, ImageSpec, LinkageBoard, LinkageWorld, REGION_POINTS};
use crate::region::{Bound, Region};
use crate::BuildError;
use twoport_control::kinematics::Kinematics;
use twoport_control::servo::ImpedanceGains;
use twoport_control::world::World;

/// The latency from a sample to its force (s) the PC images are proven
/// for: the USB protocols' two ticks at 1 kHz (the torques go out with the
/// next exchange, and the device answers within the next USB frame) and
/// three more for a desktop system's scheduling. A later force faults the
/// board to zero ("force late").
pub const LATENCY_S: f32 = 5.0e-3;

/// A linkage's image for the PC.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PcImage<const N: usize> {
    /// The device.
    pub spec: ImageSpec<N>,
    /// The coupling it runs, inside its region.
    pub coupling: ImpedanceGains,
    /// The coupling dampings of the region's grid (N s/m).
    pub damping_nspm: [f32; REGION_POINTS],
    /// The stiffest coupling proven at each (N/m): the designer's branch
    /// and bound over the workspace for a grasp of at least
    /// [`GRASP_NSPM`](super::GRASP_NSPM), at 1 kHz and [`LATENCY_S`],
    /// rounded down.
    pub limit_npm: [f32; REGION_POINTS],
}

impl<const N: usize> PcImage<N> {
    /// Its region, stating its latency.
    pub fn region(&self) -> Result<Region<REGION_POINTS>, crate::RegionError> {
        Region::new(Bound::MaxStiffness, self.damping_nspm, self.limit_npm, None)?
            .with_latency(LATENCY_S)
    }

    /// Its board on `kinematics`: disarmed and uncalibrated (the host puts
    /// the handle at the rest pose and calibrates), a wall 5 mm under the
    /// rest pose along the last axis.
    pub fn board<K: Kinematics<f32, N>>(
        &self,
        kinematics: K,
    ) -> Result<LinkageBoard<K, N>, BuildError>
    where
        LinkageWorld<N>: World<f32, N>,
    {
        let r = self.region().map_err(BuildError::Region)?;
        board_with(&self.spec, kinematics, self.coupling, r)
    }
}
