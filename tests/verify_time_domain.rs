//! `twoport verify`'s counterexamples are real: the termination it names,
//! simulated by host-sim with the board's own f32 servo (not the z-forms
//! `verify` analyses), grows at the rate the spectral radius says, and the
//! same termination at the designed gain does not.

use host_sim::engine::human::{Event, GraspKind};
use host_sim::engine::plant::Arm;
use host_sim::engine::scene::{Coupling, Discretization, VeSpec};
use host_sim::{Scene, Simulation};
use std::path::Path;
use twoport_control::{Gains, ImpedanceGains};
use twoport_design::analysis::*;
use twoport_design::network::HumanBound;
use twoport_design::verify::{radius, verify, Hand, Termination, Ve};
use twoport_design::DeviceModel;

const T: f64 = 1e-3;

fn scene(k: f64, b: f64, hand: &twoport_design::verify::Hand, ve: &Ve) -> Scene {
    let mut s = scene_on("models/excalibur.toml", k, b, ve);
    assert!(
        hand.grasp.is_some() && hand.hanging.is_empty(),
        "the simulator's hand is the grasp plus an arm of one mass"
    );
    s.human.grasp = GraspKind::Maximum;
    s.human.arm = Some(Arm {
        mass_kg: hand.mass_kg,
        damping_nspm: hand.damping_nspm,
        stiffness_npm: hand.stiffness_npm,
    });
    s
}

/// An impedance-display scene of the model file `model` (flexible, no
/// other effect), hands off, with the VE `ve` and one small push.
fn scene_on(model: &str, k: f64, b: f64, ve: &Ve) -> Scene {
    let root = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/.."));
    let mut s = Scene::load(
        &root.join("scenes/table1/impedance_bilateral_hands_off.toml"),
        &[],
    )
    .unwrap();
    s.plant.model = root.join(model);
    s.coupling = Coupling::Impedance { k, b };
    s.duration_s = 6.0;
    let spring = |stiffness_npm, damping_nspm, discretization| VeSpec::Spring {
        anchor_m: 0.0,
        stiffness_npm,
        damping_nspm,
        discretization,
    };
    s.ve = match *ve {
        Ve::TrapezoidalSpring {
            stiffness_npm: k,
            damping_nspm: b,
        } => spring(k, b, Discretization::Trapezoidal),
        Ve::Spring {
            stiffness_npm: k,
            damping_nspm: b,
        } => spring(k, b, Discretization::BackwardEuler),
        Ve::Cursor { mass_kg } => VeSpec::Cursor {
            mass_kg,
            integration: host_sim::engine::scene::Integration::Implicit,
        },
        Ve::LosslessMass { mass_kg } => VeSpec::Cursor {
            mass_kg,
            integration: host_sim::engine::scene::Integration::Lossless,
        },
        Ve::Constraint => VeSpec::Bilateral,
    };
    s.human.script = vec![Event::Force {
        at_s: 0.05,
        force_n: 2.0.into(),
        for_s: 0.005,
    }];
    s
}

/// Peak |actuator force| in a window of the run (N).
fn peaks(s: Scene, windows: &[(f64, f64)]) -> Vec<f64> {
    let mut out = vec![0.0f64; windows.len()];
    Simulation::new(s).unwrap().run(|x| {
        for (o, (a, b)) in out.iter_mut().zip(windows) {
            if x.t_s >= *a && x.t_s < *b {
                *o = o.max(x.actuator_n[0].abs());
            }
        }
    });
    out
}

