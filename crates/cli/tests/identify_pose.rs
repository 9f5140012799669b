//! `twoport identify-pose` as a user runs it: a linkage's sines at a pose
//! in, the mass and joint losses there and the coupling proven on them
//! out, and bad arguments and records refused with what is wrong.

#[path = "../../../tests/support/sine_body.rs"]
mod body;
#[path = "../../../tests/support/cli.rs"]
mod support;

use std::path::{Path, PathBuf};
use support::scratch;
use twoport_design::linkage::LinkageFile;
use twoport_identify::log;

/// `twoport`, run from the repository root.
const TWOPORT: support::Tool = support::Tool {
    bin: env!("CARGO_BIN_EXE_twoport"),
    root: concat!(env!("CARGO_MANIFEST_DIR"), "/../.."),
};

const HAPKIT: &str = "models/linkages/hapkit.toml";

/// The Hapkit's file, read from the repository.
fn hapkit() -> LinkageFile {
    LinkageFile::load(&Path::new(TWOPORT.root).join(HAPKIT)).unwrap()
}

/// A level of the Hapkit's sines at its centre ([`body::sine_body`]):
/// its handle as the file has it there (the mass and damping of its
/// pose, the motor's friction at the handle), read in the sensor's
/// steps, the sine peaking at `peak` (N), written as `x-x.csv` in a
/// folder of `dir`.
fn level(dir: &Path, peak: f64) -> PathBuf {
    let file = hapkit();
    let pose = file.pose(&[0.0]).unwrap();
    let (m, b) = (pose.mass_kg[(0, 0)], pose.damping_nspm[(0, 0)]);
    let j = pose.jacobian[(0, 0)];
    let c = file.joints.friction_nm[0] / j;
    let quantum = j * std::f64::consts::TAU / f64::from(file.motors.encoder_counts_per_rev);
    let log = body::sine_log(m, b, c, quantum, peak);
    let dir = dir.join(format!("{peak}N"));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("x-x.csv"), log.to_csv()).unwrap();
    dir
}

/// Three levels on the Hapkit, read in its sensor's 37 µm steps: its
/// motor's damping and friction back within 2%, its mass within 2%, the coupling proven on the
/// fit within 3% of the one on the file's own pose, and the set's no
/// stiffer.
#[test]
fn identify_pose_finds_the_joints_losses_and_proves_a_coupling() {
    let dir = scratch("identify-pose");
    let levels: Vec<PathBuf> = [0.25, 0.5, 1.0].iter().map(|&p| level(&dir, p)).collect();
    let mut args = vec!["identify-pose", "--linkage", HAPKIT, "--pose-rad", "0"];
    for l in &levels {
        args.extend(["--level", l.to_str().unwrap()]);
    }
    args.push("--json");
    let v = TWOPORT.json(&args);
    let file = hapkit();
    let near = |got: &serde_json::Value, want: f64, tol: f64| {
        let g = got.as_f64().unwrap();
        assert!((g / want - 1.0).abs() < tol, "{g} against {want}: {v}");
    };
    near(
        &v["joints"]["damping_nmsprad"][0],
        file.joints.damping_nmsprad[0],
        0.02,
    );
    near(
        &v["joints"]["friction_nm"][0],
        file.joints.friction_nm[0],
        0.02,
    );
    let pose = file.pose(&[0.0]).unwrap();
    near(&v["mass_kg"][0][0], pose.mass_kg[(0, 0)], 0.02);
    let k = &v["design_npm"];
    near(&k["fit"], k["file"].as_f64().unwrap(), 0.03);
    assert!(
        k["set"].as_f64().unwrap() <= k["file"].as_f64().unwrap(),
        "{v}"
    );
    assert_eq!(v["experiments"].as_array().unwrap().len(), 3);
    // The text names what a user runs.
    let out = TWOPORT.run(&args[..args.len() - 1]);
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(
        text.contains("the set") && text.contains("(run this one)"),
        "{text}"
    );
    std::fs::remove_dir_all(dir).unwrap();
}

/// Bad arguments and records are refused with what is wrong.
#[test]
fn identify_pose_refuses_bad_arguments_and_records() {
    let dir = scratch("identify-pose-bad");
    let (low, high) = (level(&dir, 0.25), level(&dir, 1.0));
    let (low, high) = (low.to_str().unwrap(), high.to_str().unwrap());
    let empty = dir.join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    let empty = empty.to_str().unwrap();
    let run = |extra: &[&str]| {
        let mut args = vec!["identify-pose", "--linkage", HAPKIT];
        args.extend(extra);
        TWOPORT.failure(&args)
    };
    let both = ["--level", low, "--level", high];
    // At the pose `q`, both levels, and `more`.
    let with = |q: &'static str, more: &[&'static str]| -> Vec<&str> {
        let mut v = vec!["--pose-rad", q];
        v.extend(both);
        v.extend(more);
        v
    };
    for (extra, want) in [
        (with("0,1", &[]), "has 1 joints"),
        (with("20", &[]), "outside"),
        (vec!["--pose-rad", "0", "--level", low], "two levels"),
        (
            vec!["--pose-rad", "0", "--level", low, "--level", empty],
            "x-x.csv",
        ),
        (with("0", &["--min-grasp", "-1"]), "--min-grasp -1"),
        (with("0", &["--skip", "30"]), "periods"),
    ] {
        let e = run(&extra);
        assert!(e.contains(want), "{extra:?}: {e}");
    }
    let e = TWOPORT.failure(&[
        "identify-pose",
        "--linkage",
        "models/nowhere.toml",
        "--pose-rad",
        "0",
        "--level",
        low,
        "--level",
        high,
    ]);
    assert!(e.contains("nowhere.toml"), "{e}");
    std::fs::remove_dir_all(dir).unwrap();
}
