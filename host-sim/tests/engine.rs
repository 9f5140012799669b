//! The simulator's acceptance tests (issue 4 §9): the paper's theoretical
//! gains are stable in every Table I case for 10 s; a gain far past the
//! bound is detected; RK4 converges to the exact-ZOH trajectory; the exact
//! ZOH plant conserves energy without damping; effects run only when named.

use host_sim::engine::plant::{Grasp, Method, SimDevice, Stepper};
use host_sim::{Scene, Simulation};
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn scene(rel: &str, sets: &[&str]) -> Scene {
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    let mut s = Scene::load(&root().join(rel), &sets).unwrap();
    s.plant.model = root().join("models/excalibur.toml");
    s
}

fn run(rel: &str, sets: &[&str]) -> host_sim::Report {
    Simulation::new(scene(rel, sets)).unwrap().run(|_| {})
}

#[test]
fn theoretical_gains_are_stable_in_every_table1_case_for_10_s() {
    let dir = root().join("scenes/table1");
    let mut n = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let rel = format!(
            "scenes/table1/{}",
            path.file_name().unwrap().to_string_lossy()
        );
        let r = run(&rel, &["duration_s=10"]);
        assert!(r.stable, "{rel}: {:?}", r.reason);
        assert!((r.sim_seconds - 10.0).abs() < 1e-9, "{rel} stopped early");
        n += 1;
    }
    assert_eq!(n, 18, "2 displays x 3 VE states x 3 grasps");
}

#[test]
fn gains_far_past_the_bound_are_detected_unstable() {
    let r = run(
        "scenes/table1/impedance_bilateral_hands_off.toml",
        &["coupling.k=1e6"],
    );
    assert!(!r.stable, "k = 1e6 N/m must be unstable");
    let r = run(
        "scenes/table1/admittance_free_maximum.toml",
        &["coupling.m=0.1"],
    );
    assert!(!r.stable, "m = 0.1 kg must be unstable");
    // And the detector, not the safety layer alone: with the velocity limit
    // out of reach, an undamped oscillation is still found.
    let mut s = scene(
        "scenes/table1/impedance_bilateral_maximum.toml",
        &["coupling.k=400000"],
    );
    s.effects.saturation = Some(host_sim::engine::scene::SaturationEffect { limit_n: 20.0 });
    let r = Simulation::new(s).unwrap().run(|_| {});
    assert!(!r.stable, "{r:?}");
}

/// The RK4 trajectory of a linear closed-loop scene converges to the exact
/// ZOH one as the sub-step shrinks: at 64 sub-steps per tick (h = 15.6 us)
/// the handle path differs by less than 1e-6 of its peak displacement.
#[test]
fn rk4_converges_to_exact_zoh() {
    let base = "scenes/table1/impedance_bilateral_maximum.toml";
    let path = |sets: &[&str]| {
        let mut xs = Vec::new();
        Simulation::new(scene(base, sets))
            .unwrap()
            .run(|s| xs.push(s.handle_m[0]));
        xs
    };
    let exact = path(&[]);
    let peak = exact.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let err = |n: u32| {
        let sets = ["integrator.on_linear=true", "integrator.method=\"rk4\""];
        let sub = format!("integrator.substeps={n}");
        let mut all: Vec<&str> = sets.to_vec();
        all.push(&sub);
        let p = path(&all);
        p.iter()
            .zip(&exact)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max)
            / peak
    };
    let (e16, e64) = (err(16), err(64));
    eprintln!("RK4 vs exact ZOH, max handle error / peak: x16 {e16:.2e}, x64 {e64:.2e}");
    assert!(e64 <= 1e-6, "RK4 x64: {e64:e} of peak");
    assert!(e64 < e16, "converging: x16 {e16:e}, x64 {e64:e}");
}

