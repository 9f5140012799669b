//! Absolute stability in the time domain (issue 7 §4): the interface at the
//! designed gains, terminated by random passive humans (paper Fig. 3: a
//! relaxed or maximum grasp in series with a random mass-spring-damper arm)
//! and random linear passive VEs (a cursor mass, a fixed point, a
//! spring-damper to an anchor), simulated with the board's own servo. None
//! may be unstable. The theory covers linear passive terminations; a wall
//! that makes and breaks contact is a nonlinear VE and is not drawn here.

use host_sim::plant::Arm;
use host_sim::scene::{Display, VeSpec};
use host_sim::{Scene, Simulation};
use proptest::prelude::*;
use proptest::test_runner::{Config, TestCaseError, TestRunner};
use std::path::Path;

/// One random termination.
#[derive(Clone, Debug)]
struct Case {
    arm: Option<Arm>,
    grasp_max: bool,
    ve: VeSpec,
    push_n: f64,
}

fn log_uniform(lo: f64, hi: f64) -> impl Strategy<Value = f64> {
    (lo.ln()..hi.ln()).prop_map(f64::exp)
}

fn arm() -> impl Strategy<Value = Arm> {
    (
        log_uniform(0.01, 10.0),
        log_uniform(0.1, 1e5),
        log_uniform(1.0, 1e7),
    )
        .prop_map(|(mass_kg, damping_nspm, stiffness_npm)| Arm {
            mass_kg,
            damping_nspm,
            stiffness_npm,
        })
}

fn ve() -> impl Strategy<Value = VeSpec> {
    prop_oneof![
        log_uniform(0.25, 20.0).prop_map(|mass_kg| VeSpec::Cursor { mass_kg }),
        (log_uniform(1e2, 1e7), log_uniform(0.1, 1e4)).prop_map(|(k, b)| VeSpec::Spring {
            anchor_m: -0.001,
            stiffness_npm: k,
            damping_nspm: b,
            discretization: Default::default(),
        }),
        Just(VeSpec::Bilateral),
    ]
}

/// Terminations aimed at one frequency (Hz): an arm resonating near it and
/// nearly lossless terminations, where a violated Llewellyn bound says an
/// unstable pair must exist.
fn tuned_case(f_hz: f64) -> impl Strategy<Value = Case> {
    let w = 2.0 * std::f64::consts::PI * f_hz;
    let arm = (
        log_uniform(0.01, 5.0),
        0.6..1.6f64,
        log_uniform(0.001, 10.0),
    )
        .prop_map(move |(m, r, b)| Arm {
            mass_kg: m,
            damping_nspm: b,
            stiffness_npm: m * (r * w) * (r * w),
        });
    let ve = prop_oneof![
        log_uniform(0.25, 50.0).prop_map(|mass_kg| VeSpec::Cursor { mass_kg }),
        (log_uniform(1e2, 1e7), log_uniform(0.001, 10.0)).prop_map(|(k, b)| VeSpec::Spring {
            anchor_m: -0.001,
            stiffness_npm: k,
            damping_nspm: b,
            discretization: Default::default(),
        }),
        Just(VeSpec::Bilateral),
    ];
    (arm.prop_map(Some), any::<bool>(), ve, -30.0..30.0f64).prop_map(
        |(arm, grasp_max, ve, push_n)| Case {
            arm,
            grasp_max,
            ve,
            push_n,
        },
    )
}

fn case() -> impl Strategy<Value = Case> {
    (
        prop::option::weighted(0.8, arm()),
        any::<bool>(),
        ve(),
        -30.0..30.0f64,
    )
        .prop_map(|(arm, grasp_max, ve, push_n)| Case {
            arm,
            grasp_max,
            ve,
            push_n,
        })
}

fn base(display: Display) -> Scene {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let file = match display {
        Display::Impedance => "scenes/table1/impedance_bilateral_hands_off.toml",
        Display::Admittance => "scenes/table1/admittance_bilateral_hands_off.toml",
    };
    let mut s = Scene::load(&root.join(file), &[]).unwrap();
    s.plant.model = root.join("models/excalibur.toml");
    s
}

/// Simulate `c` on `display` with coupling override `set`; the failure
/// reason if not stable.
fn stable(display: Display, c: &Case, set: &[(&str, f64)]) -> Result<(), String> {
    let mut s = base(display);
    for (k, v) in set {
        match *k {
            "k" => s.coupling.k = Some(*v),
            "m" => s.coupling.m = Some(*v),
            _ => unreachable!(),
        }
    }
    s.duration_s = 2.5;
    s.ve = c.ve.clone();
    s.human.grasp = if c.grasp_max {
        host_sim::human::GraspKind::Maximum
    } else {
        host_sim::human::GraspKind::Relaxed
    };
    s.human.arm = c.arm;
    // A short push on the handle, then the termination alone.
    s.human.script = vec![host_sim::human::Event::Force {
        at_s: 0.1,
        force_n: c.push_n,
        for_s: 0.02,
    }];
    let r = Simulation::new(s).unwrap().run(|_| {});
    if r.stable {
        Ok(())
    } else {
        Err(r.reason.unwrap_or_default())
    }
}

