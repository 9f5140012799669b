//! The `twoport` command line as a user runs it: one JSON object per
//! command, clear errors with exit code 2, figures written to disk.

#[path = "../../../tests/support/cli.rs"]
mod support;

use std::path::PathBuf;

/// `twoport`, run from the repository root (the default model path is
/// relative to it).
const TWOPORT: support::Tool = support::Tool {
    bin: env!("CARGO_BIN_EXE_twoport"),
    root: concat!(env!("CARGO_MANIFEST_DIR"), "/../.."),
};

/// The paper's admittance-display gains: `K_p` and a 5 kg, 500 N s/m coupling.
const PAPER_ADMITTANCE: [&str; 8] = ["--kp", "51000", "--bp", "90", "--m", "5", "--b", "500"];

/// `command admittance` at the paper's gains, with `extra` arguments.
fn paper_admittance(command: &'static str, extra: &[&'static str]) -> Vec<&'static str> {
    let mut a = vec![command, "admittance"];
    a.extend(PAPER_ADMITTANCE);
    a.extend(extra);
    a
}

#[test]
fn design_impedance_json() {
    let v = TWOPORT.json(&["design", "impedance", "--b", "90", "--json"]);
    assert_eq!(v["display"], "impedance");
    assert_eq!(v["feasible"], true);
    assert_eq!(v["human_model"], true);
    assert_eq!(v["period_s"], 0.001);
    let k = v["k_c_npm"].as_f64().unwrap();
    assert!((k - 51_000.0).abs() < 0.03 * 51_000.0, "{k}");
    assert_eq!(v["b_c_nspm"], 90.0);
}

/// `--latency` in seconds or periods holds the force later: the same
/// latency either way gives the same design, below the one without; a
/// latency that is not a time is named.
#[test]
fn a_latency_lowers_the_design_the_same_in_seconds_and_periods() {
    let k = |extra: &[&str]| {
        let mut a = vec!["design", "impedance", "--b", "90", "--json"];
        a.extend(extra);
        TWOPORT.json(&a)["k_c_npm"].as_f64().unwrap()
    };
    let (none, periods, seconds) = (
        k(&[]),
        k(&["--latency", "0.25T"]),
        k(&["--latency", "250e-6"]),
    );
    assert_eq!(periods, seconds);
    assert!(periods < 0.9 * none, "{periods} vs {none}");
    for bad in ["-1e-4", "fast", "0.1TT"] {
        let e = TWOPORT.failure(&["design", "impedance", "--latency", bad]);
        assert!(e.contains("latency"), "{bad}: {e}");
    }
    let e = TWOPORT.failure(&["design", "impedance", "--latency", "2"]);
    assert!(e.contains("--latency 2 s: at most 1 s"), "{e}");
}

#[test]
fn design_admittance_json_and_infeasible_without_human() {
    let paper = |human: &[&str]| {
        let mut args = vec![
            "design",
            "admittance",
            "--kp",
            "51000",
            "--bp",
            "90",
            "--b",
            "500",
            "--json",
        ];
        args.extend(human);
        TWOPORT.json(&args)
    };
    let v = paper(&[]);
    assert_eq!(v["display"], "admittance");
    assert_eq!(v["feasible"], true);
    assert_eq!(v["kp_npm"], 51_000.0);
    assert_eq!(v["bp_nspm"], 90.0);
    let m = v["m_c_kg"].as_f64().unwrap();
    assert!((m - 5.0).abs() < 0.15, "{m}");
    let v = paper(&["--no-human"]);
    assert_eq!(v["feasible"], false);
    assert!(v.get("m_c_kg").is_none(), "no made-up number: {v}");
    // The reason is the low-frequency limit, not the search range.
    let why = v["message"].as_str().unwrap();
    assert!(
        why.contains("no finite coupling mass") && why.contains("toward DC"),
        "{why}"
    );
}

