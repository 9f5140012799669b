//! A linkage image for the PC's loop: a device whose own board only reads
//! the encoders and drives the motors, the loop on the PC over USB. Each
//! carries its region, the designer's workspace proof at the PC's latency
//! budget, as a table a test holds to the designer.

use super::TELEMETRY_EVERY;
use super::{image_servo, io, safety, ImageSpec, LinkageWorld, PERIOD_S, REGION_POINTS};
use crate::region::{Bound, Region};
use crate::{Board, BuildError};
use twoport_control::kinematics::Kinematics;
use twoport_control::linkage::LinkageServo;
use twoport_control::passivity::{PassivityLimits, SeriesDamper};
use twoport_control::servo::{ImpedanceGains, OnDemand};
use twoport_control::world::World;

/// The latency from a sample to its force (s) the PC images are proven
/// for: the USB protocols' two ticks at 1 kHz (the torques go out with the
/// next exchange, and the device answers within the next USB frame) and
/// three more for a desktop system's scheduling. Past it the images run on
/// with their passivity layer engaged.
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
    /// A lower bound of the handle's mass in every direction over the
    /// workspace (kg): the lumped model's handle mass, under which its
    /// Cartesian mass never falls. It caps the passivity layer's damping.
    pub port_mass_kg: f32,
}

/// The passivity layer of the PC images: a series damper at each
/// Cartesian axis's port, engaged on demand.
pub type PcLayer = OnDemand<SeriesDamper>;

/// A PC image's servo: the linkage's, with [`PcLayer`].
pub type PcServo<K, const N: usize> = LinkageServo<K, LinkageWorld<N>, f32, N, PcLayer>;

/// A PC image's board.
pub type PcLinkageBoard<K, const N: usize> = Board<PcServo<K, N>, REGION_POINTS, N>;

impl<const N: usize> PcImage<N> {
    /// Its region, stating its latency.
    pub fn region(&self) -> Result<Region<REGION_POINTS>, crate::RegionError> {
        Region::new(Bound::MaxStiffness, self.damping_nspm, self.limit_npm, None)?
            .with_latency(LATENCY_S)
    }

    /// Its board on `kinematics`: disarmed and uncalibrated (the host puts
    /// the handle at the rest pose and calibrates), a wall 5 mm under the
    /// rest pose along the last axis, and a series damper at each axis's
    /// port, on demand: idle while the loop keeps to the proof, engaged
    /// by a force later than [`LATENCY_S`], when it dissipates what the
    /// coupling's port puts out from then on, as its observer books it
    /// crediting the handle's least damping, and the board runs on.
    pub fn board<K: Kinematics<f32, N>>(
        &self,
        kinematics: K,
    ) -> Result<PcLinkageBoard<K, N>, BuildError>
    where
        LinkageWorld<N>: World<f32, N>,
    {
        let r = self.region().map_err(BuildError::Region)?;
        let mut limits =
            PassivityLimits::for_device(self.port_mass_kg, PERIOD_S, safety().peak_force_n)?;
        limits.device_damping_nspm = self.spec.least_damping_nspm;
        let layer = OnDemand::new(SeriesDamper::new(limits)?);
        let servo = image_servo(&self.spec, kinematics, self.coupling)?
            .with_layers([layer; N])
            .map_err(BuildError::Linkage)?;
        Ok(Board::new(servo, [r; N], TELEMETRY_EVERY).with_io(io(&self.spec)))
    }
}