fn search(display: Display, cases: u32, set: &[(&str, f64)]) -> Result<(), TestCaseError> {
    let mut runner = TestRunner::new(Config {
        cases,
        failure_persistence: None,
        ..Config::default()
    });
    runner
        .run(&case(), |c| {
            if let Err(why) = stable(display, &c, set) {
                return Err(TestCaseError::fail(format!("unstable ({why}): {c:?}")));
            }
            Ok(())
        })
        .map_err(|e| TestCaseError::fail(e.to_string()))
}

#[test]
fn designed_gains_survive_random_passive_terminations() {
    search(Display::Impedance, 150, &[]).unwrap();
    search(Display::Admittance, 150, &[]).unwrap();
}

/// The full count (10^4 per display) runs in release in CI.
#[test]
#[ignore = "2 x 10^4 simulations: run with --release --ignored (CI does)"]
fn designed_gains_survive_ten_thousand_random_passive_terminations() {
    search(Display::Impedance, 10_000, &[]).unwrap();
    search(Display::Admittance, 10_000, &[]).unwrap();
}

/// Draw cases until one is unstable; the first found, if any.
fn find_unstable(
    strategy: impl Strategy<Value = Case>,
    display: Display,
    set: &[(&str, f64)],
    max_cases: u32,
    seed: u64,
) -> Option<(Case, String)> {
    use proptest::strategy::ValueTree;
    use proptest::test_runner::RngAlgorithm;
    let mut seed_bytes = [0u8; 32];
    seed_bytes[..8].copy_from_slice(&seed.to_le_bytes());
    let mut runner = TestRunner::new_with_rng(
        Config::default(),
        proptest::test_runner::TestRng::from_seed(RngAlgorithm::ChaCha, &seed_bytes),
    );
    (0..max_cases).find_map(|_| {
        let c = strategy.new_tree(&mut runner).ok()?.current();
        stable(display, &c, set).err().map(|why| (c, why))
    })
}

/// Past the bound the theory promises an unstable passive termination;
/// aimed at the worst frequency the designer reports (19.6 Hz), the search
/// finds one for the admittance display with the coupling mass 20% below
/// the least stable one (4.998 kg / 1.2).
///
/// For the impedance display no draw from this family (whose spring VEs are
/// backward-Euler, and so damped at high frequency) finds one even 50% past
/// the bound; see the next test for the lossless termination that does.
#[test]
fn admittance_gains_past_the_bound_meet_an_unstable_termination() {
    let found = find_unstable(
        tuned_case(19.6),
        Display::Admittance,
        &[("m", 4.998 / 1.2)],
        2_000,
        7,
    );
    let (c, why) = found.expect("an unstable passive termination");
    assert!(
        why.contains("oscillation") || why.contains("tripped"),
        "{why}: {c:?}"
    );
}

/// The impedance display past its bound, against the termination the
/// two-port points to. Past the bound the interface's `p22 = Y_cc + 1/Z_cI`
/// has a negative real part near 82 Hz, so with the hand off a nearly
/// lossless spring VE tuned there should destabilise the loop. The board's
/// backward-Euler spring cannot be that VE (its spring part alone damps
/// `kT/2`, 17-28 N s/m at 82 Hz for these stiffnesses); the trapezoidal
/// spring is lossless and can.
///
/// Found in the time domain with the board's code: a 56,000 N/m trapezoidal
/// spring with the hand off is unstable at 70,000 N/m (1.37 k_max), and
/// stable at the designed 51,074 N/m. At 1.2 k_max it still decays (late
/// RMS ratio about 0.5; the marginal coupling is about 66,000 N/m): the
/// simulated loop is better damped near 82 Hz than the designer's two-port
/// by roughly 8 N s/m, which is why the 20%-past search of issue 7 is not
/// met for this display yet.
#[test]
fn impedance_gains_past_the_bound_meet_a_lossless_termination() {
    let run = |k_c: f64| {
        let mut s = base(Display::Impedance);
        s.coupling.k = Some(k_c);
        s.duration_s = 2.5;
        s.ve = VeSpec::Spring {
            anchor_m: 0.0,
            stiffness_npm: 56_000.0,
            damping_nspm: 0.0,
            discretization: host_sim::scene::Discretization::Trapezoidal,
        };
        s.human.grasp = host_sim::human::GraspKind::HandsOff;
        s.human.script = vec![host_sim::human::Event::Force {
            at_s: 0.1,
            force_n: 5.0,
            for_s: 0.02,
        }];
        Simulation::new(s).unwrap().run(|_| {})
    };
    let past = run(70_000.0);
    assert!(!past.stable, "70,000 N/m should be unstable: {past:?}");
    let at = run(51_074.0);
    assert!(at.stable, "the designed gain: {at:?}");
    // The same VE discretised by backward Euler damps itself: stable even
    // at 70,000 N/m.
    let mut s = base(Display::Impedance);
    s.coupling.k = Some(70_000.0);
    s.duration_s = 2.5;
    s.ve = VeSpec::Spring {
        anchor_m: 0.0,
        stiffness_npm: 56_000.0,
        damping_nspm: 0.0,
        discretization: host_sim::scene::Discretization::BackwardEuler,
    };
    s.human.grasp = host_sim::human::GraspKind::HandsOff;
    let be = Simulation::new(s).unwrap().run(|_| {});
    assert!(be.stable, "backward Euler: {be:?}");
}
