//! The proven region a board ships with: the limit at each damping on a
//! log grid, and the same as Rust source for a board image.

use super::{log_grid, max_stiffness_poses, min_mass_poses, Poses};

/// The proven region for a board: for each damping on a log grid from
/// `b_lo` to `b_hi` (N s/m, `points` of them), the greatest coupling
/// stiffness (impedance display) over every pose. Dampings where nothing is
/// stable are left out. (One pose: `&[(&analysis, &bound)]`.)
pub fn region_impedance(poses: &Poses, range: (f64, f64), points: usize) -> Vec<(f64, f64)> {
    region(range, points, |b| max_stiffness_poses(poses, b))
}

/// The proven region for a board's admittance display (one regulator):
/// the least coupling mass for each damping on a log grid, over every pose.
pub fn region_admittance(poses: &Poses, range: (f64, f64), points: usize) -> Vec<(f64, f64)> {
    region(range, points, |b| min_mass_poses(poses, b))
}

fn region(
    (lo, hi): (f64, f64),
    points: usize,
    limit: impl Fn(f64) -> Option<f64>,
) -> Vec<(f64, f64)> {
    log_grid(lo, hi, points)
        .into_iter()
        .filter_map(|b| limit(b).map(|l| (b, l)))
        .collect()
}

/// A proven region as Rust source for a board image (`twoport-board`'s
/// `Region`): the damping grid, the limits (rounded *toward safety*: a
/// stiffness down, a mass up, so that the f32 copy never proves more than
/// the f64 analysis did), the regulator for an admittance region, and the
/// latency from sampling to the force the proofs allow (`latency_s`, s:
/// rounded down, the board's budget). `how` is the command that made it,
/// quoted in the header.
pub fn region_rust_source(
    rows: &[(f64, f64)],
    max_stiffness: bool,
    regulator: Option<(f64, f64)>,
    latency_s: f64,
    how: &str,
) -> String {
    use std::fmt::Write;
    let toward_safety = |l: f64| {
        let f = l as f32;
        let over = (f as f64) > l;
        match (max_stiffness, over) {
            (true, true) => f.next_down(),
            (false, false) if (f as f64) < l => f.next_up(),
            _ => f,
        }
    };
    let n = rows.len();
    let mut s = String::new();
    let _ = writeln!(s, "// Made by the designer: `{how}`. Do not edit;");
    let _ = writeln!(
        s,
        "// tests/shipped_region.rs checks it against the designer."
    );
    let bound = if max_stiffness {
        "MaxStiffness"
    } else {
        "MinMass"
    };
    let _ = writeln!(s, "/// What the region bounds.");
    let _ = writeln!(s, "pub const BOUND: Bound = Bound::{bound};");
    let _ = writeln!(s, "/// Coupling damping grid (N s/m).");
    let list = |v: &mut dyn Iterator<Item = f32>| {
        v.map(|x| format!("{x:?}")).collect::<Vec<_>>().join(", ")
    };
    let _ = writeln!(
        s,
        "pub const DAMPING_NSPM: [f32; {n}] = [{}];",
        list(&mut rows.iter().map(|r| r.0 as f32))
    );
    let unit = if max_stiffness { "N/m" } else { "kg" };
    let _ = writeln!(s, "/// The proven limit at each damping ({unit}).");
    let _ = writeln!(
        s,
        "pub const LIMIT: [f32; {n}] = [{}];",
        list(&mut rows.iter().map(|r| toward_safety(r.1)))
    );
    let _ = writeln!(
        s,
        "/// The regulator (k_p N/m, b_p N s/m) an admittance region holds for."
    );
    match regulator {
        Some((k, b)) => {
            let _ = writeln!(
                s,
                "pub const REGULATOR: Option<(f32, f32)> = Some(({:?}, {:?}));",
                k as f32, b as f32
            );
        }
        None => {
            let _ = writeln!(s, "pub const REGULATOR: Option<(f32, f32)> = None;");
        }
    }
    let budget = match latency_s as f32 {
        l if f64::from(l) > latency_s => l.next_down(),
        l => l,
    };
    let _ = writeln!(
        s,
        "/// The latency from sampling to the force (s) the limits are proven for."
    );
    let _ = writeln!(s, "pub const LATENCY_S: f32 = {budget:?};");
    s
}
