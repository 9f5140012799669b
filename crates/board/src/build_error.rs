//! Why a board image could not be built: one of its constants is wrong.

use crate::region::RegionError;
use twoport_control::linkage::LinkageError;
use twoport_control::servo::GainsError;
use twoport_control::{AxisError, EncoderError, ParamError};

/// Why a board image could not be built (a constant in it is wrong).
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum BuildError {
    /// A law's or a kinematics' parameter.
    Param(ParamError),
    /// The encoder's.
    Encoder(EncoderError),
    /// The shipped region table.
    Region(RegionError),
    /// The servo's gains or port layer, on the axis it names.
    Servo(AxisError<GainsError>),
    /// A linkage servo's.
    Linkage(LinkageError),
    /// The rest pose is not one the kinematics serve, or a wall placed
    /// from it is out of range.
    RestPose,
}

impl From<ParamError> for BuildError {
    fn from(e: ParamError) -> Self {
        BuildError::Param(e)
    }
}

impl From<EncoderError> for BuildError {
    fn from(e: EncoderError) -> Self {
        BuildError::Encoder(e)
    }
}

impl From<AxisError<GainsError>> for BuildError {
    fn from(e: AxisError<GainsError>) -> Self {
        BuildError::Servo(e)
    }
}

impl From<RegionError> for BuildError {
    fn from(e: RegionError) -> Self {
        BuildError::Region(e)
    }
}

impl From<LinkageError> for BuildError {
    fn from(e: LinkageError) -> Self {
        BuildError::Linkage(e)
    }
}
