//! `twoport region`: the proven region a board ships with.

use crate::args::*;
use crate::run::*;
use twoport_design::analysis;
use twoport_design::designer::RegionBound;

pub(crate) fn region(d: &Display<RegionImpedance, RegionAdmittance>) -> Result<(), String> {
    let (grid, common) = match d {
        Display::Impedance(r) => (&r.grid, &r.common),
        Display::Admittance(r) => (&r.grid, &r.common),
    };
    let range = (grid.b_from, grid.b_to);
    let s = designer(common)?;
    let r = match d {
        Display::Impedance(_) => s.region_impedance(range, grid.points),
        Display::Admittance(a) => s.region_admittance((a.kp, a.bp), range, grid.points),
    }
    .map_err(|e| e.to_string())?;
    if !grid.rust {
        return emit(common, &r);
    }
    let how = std::env::args().skip(1).collect::<Vec<_>>().join(" ");
    let source = analysis::region_rust_source(
        &r.rows,
        r.bound == RegionBound::MaxStiffness,
        r.regulator,
        &format!("twoport {how}"),
    );
    match &common.axis {
        // A device file: one module per axis, for a board's regions.
        Some(a) => {
            let ident: String = a
                .name
                .chars()
                .map(|c| {
                    if c.is_ascii_alphanumeric() {
                        c.to_ascii_lowercase()
                    } else {
                        '_'
                    }
                })
                .collect();
            say!(
                "/// Axis {}'s proven region.\npub mod axis_{ident} {{\nuse super::*;\n",
                a.name
            );
            say!("{source}");
            say!("}}\n");
        }
        None => say!("{source}"),
    }
    Ok(())
}
