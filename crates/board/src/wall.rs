//! The walls the images render, as data: one type for the Excalibur's wall
//! and the linkage images' floor.

use crate::BuildError;
use twoport_control::ve::{Solid, UnilateralWall};
use twoport_control::Position;

/// A [`UnilateralWall`] an image renders along one axis, placed relative
/// to the handle's rest position on that axis (the Excalibur rests at its
/// origin).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Wall {
    /// Where its surface is, from the rest position (m).
    pub surface_m: f32,
    /// Which side of the surface is solid.
    pub solid: Solid,
    /// Its stiffness (N/m).
    pub stiffness_npm: f32,
    /// Its damping (N s/m).
    pub damping_nspm: f32,
}

impl Wall {
    /// The wall for an axis resting at `rest_m` (m), its probe at `probe`,
    /// at the servo's period `period_s` (s).
    pub fn build(
        &self,
        rest_m: f32,
        period_s: f32,
        probe: Position,
    ) -> Result<UnilateralWall, BuildError> {
        let surface = Position::from_m(rest_m + self.surface_m).ok_or(BuildError::RestPose)?;
        UnilateralWall::new(
            self.stiffness_npm,
            self.damping_nspm,
            surface,
            self.solid,
            period_s,
            probe,
        )
        .map_err(BuildError::Param)
    }
}
