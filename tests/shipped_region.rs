//! The regions the Excalibur board images ship are the designer's, made by
//! the command each header names: regenerate them and compare, so the
//! firmware can never carry a stale or hand-edited proof. And each image's
//! own gains are inside its region.

use twoport_board::excalibur::{self, fast, pc, xyz};
use twoport_design::analysis::*;
use twoport_design::network::HumanBound;
use twoport_design::{DeviceModel, Plant};

/// `shipped` is what the command its header names makes (its period, or
/// the Excalibur's, its latency, its damping range and its points),
/// rounded toward safety into `limits`.
fn is_the_designers(shipped: &str, limits: &[f32]) {
    let how = shipped
        .lines()
        .next()
        .and_then(|l| l.split('`').nth(1))
        .expect("the header names the command");
    assert!(how.starts_with("twoport region impedance "), "{how}");
    let excalibur = DeviceModel::excalibur().unwrap();
    let flag = |name: &str| {
        let mut words = how.split_whitespace();
        words.find(|w| *w == name)?;
        Some(
            words
                .next()
                .and_then(|v| v.parse::<f64>().ok())
                .expect(name),
        )
    };
    let period_s = flag("--period").unwrap_or(excalibur.period_s);
    let latency_s = flag("--latency").unwrap_or(0.0);
    let range = (flag("--b-from").unwrap(), flag("--b-to").unwrap());
    let points = flag("--points").unwrap() as usize;
    let m = DeviceModel {
        latency_s,
        ..excalibur
    };
    let a = Analysis::new(&Plant::new(&m, period_s).unwrap(), GridSpec::DEFAULT);
    let bound = a.impedance_bound(Some(HumanBound::PAPER));
    let rows = region_impedance(&[(&a, &bound)], range, points);
    assert_eq!(
        region_rust_source(&rows, true, None, latency_s, how),
        shipped
    );
    // Rounded toward safety: no f32 limit exceeds the f64 proof.
    for (i, (_, k)) in rows.iter().enumerate() {
        assert!(limits[i] as f64 <= *k);
    }
}

#[test]
fn the_shipped_regions_are_the_designers() {
    let board = concat!(env!("CARGO_MANIFEST_DIR"), "/../crates/board/src/");
    let src = |file: &str| std::fs::read_to_string(format!("{board}{file}")).unwrap();
    is_the_designers(&src("excalibur_region.rs"), &excalibur::region::LIMIT);
    is_the_designers(&src("excalibur_fast_region.rs"), &fast::region::LIMIT);
    is_the_designers(&src("excalibur_xyz_region.rs"), &xyz::region::LIMIT);
    is_the_designers(&src("excalibur_pc_region.rs"), &pc::region::LIMIT);
}

/// Each image's coupling is inside its region, which states the latency
/// it is proven for; the paper's 51,000 N/m, on the boundary proven with
/// no latency, is outside the 1 kHz image's.
#[test]
fn the_images_gains_are_proven_for_their_latency() {
    let images = [
        (
            excalibur::COUPLING,
            excalibur::proven_region()
                .map(|r| (r.limit_at(excalibur::COUPLING.b_nspm), r.latency_s())),
            50e-6,
        ),
        (
            fast::COUPLING,
            fast::proven_region().map(|r| (r.limit_at(fast::COUPLING.b_nspm), r.latency_s())),
            25e-6,
        ),
        (
            xyz::COUPLING,
            xyz::proven_region().map(|r| (r.limit_at(xyz::COUPLING.b_nspm), r.latency_s())),
            200e-6,
        ),
        (
            pc::COUPLING,
            pc::proven_region().map(|r| (r.limit_at(pc::COUPLING.b_nspm), r.latency_s())),
            5e-3,
        ),
    ];
    for (c, region, latency_s) in images {
        let (limit, at) = region.unwrap();
        let limit = limit.expect("the image's damping is on the grid");
        assert!(c.k_npm <= limit, "{c:?} past proven {limit} N/m");
        assert_eq!(at, latency_s);
    }
    let r = excalibur::proven_region().unwrap();
    let paper = twoport_control::ImpedanceGains::new(51_000.0, 90.0);
    assert!(r.limit_at(paper.b_nspm).unwrap() < paper.k_npm);
}