/// With D = 0 and no input, the exact discrete map conserves the device's
/// energy: after 10^5 ticks it is unchanged to 1e-9.
#[test]
fn exact_zoh_conserves_energy_without_damping() {
    let model = twoport_design::DeviceModel::load(&root().join("models/excalibur.toml")).unwrap();
    let dev = SimDevice::flexible(&model).unwrap().without_damping();
    let sys = dev.system(
        Grasp {
            damping_nspm: 0.0,
            stiffness_npm: 0.0,
            arm: None,
        },
        false,
    );
    let mut st = Stepper::new(&sys, Method::ExactZoh, 1e-3).unwrap();
    let n = dev.n;
    // Internal vibration only: no net momentum, so the coordinates stay
    // bounded (a rigid drift would make q^T K q cancel catastrophically).
    let mut x = vec![0.0; 2 * n];
    for i in 0..n {
        x[i] = 1e-5 * (i as f64 + 1.0);
        x[n + i] = 0.01 * (1.0 - i as f64 * 0.3);
    }
    let mass: Vec<f64> = (0..n)
        .map(|i| (0..n).map(|j| dev.mass(i, j)).sum())
        .collect();
    let p: f64 = (0..n).map(|i| mass[i] * x[n + i]).sum::<f64>() / mass.iter().sum::<f64>();
    for i in 0..n {
        x[n + i] -= p;
    }
    let start = x.clone();
    let e0 = dev.energy(&x);
    for _ in 0..100_000 {
        st.step(&mut x, [0.0, 0.0], None);
    }
    let e1 = dev.energy(&x);
    assert!(((e1 - e0) / e0).abs() < 1e-9, "{e0} J -> {e1} J");
    // RK4 at 16 sub-steps, from the same state, does not: it damps the
    // fast modes numerically.
    let mut rk = Stepper::new(&sys, Method::Rk4, 1e-3 / 16.0).unwrap();
    let mut y = start;
    for _ in 0..16_000 {
        rk.step(&mut y, [0.0, 0.0], None);
    }
    assert!(
        (dev.energy(&y) - e0).abs() / e0 > 1e-3,
        "RK4 should not conserve it"
    );
    // The same with damping loses energy: the test can fail.
    let damped = SimDevice::flexible(&model).unwrap().system(
        Grasp {
            damping_nspm: 0.0,
            stiffness_npm: 0.0,
            arm: None,
        },
        false,
    );
    let mut st = Stepper::new(&damped, Method::ExactZoh, 1e-3).unwrap();
    st.step(&mut x, [0.0, 0.0], None);
    assert!(dev.energy(&x) < e1);
}

#[test]
fn linear_scenes_run_exact_zoh_and_only_named_effects() {
    let r = run("scenes/table1/impedance_free_relaxed.toml", &[]);
    assert_eq!((r.integrator.as_str(), r.substeps), ("exact_zoh", 1));
    let names: Vec<&str> = r.effects.iter().map(|e| e.name.as_str()).collect();
    assert_eq!(names, ["flexibility"]);
    let r = run(
        "scenes/table1/impedance_free_relaxed.toml",
        &[
            "effects.coulomb.force_n=2.0",
            "integrator.substeps=40",
            "effects.encoder.resolution_m=1e-6",
        ],
    );
    assert_eq!((r.integrator.as_str(), r.substeps), ("rk4", 40));
    let names: Vec<&str> = r.effects.iter().map(|e| e.name.as_str()).collect();
    assert_eq!(names, ["flexibility", "encoder", "coulomb"]);
    assert!(r.stable, "{:?}", r.reason);
}

/// Explicit Euler cannot integrate the 3.5 kHz mode at a practical step:
/// the run says so before it starts and fails with the reason.
#[test]
fn an_unstable_explicit_integrator_is_reported() {
    let r = run(
        "scenes/table1/impedance_free_relaxed.toml",
        &[
            "integrator.on_linear=true",
            "integrator.method=\"euler\"",
            "integrator.substeps=20",
        ],
    );
    let w = r.integrator_warning.as_deref().expect("a warning");
    assert!(w.contains("euler") && w.contains("Hz mode"), "{w}");
    assert!(!r.stable);
    assert!(
        r.reason.as_deref().unwrap_or("").contains("integrator"),
        "{:?}",
        r.reason
    );
    let ok = run(
        "scenes/table1/impedance_free_relaxed.toml",
        &[
            "integrator.on_linear=true",
            "integrator.method=\"rk4\"",
            "integrator.substeps=20",
        ],
    );
    assert!(ok.integrator_warning.is_none() && ok.stable, "{ok:?}");
}