#[test]
#[ignore = "release only: run with --release --ignored (CI does)"]
fn verifys_counterexample_grows_in_the_simulator_at_its_rate() {
    let model = DeviceModel::excalibur().unwrap();
    let a = Analysis::of(&model).unwrap();
    let human = Some(HumanBound::PAPER);
    let k_max = max_stiffness(&a, &a.impedance_bound(human), 90.0).unwrap();
    let past = Gains::from(ImpedanceGains::new((1.2 * k_max) as f32, 90.0));
    let v = verify(&model, T, &past, human).unwrap();
    assert!(v.unstable, "{v:?}");
    let (hand, ve) = (v.termination.hand.clone(), v.termination.ve);
    // Growth between two windows a second apart, against rho^(1 s / T).
    let w = [(4.0, 4.5), (5.0, 5.5)];
    let p = peaks(scene(1.2 * k_max, 90.0, &hand, &ve), &w);
    let simulated = p[1] / p[0];
    let predicted = v.spectral_radius.powf(1.0 / T);
    eprintln!("growth per second: simulated x{simulated:.3}, verify x{predicted:.3}");
    assert!(
        simulated > 1.5 && (simulated.ln() / predicted.ln() - 1.0).abs() < 0.15,
        "simulated x{simulated:.3}/s, verify says x{predicted:.3}/s ({v:?}, peaks {p:?})"
    );
    // The same termination at 90% of the designed stiffness decays.
    let below = Gains::from(ImpedanceGains::new((0.9 * k_max) as f32, 90.0));
    let r = radius(&model, T, &below, &v.termination).unwrap();
    assert!(r.spectral_radius < 1.0, "{r:?}");
    let p = peaks(scene(0.9 * k_max, 90.0, &hand, &ve), &w);
    assert!(p[1] < p[0], "decays at 0.9 k_max: {p:?}");
}

/// A device that declares a measurement-to-actuation delay runs it in the
/// simulator too: a rigid 1 kg, 20 N s/m handle with a one-tick delay is
/// proven to 10,000 N/m (2b/((d+1)^2 T)); verify breaks 13,000 N/m, the
/// worst hands-off VE does too by its spectral radius, and the simulator
/// agrees for the delayed model and not for the same device without the
/// delay.
#[test]
#[ignore = "release only: run with --release --ignored (CI does)"]
fn a_declared_delay_enters_the_simulator() {
    let dir = std::env::temp_dir().join(format!("twoport-delay-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let model = |d: u32| {
        format!(
            "name = \"rigid, {d}-tick delay\"\nperiod_s = 0.001\npeak_force_n = 200.0\n\
             continuous_force_n = 100.0\ndelay_samples = {d}\nM = [[1.0]]\nD = [[20.0]]\n\
             K = [[0.0]]\nG = [[1.0, -1.0]]\nC_v = [[1.0], [-1.0]]\n"
        )
    };
    let (delayed, prompt) = (dir.join("delayed.toml"), dir.join("prompt.toml"));
    std::fs::write(&delayed, model(1)).unwrap();
    std::fs::write(&prompt, model(0)).unwrap();
    let m = DeviceModel::load(&delayed).unwrap();
    let a = Analysis::of(&m).unwrap();
    let k_max = max_stiffness(&a, &a.impedance_bound(None), 0.0).unwrap();
    assert!((k_max - 10_000.0).abs() < 50.0, "{k_max}");
    let past = Gains::from(ImpedanceGains::new(13_000.0, 0.0));
    let v = verify(&m, T, &past, None).unwrap();
    assert!(v.unstable, "{v:?}");
    // The simulator's hand is a grasp plus an arm, so it replays the worst
    // hands-off termination among verify's VE families (a hand that is a
    // spring to ground, as verify's may be, it cannot hold).
    let hands_off = Hand {
        mass_kg: 1e-4,
        stiffness_npm: 0.1,
        damping_nspm: 1e-4,
        grasp: None,
        hanging: Vec::new(),
    };
    let worst = (0..25)
        .flat_map(|i| {
            let m_kg = 10f64.powf(-2.0 + i as f64 / 8.0);
            [
                Ve::Cursor { mass_kg: m_kg },
                Ve::LosslessMass { mass_kg: m_kg },
            ]
        })
        .map(|ve| {
            let t = Termination {
                hand: hands_off.clone(),
                ve,
            };
            (radius(&m, T, &past, &t).unwrap(), ve)
        })
        .max_by(|a, b| a.0.spectral_radius.total_cmp(&b.0.spectral_radius))
        .unwrap();
    assert!(worst.0.unstable, "{worst:?}");
    let run = |path: &Path| {
        let mut s = scene_on(path.to_str().unwrap(), 13_000.0, 0.0, &worst.1);
        s.human.grasp = GraspKind::HandsOff;
        Simulation::new(s).unwrap().run(|_| {})
    };
    let (d, p) = (run(&delayed), run(&prompt));
    std::fs::remove_dir_all(&dir).ok();
    assert!(
        !d.stable,
        "the delayed device at 13,000 N/m: {d:?} ({worst:?})"
    );
    assert!(p.stable, "the same device without the delay: {p:?}");
}
