//! Linkage devices for the designer: their files (kind, geometry, motors,
//! joints), and their dynamics at a pose through the control crate's
//! kinematics (the same Jacobian the board will run).

mod dynamics;
mod file;
mod pose;
mod proof;
mod report;

pub use dynamics::SerialArmDynamics;
pub use file::{Geometry, Inertia, Joints, LinkageFile, Motors, RelativeLimit};
pub use pose::{forward, PoseDynamics};
pub use proof::{workspace_design, workspace_poses, Binding, WorkspaceDesign, DESIGN_GRID};
pub use report::{stiffness, LinkageDesign};
