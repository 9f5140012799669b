//! `host-sim` as a user runs it: JSON on stdout, CSV columns, sweeps, the
//! Table I command, and errors with exit code 2.

#[path = "../../tests/support/cli.rs"]
mod support;

use std::path::Path;
use std::process::Command;

/// `host-sim`, run from the repository root.
const HOST_SIM: support::Tool = support::Tool {
    bin: env!("CARGO_BIN_EXE_host-sim"),
    root: concat!(env!("CARGO_MANIFEST_DIR"), "/.."),
};

#[test]
fn run_json_has_the_documented_fields() {
    let v = HOST_SIM.json(&["run", "scenes/stiff_wall.toml", "--duration", "3", "--json"]);
    for key in [
        "stable",
        "peak_force_n",
        "energy_in_j",
        "sim_seconds",
        "wall_seconds",
        "realtime_factor",
        "effects",
    ] {
        assert!(v.get(key).is_some(), "missing {key}: {v}");
    }
    assert_eq!(v["stable"], true);
    assert!((v["sim_seconds"].as_f64().unwrap() - 3.0).abs() < 1e-9);
    let names: Vec<&str> = v["effects"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["flexibility", "encoder", "saturation"]);
    let peak = v["peak_force_n"].as_f64().unwrap();
    assert!(peak > 5.0 && peak <= 200.0, "{peak}");
}

#[test]
fn set_overrides_any_value_and_a_big_gain_is_unstable() {
    let v = HOST_SIM.json(&[
        "run",
        "scenes/table1/impedance_bilateral_hands_off.toml",
        "--set",
        "coupling.k=1e6",
        "--json",
    ]);
    assert_eq!(v["stable"], false);
    assert!(v["reason"].as_str().unwrap().len() > 5);
}

#[test]
fn csv_has_one_row_per_tick_and_the_documented_columns() {
    let path = std::env::temp_dir().join(format!("host-sim-{}.csv", std::process::id()));
    let png = path.with_extension("png");
    HOST_SIM.json(&[
        "run",
        "scenes/vbb_blocks.toml",
        "--duration",
        "2",
        "--csv",
        path.to_str().unwrap(),
        "--png",
        png.to_str().unwrap(),
        "--json",
    ]);
    let text = std::fs::read_to_string(&path).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next().unwrap(),
        "t_s,handle_position_m,handle_velocity_mps,human_force_n,commanded_force_n,actuator_force_n,ve_position_m,ve_force_n"
    );
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 2000);
    assert!(rows
        .iter()
        .all(|r| r.len() == 8 && r.iter().all(|x| x.is_finite())));
    // The hand moves the handle; the VE (the grabbed block) follows it.
    let last = rows.last().unwrap();
    assert!(
        last[1] > 0.02 && (last[1] - last[6]).abs() < 0.005,
        "{last:?}"
    );
    assert_eq!(&std::fs::read(&png).unwrap()[1..4], b"PNG");
}

#[test]
fn sweep_finds_a_marginal_gain_between_stable_and_unstable() {
    let v = HOST_SIM.json(&[
        "sweep",
        "scenes/table1/impedance_bilateral_hands_off.toml",
        "--param",
        "coupling.k",
        "--from",
        "51000",
        "--to",
        "1000000",
        "--tol",
        "0.02",
        "--json",
    ]);
    assert_eq!(v["param"], "coupling.k");
    let k = v["marginal"].as_f64().unwrap();
    assert!(k > 51_000.0 && k < 1_000_000.0, "{k}");
    let stable = HOST_SIM.json(&[
        "run",
        "scenes/table1/impedance_bilateral_hands_off.toml",
        "--set",
        &format!("coupling.k={k}"),
        "--json",
    ]);
    assert_eq!(stable["stable"], true);
    let past = HOST_SIM.json(&[
        "run",
        "scenes/table1/impedance_bilateral_hands_off.toml",
        "--set",
        &format!("coupling.k={}", k * 1.05),
        "--json",
    ]);
    assert_eq!(past["stable"], false);
}

