//! `twoport design`: the boundary coupling of either display, the
//! recommended gain inside it, and what binds.

use crate::args::*;
use crate::run::*;

pub(crate) fn design_impedance(a: &DesignImpedance) -> Result<(), String> {
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
