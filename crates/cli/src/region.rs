//! `twoport region`: the proven region a board ships with.

use crate::args::*;
use crate::run::*;
use twoport_design::analysis;
use twoport_design::designer::RegionBound;
use twoport_design::DeviceAxis;

pub(crate) fn region(
    d: &Display<RegionImpedance, RegionAdmittance>,
    axis: Option<&DeviceAxis>,
) -> Reported {
    let (grid, common) = match d {
        Display::Impedance(r) => (&r.grid, &r.common),
        Display::Admittance(r) => (&r.grid, &r.common),
    };
    let range = (gain("b-from", grid.b_from)?, gain("b-to", grid.b_to)?);
    if !(range.0 > 0.0 && range.0 < range.1 && (2..=1000).contains(&grid.points)) {
        return Err(format!(
            "--b-from {} --b-to {} --points {}: need 0 < --b-from < --b-to and 2..=1000 --points",
            range.0, range.1, grid.points
        ));
    }
    let s = designer(common, axis)?;
    let r = match d {
        Display::Impedance(_) => s.region_impedance(range, grid.points),
        Display::Admittance(a) => s.region_admittance((a.kp, a.bp), range, grid.points),
    }
    .map_err(|e| e.to_string())?;
    if !grid.rust {
        return reported(r);
    }
    let how = std::env::args().skip(1).collect::<Vec<_>>().join(" ");
    let source = analysis::region_rust_source(
        &r.rows,
        r.bound == RegionBound::MaxStiffness,
        r.regulator,
        r.context.latency_s,
        &format!("twoport {how}"),
    );
    Ok(Box::new(RustSource(match axis {
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
            format!(
                "/// Axis {}'s proven region.\npub mod axis_{ident} {{\nuse super::*;\n{source}}}",
                a.name
            )
        }
        None => source.trim_end().to_string(),
    })))
}

/// A region as Rust source for a board image: text only (`--rust` and
/// `--json` exclude each other).
struct RustSource(String);

impl Report for RustSource {
    fn json(&self) -> Result<serde_json::Value, String> {
        Err("--rust prints Rust source, not JSON".into())
    }
    fn text(&self) -> String {
        self.0.clone()
    }
}
