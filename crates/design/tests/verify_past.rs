//! `verify` breaks tight designs 1% past, on devices where hands of one
//! or two resonances never reach the edge: vibration absorbers, beating
//! modes, a tick of delay, a flexure, a design that binds at Nyquist, and
//! one made with the human bound. Past the design the constructive
//! search takes the proof's worst hand at the aliases of its binding
//! frequency, realised as one lossless hand with a mass hanging at each,
//! and closes a pole on the unit circle with a lossless VE; at the
//! design it closes none outside it. The pole is checked on the exact
//! closed loop, which shares only the model and the laws with the proof.

use twoport_control::{Gains, ImpedanceGains};
use twoport_design::network::HumanBound;
use twoport_design::verify::Verdict;
use twoport_design::{Designer, DeviceModel};

fn device(file: &str) -> DeviceModel {
    let path = format!("{}/tests/devices/{file}", env!("CARGO_MANIFEST_DIR"));
    DeviceModel::load(std::path::Path::new(&path)).unwrap()
}

fn imp(k: f64, b: f64) -> Gains {
    ImpedanceGains::new(k as f32, b as f32).into()
}

/// The design at `b` (N s/m), `verify` at it and 1% past it; returns
/// the verdict past it and the number of masses the constructed hand
/// hangs.
fn tight(file: &str, human: Option<HumanBound>, b: f64) -> (Verdict, usize) {
    let d = Designer::new(vec![device(file)], None, human).unwrap();
    let (k, b) = d.design_impedance(Some(b), 0.0).unwrap().coupling.unwrap();
    let at = d.verify(&imp(k, b)).unwrap().verdict;
    assert!(!at.unstable, "{file}: {k} N/m broken: {at:?}");
    if let Some(c) = &at.constructed {
        assert!(c.spectral_radius < 1.0 + 1e-9, "{file} at {k}: {c:?}");
    }
    let past = d.verify(&imp(1.01 * k, b)).unwrap().verdict;
    let c = past
        .constructed
        .as_ref()
        .unwrap_or_else(|| panic!("{file}: nothing 1% past {k} N/m: {past:?}"));
    assert!((c.spectral_radius - 1.0).abs() < 1e-6, "{file}: {c:?}");
    let hand = &c.termination.hand;
    let lossless = hand.hanging.iter().all(|r| r.damping_nspm == 0.0);
    assert!(hand.damping_nspm == 0.0 && lossless, "{file}: {c:?}");
    let masses = hand.hanging.len();
    (past, masses)
}

#[test]
#[cfg_attr(debug_assertions, ignore = "release only (CI runs it)")]
fn absorbers_and_delay_are_broken_one_percent_past() {
    let (_, masses) = tight("absorber_delayed.toml", None, 1.8814);
    assert!(masses >= 4, "{masses}");
    tight("flexure_absorber.toml", None, 2.4717);
    let (_, masses) = tight("beating_delayed.toml", None, 11.2414);
    assert!(masses >= 64, "{masses}");
}

#[test]
#[cfg_attr(debug_assertions, ignore = "release only (CI runs it)")]
fn a_design_binding_at_nyquist_is_broken_just_below_it() {
    let (past, _) = tight("absorber_nyquist.toml", None, 0.23);
    let c = past.constructed.unwrap();
    assert!((490.0..500.0).contains(&c.frequency_hz), "{c:?}");
}

#[test]
#[cfg_attr(debug_assertions, ignore = "release only (CI runs it)")]
fn a_design_with_the_human_bound_is_broken_one_percent_past() {
    let (past, _) = tight("grasped_flexure.toml", Some(HumanBound::PAPER), 17.8681);
    assert!(past.constructed.unwrap().termination.hand.grasp.is_some());
}