#[test]
fn bad_scene_files_name_the_line_and_field() {
    let text = std::fs::read_to_string(root().join("scenes/stiff_wall.toml")).unwrap();
    let bad = text.replace("stiffness_npm = 5.0e6", "stiffness_npm = \"hard\"");
    let e = Scene::parse(&bad, "wall.toml", &[])
        .unwrap_err()
        .to_string();
    let line = bad.lines().position(|l| l.contains("\"hard\"")).unwrap() + 1;
    assert!(e.contains(&format!("wall.toml: line {line}")), "{e}");
    let e = Scene::parse(
        &text.replace("[coupling]\nk =", "[coupling]\nkk ="),
        "w",
        &[],
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("kk"), "{e}");
    let e = Scene::parse(&text, "w", &["coupling.b=-3".into()])
        .unwrap_err()
        .to_string();
    assert!(e.contains("coupling.b = -3"), "{e}");
    let e = Scene::parse(&text, "w", &["display=\"admittance\"".into()])
        .unwrap_err()
        .to_string();
    assert!(e.contains("coupling.m is required"), "{e}");
    for (sets, want) in [
        (
            &["effects.latency.seconds=-1e-4"][..],
            "effects.latency = -0.0001 s",
        ),
        (
            &["effects.latency.periods=2000"][..],
            "from 0 to 1000 periods",
        ),
        (
            &[
                "effects.latency.periods=0.5",
                "effects.latency.seconds=1e-4",
            ][..],
            "give one of seconds or periods",
        ),
    ] {
        let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
        let e = Scene::parse(&text, "w", &sets).unwrap_err().to_string();
        assert!(e.contains(want), "{sets:?}: {e}");
    }
    // A coupling is one display's: its keys say which, and a mix, or too
    // few, is refused with the line and what is wrong.
    for (set, want) in [
        (
            "coupling.m=5.0",
            "m belongs to an admittance display's coupling",
        ),
        ("plant.handle_mass_kg=-0.5", "plant.handle_mass_kg"),
        (
            "coupling.k=",
            "give k and b (impedance display), or kp, bp, m and b",
        ),
    ] {
        let text = if set.ends_with('=') {
            text.lines()
                .filter(|l| !l.starts_with("k = "))
                .collect::<Vec<_>>()
                .join("\n")
        } else {
            text.clone()
        };
        let sets: Vec<String> = if set.ends_with('=') {
            vec![]
        } else {
            vec![set.into()]
        };
        let e = Scene::parse(&text, "w", &sets).unwrap_err().to_string();
        assert!(e.starts_with("w") && e.contains(want), "{set}: {e}");
    }
    let e = Scene::parse(
        &text,
        "w",
        &[
            "display=\"admittance\"".into(),
            "coupling={kp=51000.0,bp=90.0,b=500.0}".into(),
            "effects.load_cell=true".into(),
        ],
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("m is required for an admittance display's coupling"),
        "{e}"
    );
    let e = Scene::parse(
        &text,
        "w",
        &[
            "effects.cable_slack.width_m=1e-4".into(),
            "effects.flexibility=false".into(),
        ],
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("cable_slack needs the flexible model"), "{e}");
    for (set, want) in [
        (
            "effects.hard_stop={position_m=-5.0}",
            "effects.hard_stop.position_m = -5 must be within ±1 m",
        ),
        (
            "effects.hard_stop={position_m=-0.02,stiffness_npm=0.0}",
            "effects.hard_stop.stiffness_npm",
        ),
        (
            "effects.hard_stop={position_m=-0.02,solid=\"left\"}",
            "unknown variant `left`",
        ),
    ] {
        let e = Scene::parse(&text, "w", &[set.into()])
            .unwrap_err()
            .to_string();
        assert!(e.contains(want), "{set}: {e}");
    }
}

