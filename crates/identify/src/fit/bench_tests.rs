//! Devices the fit was not built around, as an experiment measures them
//! (the exact sampled responses with 0.5% noise, harmonics of 0.5 Hz up to
//! 450 Hz): springs to the frame, modes 5% apart, a load cell past a mode
//! it does not sit on. Each comes back with its resonances, and the
//! impedance design on the fit within 3% of the true model's.

use super::tests::{base, impedance_k, measure, resonances};
use super::*;

fn bench(name: &str) -> DeviceModel {
    let path = format!(
        "{}/../../models/bench/{name}.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    DeviceModel::load(path.as_ref()).unwrap()
}

/// The fit the criterion chooses for `truth`, checked: its resonances
/// within 1% of the truth's, and its design at `b` within 3%.
fn comes_back(truth: &DeviceModel, b: f64) -> Fit {
    let (mut fits, best) = fit_orders(&measure(truth, 450.0, 0.005), &base(truth));
    let f = fits.swap_remove(best.expect("no order fitted"));
    let top = TAU * 500.0;
    let (want, got) = (resonances(truth, top), resonances(&f.model, top));
    assert_eq!(want.len(), got.len(), "{got:?} against {want:?}");
    for (w, g) in want.iter().zip(&got) {
        assert!((g / w - 1.0).abs() < 0.01, "{got:?} against {want:?}");
    }
    let (k_true, k_fit) = (impedance_k(truth, b), impedance_k(&f.model, b));
    eprintln!(
        "{}: resonances {:?} Hz (true {:?}); k at {b} N s/m: fit {k_fit:.1}, true {k_true:.1}",
        truth.name,
        got.iter().map(|w| w / TAU).collect::<Vec<_>>(),
        want.iter().map(|w| w / TAU).collect::<Vec<_>>()
    );
    assert!(
        (k_fit / k_true - 1.0).abs() < 0.03,
        "{k_fit} against {k_true}"
    );
    f
}

/// The stiffness the actuator feels at DC (N/m): `1/(K^-1)_00`, the
/// actuator the first coordinate.
fn static_npm(m: &DeviceModel) -> f64 {
    1.0 / m.k.clone().try_inverse().expect("no spring to the frame")[(0, 0)]
}

/// The fit is a chain held to the frame, as stiff at DC as the truth.
fn held(f: &Fit, truth: &DeviceModel) -> chain::Ground {
    let c = match &f.form {
        Form::Chain(c) => c,
        other => panic!("{other:?}"),
    };
    let (got, want) = (static_npm(&f.model), static_npm(truth));
    assert!((got / want - 1.0).abs() < 0.01, "{got} N/m against {want}");
    c.ground.expect("no spring to the frame")
}

/// A voice-coil handle on a centring spring: the spring at the actuator.
#[test]
fn a_handle_on_a_centring_spring_is_a_chain_held_to_the_frame() {
    let truth = bench("centring");
    let g = held(&comes_back(&truth, 2.0), &truth);
    assert_eq!(g.at, 0);
    assert!((g.npm / 400.0 - 1.0).abs() < 0.02, "{g:?}");
}

/// A handle on a flexure to the frame, past a cable from the motor. With
/// the encoder alone, a spring at the motor and one at the handle give
/// nearly the same response for two masses (the criterion may take
/// either); the resonances, the DC stiffness and the design are what the
/// record fixes.
#[test]
fn a_handle_on_a_flexure_to_the_frame_is_held() {
    let truth = bench("grounded_flexure");
    held(&comes_back(&truth, 2.0), &truth);
}

#[test]
fn a_load_cell_past_the_belts_mode_is_fitted_as_modes() {
    comes_back(&bench("noncollocated"), 2.0);
}

/// Two modes 5% apart (150.0 and 157.5 Hz), the antiresonance between
/// them: both found, as a chain of three masses.
#[test]
fn two_modes_five_percent_apart_come_back_as_two() {
    let truth = bench("close_modes");
    let f = comes_back(&truth, 1.0);
    assert_eq!(f.form.modes(), 2, "{:?}", f.form);
}
