//! Linkage devices for the designer: their files (kind, geometry, motors,
//! joints), and their dynamics at a pose through the control crate's
//! kinematics (the same Jacobian the board will run).

mod bounded;
mod cell;
mod dynamics;
mod file;
mod interval;
mod pose;
mod proof;
mod report;
mod rigid;
mod search;
mod symmetry;
mod taylor;
mod verify;

pub use bounded::{bound_at, stiffest, stiffest_at, theta_grid, PoseRanges};
pub use cell::{CellBounds, Undecided};
pub use dynamics::SerialArmDynamics;
pub use file::{Geometry, Inertia, Joints, LinkageFile, Motors, OnKinematics, RelativeLimit};
pub use interval::Interval;
pub use pose::{forward, inverse, PoseDynamics};
pub use proof::{
    bounded_workspace_design, certified_design, certified_design_from, least_damping,
    workspace_design, workspace_poses, Binding, Certificate, WorkspaceDesign, BOUNDED_GRID,
    DESIGN_GRID,
};
pub use report::{stiffness, LinkageDesign};
pub use search::{least, Least, Objective, BUDGET, TOLERANCE};
pub use taylor::Taylor;
pub use verify::{loop_radius, verify_linkage, HandAssumption, LinkageHand, LinkageVerdict};

/// The shipped linkage files, for the tests.
#[cfg(test)]
pub(crate) mod test_files {
    use super::LinkageFile;

    /// Their names, without `.toml`.
    pub(crate) const SHIPPED: [&str; 4] =
        ["phantom_premium_1_5", "falcon_like", "haply_2diy", "hapkit"];

    /// `models/linkages/{name}.toml`.
    pub(crate) fn shipped(name: &str) -> LinkageFile {
        let path = format!(
            "{}/../../models/linkages/{name}.toml",
            env!("CARGO_MANIFEST_DIR")
        );
        LinkageFile::load(std::path::Path::new(&path)).unwrap()
    }
}