/// The rigid 3.9 kg, 20 N s/m device behind a wall `k` (N/m, `b = 0`)
/// with the force held `alpha` of a tick late: the design crate's exact
/// discrete loop's spectral radius (hands off, the bilateral constraint).
fn exact_wall_radius(alpha: f64, k: f64) -> f64 {
    use twoport_control::{Gains, ImpedanceGains};
    use twoport_design::verify::{radius, Hand, Termination, Ve};
    let model = twoport_design::DeviceModel::from_toml(
        &format!(
            "period_s = 0.001\npeak_force_n = 50.0\ncontinuous_force_n = 20.0\n\
             latency_s = {:e}\nM = [[3.9]]\nD = [[20.0]]\nK = [[0.0]]\n\
             G = [[1.0, -1.0]]\nC_v = [[1.0], [-1.0]]\n",
            alpha * 1e-3
        ),
        "rigid",
    )
    .unwrap();
    let term = Termination {
        hand: Hand::OFF,
        ve: Ve::Constraint,
    };
    let g: Gains = ImpedanceGains::new(k as f32, 0.0).into();
    radius(&model, 1e-3, &g, &term).unwrap().spectral_radius
}

/// The wall's boundary stiffness (N/m) there, by bisection.
fn exact_wall_boundary(alpha: f64) -> f64 {
    let (mut lo, mut hi) = (1e3f64, 1e6f64);
    for _ in 0..50 {
        let mid = (lo * hi).sqrt();
        if exact_wall_radius(alpha, mid) < 1.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

/// The simulator holds the force `effects.latency` after the sample (the
/// hold switches inside the tick). On the rigid device behind a wall, 5%
/// either side of the exact loop's boundary with that latency, the
/// handle's swing grows or decays a tick at the exact loop's rate (its
/// spectral radius), to a tenth of the rate, at half a tick and at 0.9 of
/// one, in periods or in seconds; and a hair under a tick runs as a whole
/// tick's delay does.
#[test]
fn a_latency_moves_the_simulators_boundary_to_the_exact_loops() {
    let rel = "scenes/table1/impedance_bilateral_hands_off.toml";
    for (alpha, latency) in [
        (0.5, "effects.latency.periods=0.5"),
        (0.9, "effects.latency.seconds=0.0009"),
    ] {
        let k = exact_wall_boundary(alpha);
        let none = exact_wall_boundary(0.0);
        assert!(k < 0.8 * none, "α {alpha}: {k} vs {none} without");
        for f in [0.95, 1.05] {
            let kc = format!("coupling.k={}", f * k);
            let sets = ["effects.flexibility=false", "coupling.b=0", latency, &kc];
            let mut sim = Simulation::new(scene(rel, &sets)).unwrap();
            let x: Vec<f64> = (0..5000).map(|_| sim.step().handle_m[0]).collect();
            let swing = |from: usize| {
                x[from..from + 1000]
                    .iter()
                    .fold(0.0f64, |m, v| m.max(v.abs()))
            };
            // A second after the last push (at 2 s), and a second later.
            let rate = (swing(4000) / swing(3000)).ln() / 1000.0;
            let want = exact_wall_radius(alpha, f * k).ln();
            assert!(
                (rate - want).abs() < 0.1 * want.abs(),
                "α {alpha}, {f} x {k}: the swing grows {rate:e} a tick, the exact loop {want:e}"
            );
        }
    }
    let r = run(
        rel,
        &["effects.flexibility=false", "effects.latency.periods=0.25"],
    );
    let names: Vec<&str> = r.effects.iter().map(|e| e.name.as_str()).collect();
    assert_eq!(names, ["latency"]);
    // Within a thousandth of a tick of a whole tick's delay, the handle
    // moves as it does with the delay.
    let path = |sets: &[&str]| {
        let mut s = Simulation::new(scene(rel, sets)).unwrap();
        (0..3000)
            .map(|_| s.step().handle_m[0])
            .collect::<Vec<f64>>()
    };
    let base = [
        "effects.flexibility=false",
        "coupling.k=5000",
        "coupling.b=0",
    ];
    let late = path(&[&base[..], &["effects.latency.periods=0.999"]].concat());
    let delayed = path(&[&base[..], &["effects.delay.ticks=1"]].concat());
    let peak = delayed.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let off = late
        .iter()
        .zip(&delayed)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(peak > 0.0 && off < 0.01 * peak, "{off} of {peak}");
}
