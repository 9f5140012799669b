//! `twoport identify` as a user runs it: bench records of a rigid handle
//! in, each axis's model, set and figures out, and bad records and
//! arguments refused with what is wrong.

#[path = "../../../tests/support/cli.rs"]
mod support;

use std::path::PathBuf;
use support::scratch;

/// `twoport`, run from the repository root.
const TWOPORT: support::Tool = support::Tool {
    bin: env!("CARGO_BIN_EXE_twoport"),
    root: concat!(env!("CARGO_MANIFEST_DIR"), "/../.."),
};

/// A bench record of the capstan handle (0.25 kg, 2 N s/m): a multisine
/// of 1 to 300 Hz at 1 kHz, the exact sampled motion, and 1 nm of noise
/// on the encoder. `tweak` edits the samples before they are written.
fn capstan_record(
    dir: &std::path::Path,
    name: &str,
    tweak: impl Fn(&mut twoport_identify::log::Log),
) -> PathBuf {
    record_of(dir, name, 0.25, 300, tweak)
}

/// [`capstan_record`] of a handle of `m` kg, played up to `top_hz`.
fn record_of(
    dir: &std::path::Path,
    name: &str,
    m: f64,
    top_hz: u32,
    tweak: impl Fn(&mut twoport_identify::log::Log),
) -> PathBuf {
    use twoport_control::multisine::Multisine;
    let (b, t, period, periods) = (2.0_f64, 1e-3_f64, 1000u32, 8u32);
    let ms = Multisine::new(period, 1, top_hz, 2.0).unwrap();
    let a = (-b * t / m).exp();
    let (mut x, mut v) = (0.0_f64, 0.0_f64);
    let mut seed = 0x2545_f491_u64;
    let (mut force, mut position) = (Vec::new(), Vec::new());
    for n in 0..period * periods {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        let noise = ((seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 2e-9;
        let f = ms.at(n) as f64;
        force.push(f);
        position.push(x + noise);
        // The exact motion under a force held over the tick.
        x += m / b * (1.0 - a) * v + (t / b - m * (1.0 - a) / (b * b)) * f;
        v = a * v + (1.0 - a) / b * f;
    }
    let mut log = twoport_identify::log::Log {
        period_s: t,
        force_n: force,
        position_m: position,
        load_cell_n: None,
        excitation: Some(twoport_identify::log::Excitation::Periodic {
            period_ticks: period as usize,
            first: 1,
            last: top_hz as usize,
        }),
    };
    tweak(&mut log);
    let path = dir.join(format!("{name}.csv"));
    std::fs::write(&path, log.to_csv()).unwrap();
    path
}

/// `identify` on two records of a rigid handle, the axes x and y: one
/// mass each, its mass and damping back, each axis's model, set and
/// figures written, and the two device files over both axes. (That a
/// design for the set holds for the true device is the release tests'
/// part: `host-sim/tests/identify.rs`.)
#[test]
fn identify_writes_each_axis_and_the_device_files() {
    let dir = scratch("identify");
    let (x, y) = (
        capstan_record(&dir, "x", |_| {}),
        capstan_record(&dir, "y", |_| {}),
    );
    let out = dir.join("out");
    let o = out.to_str().unwrap();
    let v = TWOPORT.json(&[
        "identify",
        x.to_str().unwrap(),
        y.to_str().unwrap(),
        "--out",
        o,
        "--peak-force",
        "10",
        "--continuous-force",
        "4",
        "--plot",
        "svg",
        "--json",
    ]);
    let axes = v["axes"].as_array().unwrap();
    assert_eq!(axes.len(), 2, "{v}");
    for a in axes {
        assert_eq!(a["chosen"]["modes"], 0, "{v}");
        assert_eq!(a["chosen"]["form"], "chain");
        assert!(a["coherence_min"].as_f64().unwrap() > 0.99, "{v}");
    }
    for f in [
        "device.toml",
        "set.toml",
        "x/model.toml",
        "y/model.toml",
        "x/encoder.svg",
        "y/coherence.svg",
    ] {
        assert!(out.join(f).is_file(), "{f} not written");
    }
    let model = std::fs::read_to_string(out.join("x/model.toml")).unwrap();
    let fitted = twoport_design::DeviceModel::from_toml(&model, "model.toml").unwrap();
    assert!((fitted.m[(0, 0)] / 0.25 - 1.0).abs() < 0.01, "{model}");
    assert!((fitted.d[(0, 0)] / 2.0 - 1.0).abs() < 0.05, "{model}");
    // device.toml: each axis its fit; set.toml: each axis its set, every
    // model the fit's form with the damping lowered by the doubt (5%).
    let device = twoport_design::Device::load(&out.join("device.toml")).unwrap();
    let names: Vec<&str> = device.axes.iter().map(|a| a.name.as_str()).collect();
    assert_eq!(names, ["x", "y"]);
    assert_eq!(device.axes[0].models, std::slice::from_ref(&fitted));
    let set = twoport_design::Device::load(&out.join("set.toml")).unwrap();
    for (axis, a) in set.axes.iter().zip(axes) {
        assert_eq!(
            axis.models.len(),
            a["set_models"].as_u64().unwrap() as usize
        );
        assert!(axis.models.iter().all(|p| p.dof() == 1));
    }
    assert!((set.axes[0].models[0].d[(0, 0)] / fitted.d[(0, 0)] - 0.95).abs() < 1e-9);
    std::fs::remove_dir_all(dir).unwrap();
}

/// A loaded record (the capstan with 0.1 kg on its handle) is fitted with
/// the bare one: the chosen fit is the joint one, and the handle's mass
/// comes back.
#[test]
fn identify_fits_a_loaded_record_with_the_bare_one() {
    let dir = scratch("identify-loaded");
    let x = capstan_record(&dir, "x", |_| {});
    let loaded = record_of(&dir, "x-loaded", 0.35, 300, |_| {});
    let out = dir.join("out");
    let v = TWOPORT.json(&[
        "identify",
        x.to_str().unwrap(),
        "--loaded",
        &format!("x={}", loaded.display()),
        "--added-mass",
        "0.1",
        "--out",
        out.to_str().unwrap(),
        "--peak-force",
        "10",
        "--continuous-force",
        "4",
        "--json",
    ]);
    let a = &v["axes"][0];
    let orders = a["orders"].as_array().unwrap();
    assert_eq!(orders.last().unwrap()["loaded"], true, "{v}");
    assert_eq!(a["chosen"]["modes"], 0, "{v}");
    assert!(
        a["record"]
            .as_str()
            .unwrap()
            .contains("0.1 kg on the handle"),
        "{v}"
    );
    let model = std::fs::read_to_string(out.join("x/model.toml")).unwrap();
    let fitted = twoport_design::DeviceModel::from_toml(&model, "model.toml").unwrap();
    assert!((fitted.m[(0, 0)] / 0.25 - 1.0).abs() < 0.01, "{model}");
    std::fs::remove_dir_all(dir).unwrap();
}

/// Bad records and arguments are refused with what is wrong.
#[test]
fn identify_refuses_bad_records_and_arguments() {
    let dir = scratch("identify-bad");
    let out = dir.join("out");
    let o = out.to_str().unwrap().to_string();
    // `identify RECORD` with the amplifier's numbers and `extra`.
    let args = |record: &PathBuf, extra: &[&str]| -> Vec<String> {
        let record = record.to_str().unwrap();
        let base = ["identify", record, "--out", &o, "--peak-force", "10"];
        let amp = ["--continuous-force", "4"];
        base.iter()
            .chain(&amp)
            .chain(extra)
            .map(|a| a.to_string())
            .collect()
    };
    let run = |record: &PathBuf, extra: &[&str], ok: bool| {
        let a = args(record, extra);
        let a: Vec<&str> = a.iter().map(String::as_str).collect();
        if ok {
            TWOPORT.json(&a).to_string()
        } else {
            TWOPORT.failure(&a)
        }
    };
    let fail = |record: &PathBuf, extra: &[&str]| run(record, extra, false);
    let good = capstan_record(&dir, "capstan", |_| {});
    for (extra, want) in [
        (
            &["--load-cell-pole", "235"][..],
            "has no load_cell_n column",
        ),
        (&["--sigmas", "-1"][..], "--sigmas -1"),
        (&["--damping-doubt", "1"][..], "--damping-doubt 1"),
        (&["--skip", "7"][..], "whole periods"),
        (&["--added-mass", "0.1"][..], "give them"),
        (&["--loaded", "capstan=x.csv"][..], "--added-mass (kg)"),
        (
            &["--loaded", "capstan=x.csv", "--added-mass", "-1"][..],
            "--added-mass -1",
        ),
        (
            &["--loaded", "y=x.csv", "--added-mass", "0.1"][..],
            "no record names the axis \"y\"",
        ),
        (
            &["--loaded", "x.csv", "--added-mass", "0.1"][..],
            "give it as AXIS=PATH",
        ),
        (
            &["--loaded", "capstan=nowhere.csv", "--added-mass", "0.1"][..],
            "nowhere.csv",
        ),
    ] {
        let e = fail(&good, extra);
        assert!(e.contains(want), "{extra:?}: {e}");
    }
    type Tweak = dyn Fn(&mut twoport_identify::log::Log);
    let cases: [(&Tweak, &str); 3] = [
        (
            &|l| l.force_n.iter_mut().for_each(|f| *f = f.clamp(-1.0, 1.0)),
            "the force is clipped",
        ),
        (
            &|l| l.load_cell_n = Some(vec![0.0; l.force_n.len()]),
            "give its filter pole with --load-cell-pole",
        ),
        (&|l| l.force_n[10] *= 100.0, "past --peak-force"),
    ];
    for (tweak, want) in cases {
        let e = fail(&capstan_record(&dir, "capstan", tweak), &[]);
        assert!(e.contains(want) && e.contains("capstan.csv"), "{want}: {e}");
    }
    // A record another program wrote has no experiment line: without
    // --excitation it is refused, saying how to name one; with it, read.
    let bare = dir.join("elsewhere.csv");
    let text = std::fs::read_to_string(capstan_record(&dir, "made", |_| {})).unwrap();
    std::fs::write(&bare, text.lines().skip(1).collect::<Vec<_>>().join("\n")).unwrap();
    let e = fail(&bare, &[]);
    assert!(
        e.contains("--excitation") && e.contains("elsewhere.csv"),
        "{e}"
    );
    let said = "period_ticks = 1000, first = 1, last = 300";
    let read: serde_json::Value =
        serde_json::from_str(&run(&bare, &["--excitation", said, "--json"], true)).unwrap();
    let axis = &read["axes"][0];
    assert_eq!(axis["chosen"]["modes"], 0, "{axis}");
    for (words, want) in [
        ("period_ticks = 1000, first = 1, last = 200", "give one"),
        (
            "stepped, step_ticks = -3",
            "--excitation \"stepped, step_ticks = -3\"",
        ),
    ] {
        let e = fail(
            &capstan_record(&dir, "made", |_| {}),
            &["--excitation", words],
        );
        assert!(e.contains(want), "{words}: {e}");
    }
    // Played to 50 Hz at 1 kHz: short of the fifth of the sampling rate
    // a design needs.
    let narrow = record_of(&dir, "narrow", 0.25, 50, |_| {});
    let e = fail(&narrow, &[]);
    assert!(
        e.contains("narrow.csv") && e.contains("stops at 50.0 Hz") && e.contains("200.0 Hz"),
        "{e}"
    );
    let e = fail(&dir.join("missing.csv"), &[]);
    assert!(e.contains("missing.csv"), "{e}");
    // Two records of one name would be one axis twice.
    let other = dir.join("again");
    std::fs::create_dir_all(&other).unwrap();
    let twin = capstan_record(&other, "capstan", |_| {});
    let e = fail(&good, &[twin.to_str().unwrap()]);
    assert!(e.contains("two records name the axis \"capstan\""), "{e}");
    std::fs::remove_dir_all(dir).unwrap();
}
