//! host-sim's one error type.

use crate::link::LinkError;
use thiserror::Error;

/// Why the simulator, a study, a PIL run or the scope refused or stopped,
/// naming what is wrong and where.
#[derive(Clone, Debug, PartialEq, Error)]
#[non_exhaustive]
pub enum Error {
    /// A scene file that is not a scene: the file and the line or field.
    #[error("{0}")]
    Scene(String),
    /// The designer refused the device (a model file, its dynamics).
    #[error(transparent)]
    Design(#[from] twoport_design::Error),
    /// A call to a board failed.
    #[error(transparent)]
    Link(#[from] LinkError),
    /// A scene the simulator cannot build or run as given (the field, and
    /// why).
    #[error("{0}")]
    Sim(String),
    /// A processor-in-the-loop run that cannot start or go on.
    #[error("{0}")]
    Pil(String),
    /// The scope's window would not open (no display, no GPU context).
    #[error("the window would not open: {0}")]
    NoWindow(String),
    /// A linkage reached a pose with no kinematics (singular or out of
    /// reach): the joint angles (rad).
    #[error("no kinematics at the joint angles {0:?} rad: a singular pose, or out of reach")]
    Pose(Vec<f64>),
    /// A linkage file with `file` joints where the run was built for
    /// `run`.
    #[error("the linkage file has {file} joints; the run was built for {run}")]
    Joints {
        /// The file's joints.
        file: usize,
        /// The run's.
        run: usize,
    },
    /// An output (a CSV, a plot, a window) that could not be made.
    #[error("{0}")]
    Output(String),
}

impl Error {
    /// A scene the simulator cannot build or run: `why`, naming the field.
    pub fn sim(why: impl Into<String>) -> Self {
        Error::Sim(why.into())
    }
}

/// A message naming the field and the problem, from the engine's checks.
impl From<String> for Error {
    fn from(why: String) -> Self {
        Error::Sim(why)
    }
}

impl From<&str> for Error {
    fn from(why: &str) -> Self {
        Error::Sim(why.to_string())
    }
}
