//! `twoport host-ve`: a coupling proven against a body the host moves.

#[path = "../../../tests/support/cli.rs"]
mod support;

const TWOPORT: support::Tool = support::Tool {
    bin: env!("CARGO_BIN_EXE_twoport"),
    root: concat!(env!("CARGO_MANIFEST_DIR"), "/../.."),
};

/// A soft coupling is proven against a 1 kg, 10 N s/m body at 1 kHz and
/// 2 ms; the paper's stiff one is not, and the report says how much
/// damping the body would need (more than it has).
#[test]
fn a_soft_coupling_is_proven_against_a_host_body_and_the_paper_s_is_not() {
    let v = TWOPORT.json(&[
        "host-ve",
        "--host-body",
        "1,10",
        "--k",
        "20000",
        "--b",
        "60",
        "--json",
    ]);
    assert_eq!(v["proven"], true);
    assert_eq!(
        (v["ve_period_ticks"].as_u64(), v["delay_ticks"].as_u64()),
        (Some(1), Some(2))
    );
    let c = &v["poses"][0]["check"];
    assert!(c["least_damping_nspm"].as_f64().unwrap() < 10.0, "{c}");
    let v = TWOPORT.json(&[
        "host-ve",
        "--host-body",
        "1,10",
        "--k",
        "51000",
        "--b",
        "90",
        "--json",
    ]);
    assert_eq!(v["proven"], false);
    let c = &v["poses"][0]["check"];
    assert!(c["least_damping_nspm"].as_f64().unwrap() > 10.0, "{c}");
    assert!(c["min_margin_nspm"].as_f64().unwrap() < 0.0, "{c}");
}

#[test]
fn bad_host_arguments_are_named() {
    let e = TWOPORT.failure(&["host-ve", "--k", "1000", "--b", "10"]);
    assert!(e.contains("--host-body"), "{e}");
    let e = TWOPORT.failure(&["host-ve", "--host-body", "1,10", "--k", "1000"]);
    assert!(e.contains("--k: give --b"), "{e}");
    let e = TWOPORT.failure(&["host-ve", "--host-body", "1,-1", "--k", "1000", "--b", "10"]);
    assert!(e.contains("the damping must be 0 N s/m or more"), "{e}");
    let e = TWOPORT.failure(&[
        "host-ve",
        "--host-body",
        "1,10",
        "--k",
        "1000",
        "--b",
        "10",
        "--period",
        "0.0015",
    ]);
    assert!(
        e.contains("not a whole multiple of --ve-rate 1000 Hz"),
        "{e}"
    );
    let e = TWOPORT.failure(&["host-ve", "--host-body", "1,10", "--k", "-5", "--b", "10"]);
    assert!(e.contains("--k"), "{e}");
}

/// The two-rate proof takes the board's latency inside the tick through
/// the device's sampled terms: at half a tick the stiffest coupling proven
/// against the host's body is softer than with none, and the exact
/// two-rate loop, with the force held half a tick late, finds no hand
/// that breaks it.
#[test]
fn the_two_rate_proof_takes_a_latency() {
    let k = |extra: &[&str]| {
        let mut a = vec!["host-ve", "--host-body", "1,10", "--json"];
        a.extend(extra);
        TWOPORT.json(&a)
    };
    let (none, late) = (k(&[]), k(&["--latency", "0.5T", "--verify"]));
    assert_eq!(
        (none["proven"].as_bool(), late["proven"].as_bool()),
        (Some(true), Some(true))
    );
    let (k0, k1) = (
        none["k_npm"].as_f64().unwrap(),
        late["k_npm"].as_f64().unwrap(),
    );
    assert!(k1 < 0.8 * k0, "{k1} vs {k0}");
    let v = &late["poses"][0]["verify"];
    assert_eq!(v["unstable"], false, "{v}");
}