#[test]
fn check_json_both_displays() {
    let v = TWOPORT.json(&["check", "impedance", "--k", "51000", "--b", "90", "--json"]);
    assert_eq!(v["absolutely_stable"], true);
    assert!(v["min_margin"].as_f64().unwrap() >= 0.0);
    let v = TWOPORT.json(&["check", "impedance", "--k", "60000", "--b", "90", "--json"]);
    assert_eq!(v["absolutely_stable"], false);
    let f = v["worst_frequency_hz"].as_f64().unwrap();
    assert!(f > 1.0 && f < 500.0, "{f}");
    let mut args = paper_admittance("check", &["--json"]);
    args[7] = "5.1";
    let v = TWOPORT.json(&args);
    assert_eq!(v["absolutely_stable"], true);
}

#[test]
fn zrange_json_runs_from_a_tenth_of_a_hertz_to_nyquist() {
    let v = TWOPORT.json(&paper_admittance("zrange", &["--points", "50", "--json"]));
    let f = v["frequency_hz"].as_array().unwrap();
    assert_eq!(f.len(), 50);
    assert!((f[0].as_f64().unwrap() - 0.1).abs() < 1e-12);
    assert!((f[49].as_f64().unwrap() - 500.0).abs() < 1e-9);
    for key in ["z_min", "z_max"] {
        let z = v[key].as_array().unwrap();
        assert_eq!(z.len(), 50);
        assert!(z.iter().all(|p| p[0].is_f64() && p[1].is_f64()), "{key}");
    }
}

/// A command line's words.
fn words(line: &str) -> Vec<&str> {
    line.split_whitespace().collect()
}

