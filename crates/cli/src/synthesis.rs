//! `twoport design`: the boundary coupling of either display, the
//! recommended gain inside it, and what binds.

use crate::args::*;
use crate::run::*;
use twoport_design::DeviceAxis;

pub(crate) fn design_impedance(a: &DesignImpedance, axis: Option<&DeviceAxis>) -> Reported {
    if let Some(g) = a.min_grasp {
        return Err(format!(
            "--min-grasp {g}: a grasp's least damping is proven on linkage devices (--device LINKAGE) only"
        ));
    }
    let margin = a.margin.fraction()?;
    let d = designer(&a.common, axis)?;
    reported(d.design_impedance(a.b, margin).map_err(|e| e.to_string())?)
}

pub(crate) fn design_admittance(a: &DesignAdmittance, axis: Option<&DeviceAxis>) -> Reported {
    let margin = a.margin.fraction()?;
    let d = designer(&a.common, axis)?;
    let regulator = a.kp.zip(a.bp);
    reported(
        d.design_admittance(regulator, a.b, margin)
            .map_err(|e| e.to_string())?,
    )
}

/// `design impedance --device LINKAGE`: the proof over the linkage's
/// workspace, hands off or for a least grasp.
pub(crate) fn design_linkage(a: &DesignImpedance) -> Reported {
    use twoport_design::linkage::{certified_design, LinkageDesign};
    use twoport_design::network::HumanBound;
    let margin = a.margin.fraction()?;
    let file = linkage_file(&a.common)?;
    let b = gain("b", a.b.unwrap_or(0.0))?;
    if let Some(g) = a.min_grasp {
        gain("min-grasp", g)?;
    }
    // A least grasp alone, hands off, or (by default, as for every
    // device) the paper's bound on how stiff the grasp is, whose
    // certificate is the hands-off one.
    let human = (a.min_grasp.is_none() && !a.common.no_human).then_some(HumanBound::PAPER);
    let d =
        certified_design(&file, b, a.min_grasp.unwrap_or(0.0), human).map_err(|e| e.to_string())?;
    reported(LinkageDesign::new(&file, &d, margin))
}
