//! `twoport region`: the proven region a board ships with.

use crate::args::*;
use crate::session::*;
use serde_json::json;
use twoport_design::design;

pub(crate) fn region(d: &Display<RegionImpedance, RegionAdmittance>) -> Result<(), String> {
    let (grid, common) = match d {
        Display::Impedance(r) => (&r.grid, &r.common),
        Display::Admittance(r) => (&r.grid, &r.common),
    };
    let (lo, hi) = (gain("b-from", grid.b_from)?, gain("b-to", grid.b_to)?);
    if !(lo > 0.0 && hi > lo && (2..=1000).contains(&grid.points)) {
        return Err("need 0 < --b-from < --b-to and 2..=1000 --points".into());
    }
    let s = Session::open(common)?;
    let (bound, rows, regulator) = match d {
        Display::Impedance(_) => {
            let b = s.impedance_bounds(false);
            (
                "max_stiffness_npm",
                design::region_impedance(&s.with(&b), (lo, hi), grid.points),
                None,
            )
        }
        Display::Admittance(r) => {
            s.force_sensor()?;
            let (kp, bp) = (gain("kp", r.kp)?, gain("bp", r.bp)?);
            let k = design::regulator_tf(kp, bp, s.period()).map_err(|e| e.to_string())?;
            let b = s.admittance_bounds(&k, false);
            (
                "min_mass_kg",
                design::region_admittance(&s.with(&b), (lo, hi), grid.points),
                Some((kp, bp)),
            )
        }
    };
    if grid.rust {
        let how = std::env::args().skip(1).collect::<Vec<_>>().join(" ");
        let source = design::region_rust_source(
            &rows,
            bound == "max_stiffness_npm",
            regulator,
            &format!("twoport {how}"),
        );
        match &s.axis {
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
                println!(
                    "/// Axis {}'s proven region.\npub mod axis_{ident} {{\nuse super::*;",
                    a.name
                );
                print!("{source}");
                println!("}}");
            }
            None => print!("{source}"),
        }
        return Ok(());
    }
    let v = json!({"bound": bound, "damping_nspm": rows.iter().map(|r| r.0).collect::<Vec<_>>(),
        "limit": rows.iter().map(|r| r.1).collect::<Vec<_>>(), "regulator": regulator,
        "period_s": s.period(), "human_model": s.human.is_some()});
    s.emit(v, || {
        println!("{:>14} {:>16}", "b (N s/m)", bound);
        for (b, l) in &rows {
            println!("{b:>14.3} {l:>16.4}");
        }
    });
    Ok(())
}