#[test]
fn bad_inputs_are_named() {
    let e = TWOPORT.failure(&["check", "impedance", "--k", "-3", "--b", "90"]);
    assert!(e.contains("--k -3"), "{e}");
    let e = TWOPORT.failure(&words(
        "check impedance --k 1e4 --b 90 --model no/such.toml",
    ));
    assert!(
        e.contains("no/such.toml") && e.contains("cannot read"),
        "{e}"
    );
    let dir = support::scratch("errors");
    let bad = dir.join("bad.toml");
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../models/excalibur.toml"
    ))
    .unwrap()
    .replacen("0.2799, 0.3343", "0.28, 0.3343", 1);
    std::fs::write(&bad, text).unwrap();
    let e = TWOPORT.failure(&["design", "impedance", "--model", bad.to_str().unwrap()]);
    assert!(
        e.contains("M is not symmetric: M[2][3] = 0.2799 but M[3][2] = 0.28"),
        "{e}"
    );
    let e = TWOPORT.failure(&[
        "check",
        "impedance",
        "--k",
        "1",
        "--b",
        "1",
        "--period",
        "0",
    ]);
    assert!(e.contains("--period 0"), "{e}");
    let e = TWOPORT.failure(&["plot", "fig8", "--out", dir.join("x.jpg").to_str().unwrap()]);
    assert!(e.contains(".png or .svg"), "{e}");
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn plots_are_written_as_png_and_svg() {
    let dir: PathBuf = std::env::temp_dir().join(format!("twoport-plot-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (fig, ext) in [("fig8", "png"), ("fig9", "svg"), ("fig10", "png")] {
        let out = dir.join(format!("{fig}.{ext}"));
        TWOPORT.json(&["plot", fig, "--out", out.to_str().unwrap(), "--json"]);
        let bytes = std::fs::read(&out).unwrap();
        match ext {
            "png" => assert_eq!(&bytes[1..4], b"PNG"),
            _ => assert!(String::from_utf8_lossy(&bytes).contains("frequency (Hz)")),
        }
        assert!(bytes.len() > 10_000, "{fig}: {} bytes", bytes.len());
    }
}

#[test]
fn every_subcommand_has_help() {
    for args in [
        vec!["--help"],
        vec!["design", "--help"],
        vec!["design", "impedance", "--help"],
        vec!["design", "admittance", "--help"],
        vec!["check", "impedance", "--help"],
        vec!["check", "admittance", "--help"],
        vec!["zrange", "impedance", "--help"],
        vec!["zrange", "admittance", "--help"],
        vec!["plot", "--help"],
        vec!["region", "impedance", "--help"],
        vec!["verify", "impedance", "--help"],
        vec!["identify", "--help"],
        vec!["rates", "--help"],
        vec!["devices", "--help"],
        vec!["spec", "--help"],
        vec!["teleop", "verify", "--help"],
        vec!["teleop", "verify", "four-channel", "--help"],
    ] {
        let out = TWOPORT.run(&args);
        assert!(out.status.success(), "{args:?}");
        assert!(
            String::from_utf8_lossy(&out.stdout).contains("Usage"),
            "{args:?}"
        );
    }
}

#[test]
fn region_tables_for_a_board() {
    let v = TWOPORT.json(&[
        "region",
        "impedance",
        "--b-from",
        "20",
        "--b-to",
        "120",
        "--points",
        "6",
        "--json",
    ]);
    assert_eq!(v["bound"], "k_max_npm");
    let (b, k) = (
        v["b_nspm"].as_array().unwrap(),
        v["k_max_npm"].as_array().unwrap(),
    );
    assert_eq!((b.len(), k.len()), (6, 6));
    assert!(k.iter().all(|x| x.as_f64().unwrap() > 1e4));
    let v = TWOPORT.json(&[
        "region",
        "admittance",
        "--kp",
        "51000",
        "--bp",
        "90",
        "--b-from",
        "400",
        "--b-to",
        "1000",
        "--points",
        "4",
        "--json",
    ]);
    assert_eq!(v["bound"], "m_min_kg");
    assert_eq!(v["regulator"], serde_json::json!([51000.0, 90.0]));
    let m: Vec<f64> = v["m_min_kg"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert!(m.iter().all(|x| (4.0..6.0).contains(x)), "{m:?}");
}

/// Several poses: the design is the worst pose's, names the pose that
/// binds, and the commands that draw one device refuse several.
#[test]
fn several_poses_design_for_all() {
    let k = |model: &[&str]| {
        let mut args = vec!["design", "impedance", "--b", "90", "--json"];
        for m in model {
            args.extend(["--model", m]);
        }
        TWOPORT.json(&args)
    };
    let (e, t) = (k(&["models/excalibur.toml"]), k(&["models/two_mass.toml"]));
    let both = k(&["models/two_mass.toml", "models/excalibur.toml"]);
    let (ke, kt, kb) = (
        e["k_c_npm"].as_f64().unwrap(),
        t["k_c_npm"].as_f64().unwrap(),
        both["k_c_npm"].as_f64().unwrap(),
    );
    // The worst pose's limit, to the search's 1e-6.
    let want = ke.min(kt);
    assert!((kb - want).abs() <= 2e-6 * want, "{kb} vs {want}: {both}");
    let binding = if ke < kt { "Excalibur" } else { "Two-mass" };
    assert!(
        both["binding_pose"].as_str().unwrap().starts_with(binding),
        "{both}"
    );
    assert!(both["binding_frequency_hz"].as_f64().unwrap() > 0.0);
    let e = TWOPORT.failure(&[
        "zrange",
        "impedance",
        "--k",
        "1000",
        "--b",
        "10",
        "--model",
        "models/excalibur.toml",
        "--model",
        "models/two_mass.toml",
    ]);
    assert!(e.contains("zrange takes one --model"), "{e}");
}

/// The rigid capstan has no force sensor: an admittance display is refused
/// with the reason, and its impedance design is Colgate's 2b/T at b_c = 0,
/// where the paper's approximation (aliasing neglected) proves more.
#[test]
fn a_device_without_a_force_sensor() {
    let e = TWOPORT.failure(&["design", "admittance", "--model", "models/capstan.toml"]);
    assert!(e.contains("no force sensor"), "{e}");
    let v = TWOPORT.json(&words(
        "design impedance --no-human --model models/capstan.toml --json",
    ));
    let k = v["k_c_npm"].as_f64().unwrap();
    assert_eq!(v["b_c_nspm"], 0.0);
    assert!((k - 2.0 * 2.0 / 1e-3).abs() < 0.002 * k, "{v}");
    assert_eq!(v["binding_bound"], "sampled-data");
    assert!(v["paper_k_c_npm"].as_f64().unwrap() > 1.1 * k, "{v}");
}

/// A device file designs each axis on its own model: the shipped
/// three-axis Excalibur gives each axis the x axis's coupling, and a
/// device whose y axis is the rigid capstan gives y the capstan's own.
#[test]
fn a_device_file_designs_every_axis_on_its_own_model() {
    let design = |args: &str| TWOPORT.json(&words(args));
    let one = design("design impedance --b 90 --json");
    let xyz = design("design impedance --b 90 --device models/devices/excalibur_xyz.toml --json");
    let axes = xyz["axes"].as_array().unwrap();
    assert_eq!(axes.len(), 3);
    for (a, name) in axes.iter().zip(["x", "y", "z"]) {
        assert_eq!(a["axis"], name);
        assert_eq!(a["k_c_npm"], one["k_c_npm"], "axis {name}");
    }

    let dir = std::env::temp_dir().join(format!("twoport-device-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let models = concat!(env!("CARGO_MANIFEST_DIR"), "/../../models");
    let write = |file: &str, text: String| {
        let p = dir.join(file);
        std::fs::write(&p, text).unwrap();
        p.display().to_string()
    };
    let axis = |name: &str, model: &str| {
        format!("[[axis]]\nname = \"{name}\"\nmodels = [\"{models}/{model}\"]\n")
    };
    let mixed = write(
        "mixed.toml",
        axis("x", "excalibur.toml") + &axis("y", "capstan.toml"),
    );
    let v = design(&format!("design impedance --b 90 --device {mixed} --json"));
    let capstan = design("design impedance --b 90 --model models/capstan.toml --json");
    let (x, y) = (&v["axes"][0], &v["axes"][1]);
    assert_eq!(y["k_c_npm"], capstan["k_c_npm"]);
    assert!(
        x["k_c_npm"].as_f64().unwrap() > 2.0 * y["k_c_npm"].as_f64().unwrap(),
        "{v}"
    );

    // Bad device files are refused by name: the file, the axis, the fault.
    let four = write(
        "four.toml",
        ["a", "b", "c", "d"]
            .map(|n| axis(n, "excalibur.toml"))
            .concat(),
    );
    let missing = write(
        "missing.toml",
        axis("x", "excalibur.toml") + &axis("y", "no_such.toml"),
    );
    for (file, want) in [
        (&four, "4 [[axis]] tables: a device has 1 to 3"),
        (&missing, "axis 1 (y): "),
    ] {
        let e = TWOPORT.failure(&words(&format!("design impedance --device {file}")));
        assert!(e.contains(file.as_str()) && e.contains(want), "{e}");
    }
    // A board's regions: one Rust module per axis.
    let out = TWOPORT.run(&words(
        "region impedance --b-from 10 --b-to 100 --points 4 --rust --device models/devices/excalibur_xyz.toml",
    ));
    let rust = String::from_utf8(out.stdout).unwrap();
    for axis in ["x", "y", "z"] {
        assert!(rust.contains(&format!("pub mod axis_{axis} {{")), "{rust}");
    }
    assert_eq!(rust.matches("pub const LIMIT").count(), 3);
    assert_eq!(rust.matches('{').count(), rust.matches('}').count());
    let e = TWOPORT.failure(&words(
        "zrange impedance --k 5e4 --b 90 --device models/devices/excalibur_xyz.toml",
    ));
    assert!(e.contains("give that axis's --model"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

/// `design` gives the boundary and a recommended gain a chosen margin
/// inside it; `check` says how far inside (or past) the boundary given
/// gains are, and the published texts round toward safety.
#[test]
fn design_recommends_a_margin_and_check_reports_it() {
    let d = TWOPORT.json(&[
        "design",
        "impedance",
        "--b",
        "90",
        "--margin",
        "0.2",
        "--json",
    ]);
    let (k, rec) = (
        d["k_c_npm"].as_f64().unwrap(),
        d["recommended_k_c_npm"].as_f64().unwrap(),
    );
    assert!((rec - 0.8 * k).abs() <= 1e-9 * k, "{d}");
    let check = |k: f64| {
        TWOPORT.json(&[
            "check",
            "impedance",
            "--k",
            &k.to_string(),
            "--b",
            "90",
            "--json",
        ])
    };
    let inside = check(rec);
    assert_eq!(inside["absolutely_stable"], true, "{inside}");
    let g = inside["gain_margin"].as_f64().unwrap();
    assert!((g - 0.2).abs() < 1e-5, "{inside}");
    let past = check(1.01 * k);
    assert_eq!(past["absolutely_stable"], false, "{past}");
    assert!(past["gain_margin"].as_f64().unwrap() < 0.0, "{past}");
    // The text's boundary, rounded down, is itself proven.
    let out = TWOPORT.run(&["design", "impedance", "--b", "90"]);
    let text = String::from_utf8(out.stdout).unwrap();
    let shown: f64 = text
        .split("b_c = 90 N s/m: ")
        .nth(1)
        .and_then(|r| r.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("{text}"));
    assert!(shown <= k && shown > k - 1.0, "{shown} vs {k}");
    let e = TWOPORT.failure(&["design", "impedance", "--margin", "2"]);
    assert!(e.contains("--margin 2"), "{e}");
}

/// A linkage file given as `--device` is proven over its workspace: for
/// every passive hand, or for every grasp of a least damping (which adds
/// to the handle's own), and its map is drawn.
#[test]
fn linkages_are_proven_over_their_workspace() {
    let dev = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../models/linkages/phantom_premium_1_5.toml"
    );
    let off = TWOPORT.json(&[
        "design",
        "impedance",
        "--device",
        dev,
        "--no-human",
        "--json",
    ]);
    let grasp = TWOPORT.json(&[
        "design",
        "impedance",
        "--device",
        dev,
        "--min-grasp",
        "1",
        "--json",
    ]);
    let (k0, k1) = (
        off["k_c_npm"].as_f64().unwrap(),
        grasp["k_c_npm"].as_f64().unwrap(),
    );
    // The certificate is below the least damped pose found, within 1e-4,
    // and below the PHANToM's least damped pose (7.4072 N/m hands off).
    let b = off["binding_damping_nspm"].as_f64().unwrap();
    let below = |k: f64, at: f64| k <= at && k >= at * (1.0 - 1e-4);
    assert!(below(k0, 2.0 * b / 1e-3) && k0 <= 7.4072, "{off}");
    assert!(below(k1, 2.0 * (b + 1.0) / 1e-3), "{grasp}");
    assert!(off["certificate_gap"].as_f64().unwrap() <= 1e-4, "{off}");
    assert_eq!(off["binding_direction"].as_array().unwrap().len(), 3);
    // By default, the paper's bound on the grasp: every hand it allows is
    // passive, so the certificate is the hands-off one, and the bound's
    // frequency at the binding pose is reported.
    let paper = TWOPORT.json(&["design", "impedance", "--device", dev, "--json"]);
    assert_eq!(paper["k_c_npm"], off["k_c_npm"], "{paper}");
    assert!(
        paper["binding_frequency_hz"].as_f64().unwrap() > 0.0,
        "{paper}"
    );
    assert!(
        paper["human"].as_str().unwrap().contains("Z_max"),
        "{paper}"
    );
    let e = TWOPORT.failure(&["design", "impedance", "--min-grasp", "1"]);
    assert!(e.contains("linkage"), "{e}");
    // verify searches the linkage's exact loop: nothing 0.1 % inside the
    // hands-off design, a growing loop 20 % past it.
    let k = |f: f64| format!("{}", f * k0);
    let at = TWOPORT.json(&[
        "verify",
        "impedance",
        "--device",
        dev,
        "--k",
        &k(0.999),
        "--b",
        "0",
        "--no-human",
        "--json",
    ]);
    assert_eq!(at["unstable"], false, "{at}");
    let past = TWOPORT.json(&[
        "verify",
        "impedance",
        "--device",
        dev,
        "--k",
        &k(1.2),
        "--b",
        "0",
        "--no-human",
        "--json",
    ]);
    assert_eq!(past["unstable"], true, "{past}");
    assert_eq!(past["hand"]["direction"].as_array().unwrap().len(), 3);
    let e = TWOPORT.failure(&[
        "verify",
        "impedance",
        "--k",
        "1",
        "--b",
        "0",
        "--min-grasp",
        "1",
    ]);
    assert!(e.contains("linkage"), "{e}");
    let e = TWOPORT.failure(&["design", "impedance", "--device", dev, "--min-grasp", "-1"]);
    assert!(e.contains("--min-grasp -1"), "{e}");
    let dir: PathBuf = std::env::temp_dir().join(format!("twoport-map-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("map.svg");
    let v = TWOPORT.json(&[
        "plot",
        "workspace",
        "--device",
        dev,
        "--no-human",
        "--out",
        out.to_str().unwrap(),
        "--json",
    ]);
    assert!(
        (v["k_c_npm"].as_f64().unwrap() - k0).abs() < 0.1 * k0,
        "{v}"
    );
    assert!(std::fs::read_to_string(&out).unwrap().contains("k_c (N/m)"));
    let e = TWOPORT.failure(&["plot", "workspace", "--out", out.to_str().unwrap()]);
    assert!(e.contains("--device LINKAGE"), "{e}");
}

/// A reader that stops reading (`twoport ... | head`) ends the command
/// quietly: a closed pipe is not a panic.
#[test]
fn a_closed_pipe_ends_the_command_quietly() {
    TWOPORT.closes_quietly(&["design", "impedance", "--b", "90"]);
}

/// `spec` proves each PC-driven device at its rate and its protocol's
/// latency. Two whole ticks, no fraction: the workspace certificate is the
/// rigid bound `2b/((d + 1)² T)` of the handle's least damping `b`, hands
/// off and with the grasp added, which the report's own damping bound
/// gives back; and CHAI3D's hand-set Falcon stiffness is past it.
/// `devices` lists them; an unknown device is named.
#[test]
fn spec_proves_a_pc_driven_device_at_its_rate_and_latency() {
    let v = TWOPORT.json(&["devices", "--json"]);
    let names: Vec<&str> = v["devices"]
        .as_array()
        .unwrap()
        .iter()
        .map(|d| d["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["falcon", "haply-2diy", "touch"]);
    for name in ["falcon", "haply-2diy", "touch"] {
        let v = TWOPORT.json(&["spec", name, "--min-grasp", "2", "--json"]);
        let t = 1.0 / v["rate_hz"].as_f64().unwrap();
        assert_eq!(v["latency_s"].as_f64().unwrap(), 2.0 * t);
        let b = v["grasp_b_max_nspm"].as_f64().unwrap();
        let rigid = |b: f64| 2.0 * b / (9.0 * t);
        let k = v["grasp_k_npm"].as_f64().unwrap();
        assert!(
            (k - rigid(b)).abs() < 1e-3 * k,
            "{name}: {k} vs {}",
            rigid(b)
        );
        let off = v["hands_off_k_npm"].as_f64().unwrap();
        assert!((off - rigid(b - 2.0)).abs() < 1e-3 * off, "{name}: {off}");
    }
    let v = TWOPORT.json(&["spec", "falcon", "--json"]);
    assert!(v["chai3d_k_npm"].as_f64().unwrap() > 5.0 * v["grasp_k_npm"].as_f64().unwrap());
    // The driver's coupling, and the latency its region is proven for:
    // the board image's.
    let image = twoport_board::linkage::falcon_pc::IMAGE.coupling;
    assert_eq!(v["driven_k_npm"].as_f64(), Some(f64::from(image.k_npm)));
    assert_eq!(
        v["driven_latency_s"].as_f64(),
        Some(f64::from(twoport_board::linkage::pc::LATENCY_S))
    );
    // What is plugged in: every serial port, each with its path.
    let ports = TWOPORT.json(&["devices", "--json"]);
    assert!(ports["ports"]
        .as_array()
        .unwrap()
        .iter()
        .all(|p| p["path"].is_string()));
    let v = TWOPORT.json(&["spec", "touch", "--json"]);
    assert_eq!(v["chai3d_k_npm"].as_f64(), Some(400.0));
    let touch = twoport_board::linkage::touch::IMAGE.coupling;
    assert_eq!(v["driven_k_npm"].as_f64(), Some(f64::from(touch.k_npm)));
    let e = TWOPORT.failure(&["spec", "omni"]);
    assert!(
        e.contains("omni") && e.contains("falcon, haply-2diy, touch"),
        "{e}"
    );
    let e = TWOPORT.failure(&["spec", "falcon", "--min-grasp", "nan"]);
    assert!(e.contains("--min-grasp"), "{e}");
}
