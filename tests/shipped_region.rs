//! The regions the Excalibur board images ship are the designer's, made by
//! the command each header names: regenerate them and compare, so the
//! firmware can never carry a stale or hand-edited proof. And each image's
//! own gains are inside its region.

use twoport_board::excalibur::{self, fast};
use twoport_design::analysis::*;
use twoport_design::network::HumanBound;
use twoport_design::{DeviceModel, Plant};

/// `shipped` is what `how` makes at `period_s` over `range` in `points`,
/// rounded toward safety into `limits`.
fn is_the_designers(
    shipped: &str,
    how: &str,
    period_s: f64,
    range: (f64, f64),
    points: usize,
    limits: &[f32],
) {
    let header = shipped
        .lines()
        .next()
        .and_then(|l| l.split('`').nth(1))
        .expect("the header names the command");
    assert_eq!(header, how);
    let m = DeviceModel::excalibur().unwrap();
    let a = Analysis::new(&Plant::new(&m, period_s).unwrap(), GridSpec::DEFAULT);
    let bound = a.impedance_bound(Some(HumanBound::PAPER));
    let rows = region_impedance(&[(&a, &bound)], range, points);
    assert_eq!(region_rust_source(&rows, true, None, how), shipped);
    // Rounded toward safety: no f32 limit exceeds the f64 proof.
    for (i, (_, k)) in rows.iter().enumerate() {
        assert!(limits[i] as f64 <= *k);
    }
}

#[test]
fn the_shipped_regions_are_the_designers() {
    is_the_designers(
        include_str!("../crates/board/src/excalibur_region.rs"),
        "twoport region impedance --b-from 10 --b-to 810 --points 17 --rust",
        1e-3,
        (10.0, 810.0),
        17,
        &excalibur::region::LIMIT,
    );
    is_the_designers(
        include_str!("../crates/board/src/excalibur_fast_region.rs"),
        "twoport region impedance --period 0.00025 --b-from 30 --b-to 2430 --points 17 --rust",
        2.5e-4,
        (30.0, 2430.0),
        17,
        &fast::region::LIMIT,
    );
}

#[test]
fn the_images_gains_are_proven() {
    let (c, r) = (excalibur::COUPLING, excalibur::proven_region().unwrap());
    let limit = r.limit_at(c.b_nspm).expect("b = 90 N s/m is on the grid");
    assert!(c.k_npm <= limit, "{} N/m > proven {limit} N/m", c.k_npm);
    let (c, r) = (fast::COUPLING, fast::proven_region().unwrap());
    let limit = r
        .limit_at(c.b_nspm)
        .expect("the image's damping is on the grid");
    assert!(
        c.k_npm <= limit,
        "{} N/m > proven {limit} N/m at 4 kHz",
        c.k_npm
    );
}
