//! The designer's reports: what the JSON says is what the text says and
//! what the report holds, and bad questions are refused by name.

use twoport_design::designer::{BindingBound, Designer, Limit};
use twoport_design::network::HumanBound;
use twoport_design::{DeviceModel, Error};

fn excalibur() -> Designer {
    Designer::new(
        vec![DeviceModel::excalibur().unwrap()],
        None,
        Some(HumanBound::PAPER),
    )
    .unwrap()
}

/// The impedance design's JSON carries the boundary and the recommended
/// stiffness the text prints, and the admittance design asked next on the
/// same designer takes its regulator from it (eq 30).
#[test]
fn a_designs_json_and_text_say_the_same() {
    let d = excalibur();
    let r = d.design_impedance(Some(90.0), 0.1).unwrap();
    let (k, b) = r.coupling.expect("a design");
    let v = serde_json::to_value(&r).unwrap();
    assert_eq!(v["k_c_npm"].as_f64(), Some(k));
    assert_eq!(v["b_c_nspm"].as_f64(), Some(b));
    assert_eq!(v["feasible"], true);
    let rec = r.recommended().unwrap();
    assert!((rec - 0.9 * k).abs() < 1e-9 * k);
    assert_eq!(v["recommended_k_c_npm"].as_f64(), Some(rec));
    let text = r.to_string();
    assert!(text.contains(&Limit::Stiffness.text(k)), "{text}");
    assert!(text.contains(&Limit::Stiffness.text(rec)), "{text}");
    assert_eq!(
        r.binding == BindingBound::SampledData,
        v["binding_bound"] == "sampled-data"
    );

    let a = d.design_admittance(None, Some(500.0), 0.1).unwrap();
    let best = d.design_impedance(None, 0.1).unwrap().coupling.unwrap();
    let reg = a.regulator.unwrap();
    assert_eq!((reg.kp, reg.bp), best);
    let v = serde_json::to_value(&a).unwrap();
    assert_eq!(v["kp_npm"].as_f64(), Some(best.0));
    assert_eq!(v["m_c_kg"].as_f64(), a.coupling.map(|c| c.0));
}

/// A check inside the boundary has a positive gain margin, one past it a
/// negative one, and both say so in JSON and text.
#[test]
fn a_check_reports_its_margin_to_the_boundary() {
    let d = excalibur();
    let (k, _) = d
        .design_impedance(Some(90.0), 0.0)
        .unwrap()
        .coupling
        .unwrap();
    let inside = d.check_impedance(0.8 * k, 90.0).unwrap();
    let past = d.check_impedance(1.2 * k, 90.0).unwrap();
    assert!(inside.check.absolutely_stable && !past.check.absolutely_stable);
    assert!((inside.gain_margin.unwrap() - 0.2).abs() < 1e-9);
    assert!((past.gain_margin.unwrap() + 0.2).abs() < 1e-9);
    assert_eq!(
        serde_json::to_value(&past).unwrap()["boundary_k_c_npm"].as_f64(),
        Some(k)
    );
    assert!(past.to_string().contains("past the boundary"), "{past}");
}

/// Bad questions are refused by name before any analysis: a margin out
/// of range, a negative gain, a region grid that is no grid, an
/// admittance display on a device without a force sensor, and no pose.
#[test]
fn bad_questions_are_refused_by_name() {
    let d = excalibur();
    assert_eq!(
        d.design_impedance(None, 2.0).unwrap_err(),
        Error::Margin(2.0)
    );
    let e = d.check_impedance(-1.0, 90.0).unwrap_err();
    assert_eq!(e.to_string(), "k -1: must be a finite number >= 0");
    assert_eq!(
        d.region_impedance((100.0, 10.0), 8).unwrap_err(),
        Error::RegionGrid
    );
    let mut no_sensor = DeviceModel::excalibur().unwrap();
    no_sensor.force_sensor = false;
    let e = Designer::new(vec![no_sensor], None, None)
        .unwrap()
        .design_admittance(None, None, 0.1)
        .unwrap_err();
    assert!(matches!(e, Error::NoForceSensor(_)), "{e}");
    assert_eq!(
        Designer::new(vec![], None, None).unwrap_err(),
        Error::NoPose
    );
}

/// An infeasible design names the frequency that binds: on a rigid 1 kg,
/// 20 N s/m handle without the human bound, a coupling damping past the
/// device's (25 N s/m) fails at Nyquist for every stiffness, not toward
/// DC, where the bound vanishes.
#[test]
fn an_infeasible_design_names_the_frequency_that_binds() {
    let rigid = DeviceModel::from_toml(
        "period_s = 0.001\npeak_force_n = 50.0\ncontinuous_force_n = 20.0\n\
         M = [[1.0]]\nD = [[20.0]]\nK = [[0.0]]\nG = [[1.0, -1.0]]\nC_v = [[1.0], [-1.0]]\n",
        "rigid",
    )
    .unwrap();
    let d = Designer::new(vec![rigid], None, None).unwrap();
    let r = d.design_impedance(Some(25.0), 0.1).unwrap();
    assert!(r.coupling.is_none());
    let why = r.message.unwrap();
    assert!(
        why.contains("500.00 Hz") && !why.contains("toward DC"),
        "{why}"
    );
    // Below the device's damping there is one.
    assert!(d
        .design_impedance(Some(15.0), 0.1)
        .unwrap()
        .coupling
        .is_some());
}

/// A design that binds at a lightly damped mode says so: the heavy
/// actuator on a stiff flexure, held still, rings at 150 Hz with a damping
/// ratio near 2e-6, which holds it to 21 N/m: too soft to be useful, so it
/// is refused with that reason, not given as a number. The Excalibur's
/// design binds at no such mode.
#[test]
fn a_design_limited_by_a_lightly_damped_mode_says_which() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/devices/heavy_actuator.toml"
    );
    let m = DeviceModel::load(std::path::Path::new(path)).unwrap();
    let d = Designer::new(vec![m], None, None).unwrap();
    let r = d.design_impedance(Some(0.0), 0.1).unwrap();
    let l = *r.limited_by().expect("a lightly damped mode");
    assert!((l.frequency_hz - 150.4).abs() < 0.5, "{l:?}");
    assert!(l.damping_ratio < 1e-5, "{l:?}");
    assert_eq!(r.coupling, None);
    let k = r.limited_to.expect("the refused limit");
    assert!(k > 21.0 && k < 21.6, "{k}");
    let text = r.to_string();
    assert!(
        text.contains("infeasible: nothing useful is proven: a mode at 150.41 Hz"),
        "{text}"
    );
    assert!(!text.contains("recommended"), "{text}");
    let v = serde_json::to_value(&r).unwrap();
    assert!(v["limited_by"]["damping_ratio"].as_f64().unwrap() < 1e-5);
    assert_eq!(v["feasible"], false);
    assert_eq!(v["limited_to_k_c_npm"].as_f64(), Some(k));
    let e = excalibur().design_impedance(Some(90.0), 0.1).unwrap();
    assert_eq!(e.limited_by(), None);
}
