//! `twoport rates`: each device's proven coupling at each servo rate.

#[path = "../../../tests/support/cli.rs"]
mod support;

const TWOPORT: support::Tool = support::Tool {
    bin: env!("CARGO_BIN_EXE_twoport"),
    root: concat!(env!("CARGO_MANIFEST_DIR"), "/../.."),
};

fn numbers(v: &serde_json::Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

/// A linkage's proof with a least grasp is Colgate's exact bound,
/// `k T/2 = λ_min(D_x) + b_g`, so its k doubles with the rate, exactly.
/// A lumped device's best coupling stiffens with the rate, and more than
/// it does at the first rate's damping, which is where both start. The
/// figure is written.
#[test]
fn the_proven_coupling_grows_with_the_servo_rate() {
    let dir = support::scratch("rates");
    let png = dir.join("rates.png");
    let v = TWOPORT.json(&[
        "rates",
        "--model",
        "models/capstan.toml",
        "--linkage",
        "models/linkages/hapkit.toml",
        "--rates",
        "1000,2000,4000",
        "--plot",
        png.to_str().unwrap(),
        "--json",
    ]);
    assert_eq!(numbers(&v["rates_hz"]), [1000.0, 2000.0, 4000.0]);
    let capstan = &v["devices"][0];
    let (k, same) = (
        numbers(&capstan["k_npm"]),
        numbers(&capstan["k_at_first_b_npm"]),
    );
    assert_eq!(k[0], same[0]);
    for i in 1..3 {
        assert!(k[i] > same[i] && same[i] > same[i - 1], "{k:?} {same:?}");
    }
    let hapkit = numbers(&v["devices"][1]["k_npm"]);
    for i in 1..3 {
        assert!((hapkit[i] / hapkit[i - 1] - 2.0).abs() < 1e-9, "{hapkit:?}");
    }
    assert_eq!(&std::fs::read(&png).unwrap()[1..4], b"PNG");
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn bad_rates_and_grasps_are_named() {
    let e = TWOPORT.failure(&["rates", "--rates", "1000,0"]);
    assert!(e.contains("--rates: 0 Hz"), "{e}");
    let e = TWOPORT.failure(&["rates", "--min-grasp", "-1"]);
    assert!(e.contains("--min-grasp -1"), "{e}");
    let e = TWOPORT.failure(&["rates", "--host-body", "1"]);
    assert!(e.contains("--host-body [1.0]"), "{e}");
    let e = TWOPORT.failure(&["rates", "--host-body", "0,10"]);
    assert!(e.contains("the mass must be > 0 kg"), "{e}");
    let e = TWOPORT.failure(&["rates", "--host-body", "1,10", "--rates", "1500"]);
    assert!(
        e.contains("1500 Hz: not a whole multiple of --ve-rate 1000 Hz"),
        "{e}"
    );
    let e = TWOPORT.failure(&["rates", "--host-body", "1,10", "--host-delay", "0"]);
    assert!(e.contains("--host-delay 0"), "{e}");
    let e = TWOPORT.failure(&["rates", "--model", "no/such.toml"]);
    assert!(e.contains("no/such.toml"), "{e}");
}

/// With the board's latency (a computation's time, the same at every
/// rate) each rate's coupling is proven with it: lower than without, and
/// by a larger share the faster the tick. A latency in periods is the
/// same share of every tick. A linkage's certificate is the rigid bound of
/// its least damping: at half a tick, Colgate's `2b/T` over `1 + 3α`.
#[test]
fn a_boards_latency_costs_a_faster_rate_more() {
    let k = |extra: &[&str]| {
        let words = "rates --model models/capstan.toml --linkage models/linkages/hapkit.toml \
                     --rates 1000,10000 --json";
        let mut a: Vec<&str> = words.split_whitespace().collect();
        a.extend(extra);
        TWOPORT.json(&a)
    };
    let (none, late) = (k(&[]), k(&["--latency", "18e-6"]));
    let (k0, k1) = (
        numbers(&none["devices"][0]["k_npm"]),
        numbers(&late["devices"][0]["k_npm"]),
    );
    assert!(k1[0] < k0[0] && k1[1] < k0[1], "{k0:?} {k1:?}");
    assert!(k1[1] / k0[1] < k1[0] / k0[0], "{k0:?} {k1:?}");
    assert_eq!(numbers(&late["latency_s"]), [18e-6, 18e-6]);
    let share = k(&["--latency", "0.1T"]);
    let s = numbers(&share["latency_s"]);
    assert!(
        (s[0] - 1e-4).abs() < 1e-15 && (s[1] - 1e-5).abs() < 1e-15,
        "{s:?}"
    );
    let half = k(&["--latency", "0.5T"]);
    let (h0, h1) = (
        numbers(&none["devices"][1]["k_npm"]),
        numbers(&half["devices"][1]["k_npm"]),
    );
    for (a, b) in h0.iter().zip(&h1) {
        let want = a / 2.5;
        assert!(
            (b - want).abs() < 1e-3 * want,
            "{b} vs {want} ({h0:?} {h1:?})"
        );
    }
}
