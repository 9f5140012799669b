//! `twoport design`: the boundary coupling of either display, the
//! recommended gain inside it, and what binds.

use crate::args::*;
use crate::run::*;

pub(crate) fn design_impedance(a: &DesignImpedance) -> Result<(), String> {
    if let Some(g) = a.min_grasp {
        return Err(format!(
            "--min-grasp {g}: a grasp's least damping is proven on linkage devices (--device LINKAGE) only"
        ));
    }
    let margin = a.margin.fraction()?;
    let d = designer(&a.common)?;
    let r = d.design_impedance(a.b, margin).map_err(|e| e.to_string())?;
    emit(&a.common, &r)
}

pub(crate) fn design_admittance(a: &DesignAdmittance) -> Result<(), String> {
    let margin = a.margin.fraction()?;
    let d = designer(&a.common)?;
    let regulator = a.kp.zip(a.bp);
    let r = d
        .design_admittance(regulator, a.b, margin)
        .map_err(|e| e.to_string())?;
    emit(&a.common, &r)
}

/// `design impedance --device LINKAGE`: the proof over the linkage's
/// workspace, hands off or for a least grasp.
pub(crate) fn design_linkage(a: &DesignImpedance) -> Result<(), String> {
    use twoport_design::linkage::{
        workspace_design, workspace_poses, LinkageDesign, LinkageFile, DESIGN_GRID,
    };
    let margin = a.margin.fraction()?;
    let path = a.common.device.as_ref().ok_or("--device: a linkage file")?;
    let mut file = LinkageFile::load(path).map_err(|e| e.to_string())?;
    let grasp = match (a.min_grasp, a.common.no_human) {
        (Some(g), _) => g,
        (None, true) => 0.0,
        (None, false) => {
            return Err(format!(
                "--device {}: a linkage is proven for every passive hand (--no-human) or for \
                 every hand that grasps with at least some damping (--min-grasp B); \
                 the paper's bound on the grasp is not proven for linkages yet",
                path.display()
            ))
        }
    };
    if let Some(t) = a.common.period {
        if !(t.is_finite() && t > 0.0) {
            return Err(format!("--period {t}: must be finite and > 0"));
        }
        file.period_s = t;
    }
    let poses = workspace_poses(&file, DESIGN_GRID);
    let d =
        workspace_design(&file, &poses, a.b.unwrap_or(0.0), grasp).map_err(|e| e.to_string())?;
    emit(&a.common, &LinkageDesign::new(&file, &d, margin))
}