/// The command's JSON (the table itself is tested in the library, by
/// tests/study.rs): one case copied to a folder of its own.
#[test]
fn table1_json_has_the_documented_fields() {
    let dir = std::env::temp_dir().join(format!("host-sim-table1-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scene = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../scenes/table1/impedance_bilateral_hands_off.toml");
    std::fs::copy(&scene, dir.join("impedance_bilateral_hands_off.toml")).unwrap();
    let v = HOST_SIM.json(&["table1", "--scenes", dir.to_str().unwrap(), "--json"]);
    std::fs::remove_dir_all(&dir).ok();
    let cases = v["cases"].as_array().unwrap();
    assert_eq!(cases.len(), 1);
    assert_eq!(cases[0]["case"], "impedance_bilateral_hands_off");
    assert_eq!(cases[0]["display"], "impedance");
    assert_eq!(cases[0]["stable_at_theoretical_gains"], true);
    assert!(cases[0]["marginal"].as_f64().unwrap() > 51_000.0);
    assert_eq!(v["all_stable_at_theoretical_gains"], true);
    assert!(v["impedance_boundary_k"].as_f64().unwrap() > 51_000.0);
    assert!(v["admittance_boundary_m"].is_null());
}

#[test]
fn errors_name_the_problem_and_exit_2() {
    for (args, want) in [
        (
            vec!["run", "no/such/scene.toml"],
            "no/such/scene.toml: cannot read",
        ),
        (
            vec!["run", "scenes/stiff_wall.toml", "--set", "coupling.b=-1"],
            "coupling.b = -1",
        ),
        (
            vec!["run", "scenes/stiff_wall.toml", "--set", "nonsense"],
            "expected key=value",
        ),
        (
            vec![
                "sweep",
                "scenes/stiff_wall.toml",
                "--param",
                "coupling.k",
                "--from",
                "1000",
                "--to",
                "2000",
            ],
            "stable at both",
        ),
    ] {
        let out = HOST_SIM.run(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let e = String::from_utf8_lossy(&out.stderr);
        assert!(e.contains(want), "{args:?}: {e}");
    }
}

#[test]
fn with_no_display_the_scope_says_so_and_runs_headless() {
    let out = Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .current_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/.."))
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .expect("run host-sim");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("no display"), "{err}");
    assert!(err.contains("headless"), "{err}");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("Stiff wall") && text.contains("stable"),
        "{text}"
    );
}

#[test]
fn a_screenshot_without_a_display_is_a_clear_error() {
    let out = Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .args(["--screenshot", "/tmp/never.png", "--exit-after", "1"])
        .current_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/.."))
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .expect("run host-sim");
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("--screenshot needs a window"), "{err}");
}

/// Every subcommand `host-sim --help` lists has its row in the crate's
/// README, and the README lists none that is gone.
#[test]
fn the_readme_lists_every_subcommand() {
    let out = Command::new(HOST_SIM.bin).arg("--help").output().unwrap();
    let help = String::from_utf8_lossy(&out.stdout);
    let listed: Vec<&str> = help
        .lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter_map(|l| l.split_whitespace().next())
        .filter(|c| *c != "help")
        .collect();
    assert!(listed.len() >= 7, "{help}");
    let readme =
        std::fs::read_to_string(Path::new(HOST_SIM.root).join("host-sim/README.md")).unwrap();
    let rows: Vec<&str> = readme
        .lines()
        .filter_map(|l| l.strip_prefix("| `"))
        .filter_map(|l| l.split('`').next())
        .collect();
    for c in &listed {
        assert!(rows.contains(c), "README lacks `{c}`: {rows:?}");
    }
    for r in &rows {
        assert!(
            listed.contains(r),
            "README lists `{r}`, which --help does not"
        );
    }
}

/// A reader that stops early (`| head`) ends the report quietly: no
/// panic, exit code 0, as any Unix filter does. (The pipe is closed before
/// the report's first line, so every write meets it closed.)
#[test]
fn a_closed_pipe_ends_the_report_quietly() {
    HOST_SIM.closes_quietly(&["table1"]);
}

#[test]
fn teleop_reports_both_sides_and_writes_both_to_its_csv() {
    let path = std::env::temp_dir().join(format!("host-sim-teleop-{}.csv", std::process::id()));
    let v = HOST_SIM.json(&[
        "teleop",
        "scenes/teleop/rigid_pair.toml",
        "--set",
        "duration_s=2",
        "--csv",
        path.to_str().unwrap(),
        "--json",
    ]);
    assert_eq!(v["stable"], true, "{v}");
    for side in ["master", "slave"] {
        assert!(v[side]["peak_force_n"].as_f64().unwrap() > 0.0, "{v}");
    }
    assert!(v["tracking_rms_m"].as_f64().unwrap() > 0.0, "{v}");
    let text = std::fs::read_to_string(&path).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(
        header[..3],
        ["t_s", "master_position_m", "slave_position_m"]
    );
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 2_000);
    assert!(rows.iter().all(|r| r.len() == header.len()));
    // The tap moved the master first and the slave after it.
    let first_moved = |col: usize| rows.iter().position(|r| r[col] != 0.0).unwrap();
    assert!(first_moved(1) < first_moved(2));
    let _ = std::fs::remove_file(&path);
    // 20% past the proven spring the same tap grows.
    let v = HOST_SIM.json(&[
        "teleop",
        "scenes/teleop/rigid_pair.toml",
        "--set",
        "law.gains.k_m_npm=600",
        "--set",
        "law.gains.k_s_npm=600",
        "--json",
    ]);
    assert_eq!(v["stable"], false, "{v}");
}
