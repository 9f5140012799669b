//! The region the Excalibur board image ships is the designer's, made by the
//! command its header names: regenerate it and compare, so the firmware can
//! never carry a stale or hand-edited proof. And the image's own gains are
//! inside it.

use twoport_board::excalibur;
use twoport_design::analysis::*;
use twoport_design::network::HumanBound;

#[test]
fn the_shipped_region_is_the_designers() {
    let shipped = include_str!("../crates/board/src/excalibur_region.rs");
    let how = shipped
        .lines()
        .next()
        .and_then(|l| l.split('`').nth(1))
        .expect("the header names the command");
    assert_eq!(
        how,
        "twoport region impedance --b-from 10 --b-to 810 --points 17 --rust"
    );
    let a = Analysis::excalibur();
    let bound = a.impedance_bound(Some(HumanBound::PAPER));
    let rows = region_impedance(&[(&a, &bound)], (10.0, 810.0), 17);
    assert_eq!(region_rust_source(&rows, true, None, how), shipped);
    // Rounded toward safety: no f32 limit exceeds the f64 proof.
    for (i, (_, k)) in rows.iter().enumerate() {
        assert!(excalibur::region::LIMIT[i] as f64 <= *k);
    }
}

#[test]
fn the_images_gains_are_proven() {
    let r = excalibur::proven_region().unwrap();
    let (k, b) = (excalibur::COUPLING.k_npm, excalibur::COUPLING.b_nspm);
    let limit = r.limit_at(b).expect("b = 90 N s/m is on the grid");
    assert!(k <= limit, "{k} N/m > proven {limit} N/m at {b} N s/m");
}
