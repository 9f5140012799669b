//! Absolute stability in the time domain (issue 7 §4): the interface at the
//! designed gains, terminated by random passive humans (paper Fig. 3: a
//! relaxed or maximum grasp in series with a random mass-spring-damper arm)
//! and random linear passive VEs (a cursor mass, a fixed point, a
//! spring-damper to an anchor), simulated with the board's own servo. None
//! may be unstable. The theory covers linear passive terminations; a wall
//! that makes and breaks contact is a nonlinear VE and is not drawn here.

use host_sim::engine::plant::Arm;
use host_sim::engine::scene::{Coupling, Integration, VeSpec};
use host_sim::{Scene, Simulation};
use proptest::prelude::*;
use proptest::test_runner::{Config, TestCaseError, TestRunner};
use std::path::Path;
use twoport_control::servo::Display;

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

/// A random arm whose own ringing the criterion can tell from a
/// sustained one: an arm decays at `b/2m` at the slowest, and one slower
/// than the criterion's threshold (`ζω` of 0.36 rad/s, with a factor of
/// three to spare) rings on by itself, whatever the interface does (an
/// 8 kg arm on 1 N s/m, 0.06 rad/s, kept 71% a second against a stable
/// interface).
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
        .prop_filter("an arm that rings on by itself", |a| {
            a.damping_nspm / (2.0 * a.mass_kg) > 3.0 * 0.36
        })
}

fn ve() -> impl Strategy<Value = VeSpec> {
    ve_within(20.0, (0.1, 1e4))
}

/// A cursor of 0.25 kg to `max_mass_kg`, a spring (100 N/m to 10 MN/m)
/// whose damping is log-uniform over `damping_nspm`, or a bilateral
/// constraint.
fn ve_within(max_mass_kg: f64, damping_nspm: (f64, f64)) -> impl Strategy<Value = VeSpec> {
    prop_oneof![
        log_uniform(0.25, max_mass_kg).prop_map(|mass_kg| VeSpec::Cursor {
            mass_kg,
            integration: Integration::Implicit
        }),
        (
            log_uniform(1e2, 1e7),
            log_uniform(damping_nspm.0, damping_nspm.1)
        )
            .prop_map(|(k, b)| VeSpec::Spring {
                anchor_m: -0.001,
                stiffness_npm: k,
                damping_nspm: b,
                discretization: Default::default()
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
    let ve = ve_within(50.0, (0.001, 10.0));
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
    let root = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/.."));
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
            "k" => {
                if let Coupling::Impedance { k, .. } = &mut s.coupling {
                    *k = *v;
                }
            }
            "m" => {
                if let Coupling::Admittance { m, .. } = &mut s.coupling {
                    *m = *v;
                }
            }
            _ => unreachable!(),
        }
    }
    s.duration_s = 2.5;
    s.ve = c.ve.clone();
    s.human.grasp = if c.grasp_max {
        host_sim::engine::human::GraspKind::Maximum
    } else {
        host_sim::engine::human::GraspKind::Relaxed
    };
    s.human.arm = c.arm;
    // A short push on the handle, then the termination alone.
    s.human.script = vec![host_sim::engine::human::Event::Force {
        at_s: 0.1,
        force_n: c.push_n.into(),
        for_s: 0.02,
    }];
    let r = Simulation::new(s).unwrap().run(|_| {});
    if r.stable {
        Ok(())
    } else {
        Err(r.reason.unwrap_or_default())
    }
}

/// The same draws on every run: a verdict must not depend on the day.
fn search(display: Display, cases: u32, set: &[(&str, f64)]) -> Result<(), TestCaseError> {
    let config = Config {
        cases,
        failure_persistence: None,
        ..Config::default()
    };
    let seed = [0x5eu8; 32];
    let rng = proptest::test_runner::TestRng::from_seed(
        proptest::test_runner::RngAlgorithm::ChaCha,
        &seed,
    );
    let mut runner = TestRunner::new_with_rng(config, rng);
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

/// The designer's Excalibur at T = 1 ms.
fn excalibur_plant() -> twoport_design::Plant {
    twoport_design::analysis::Analysis::excalibur()
        .plant()
        .clone()
}

/// The designer's view of the impedance display at the VE port, hand off:
/// `p22 = Y_cc + 1/Z_cI` at each of `f_hz` for coupling stiffness `k`
/// (b = 90).
fn designer_p22(
    plant: &twoport_design::Plant,
    k: f64,
    f_hz: &[f64],
) -> Vec<num_complex::Complex64> {
    use twoport_design::analysis::*;
    use twoport_design::network::*;
    let omegas: Vec<f64> = f_hz
        .iter()
        .map(|f| 2.0 * std::f64::consts::PI * f)
        .collect();
    let zc = impedance_coupling_tf(k, 90.0, plant.period_s()).unwrap();
    Analysis::on(plant, &omegas)
        .points
        .iter()
        .map(|p| with_impedance_coupling(&impedance_display(p, None), zc.eval(p.z))[1][1])
        .collect()
}

/// The impedance display past its bound, against the termination the
/// two-port names. 20% past the bound (`k = 1.2 k_max` at `b = 90 N s/m`)
/// the interface's `p22` has a negative real part near 82 Hz: with the hand
/// off, a VE of impedance `-1/p22` there closes the loop with a pole on the
/// unit circle, and one with less damping puts it outside. That VE is a
/// spring of about 37,000 N/m with 3.9 N s/m. The board's backward-Euler
/// spring cannot be it (its spring part alone damps `kT/2 = 19 N s/m`
/// there, which is why random searches over backward-Euler VEs never found
/// this case); the lossless trapezoidal spring can.
///
/// Simulated with the board's code: with half the marginal damping the
/// oscillation grows (slowly: x1.5 per second, so the run is 10 s), and the
/// same VE at the designed gain decays.
#[test]
fn impedance_gains_past_the_bound_meet_the_termination_the_two_port_names() {
    use twoport_design::analysis::*;
    use twoport_design::network::HumanBound;
    let plant = excalibur_plant();
    let t = plant.period_s();
    let a = Analysis::new(&plant, GridSpec::DEFAULT);
    let human = Some(HumanBound::PAPER);
    let k_max = max_stiffness(&a, &a.impedance_bound(human), 90.0).unwrap();
    let k = 1.2 * k_max;
    let worst = check_impedance(&a, k, 90.0, human)
        .unwrap()
        .worst_frequency_hz;
    // The most negative Re p22 near the worst frequency.
    let fs: Vec<f64> = (0..=400).map(|i| worst - 4.0 + 0.02 * i as f64).collect();
    let (f, p) = fs
        .iter()
        .copied()
        .zip(designer_p22(&plant, k, &fs))
        .min_by(|x, y| x.1.re.total_cmp(&y.1.re))
        .unwrap();
    assert!(
        p.re < 0.0,
        "Re p22 = {} at {f} Hz: the bound is violated",
        p.re
    );
    // -1/p22 as a trapezoidal spring b - j (kT/2) cot(wT/2).
    let ze = -p.inv();
    let half_angle = std::f64::consts::PI * f * t;
    let k_e = -2.0 * ze.im * half_angle.tan() / t;
    let b_e = ze.re;
    assert!(
        k_e > 0.0 && b_e > 0.0,
        "passive: k_e {k_e}, b_e {b_e} at {f} Hz"
    );
    let run = |k_c: f64, discretization| {
        let mut s = base(Display::Impedance);
        if let Coupling::Impedance { k, .. } = &mut s.coupling {
            *k = k_c;
        }
        s.duration_s = 10.0;
        s.ve = VeSpec::Spring {
            anchor_m: 0.0,
            stiffness_npm: k_e,
            damping_nspm: 0.5 * b_e,
            discretization,
        };
        s.human.grasp = host_sim::engine::human::GraspKind::HandsOff;
        s.human.script = vec![host_sim::engine::human::Event::Force {
            at_s: 0.1,
            force_n: 30.0.into(),
            for_s: 0.005,
        }];
        Simulation::new(s).unwrap().run(|_| {})
    };
    use host_sim::engine::scene::Discretization::{BackwardEuler, Trapezoidal};
    let past = run(k, Trapezoidal);
    assert!(
        !past.stable,
        "k = {k:.0} N/m against a {k_e:.0} N/m, {:.2} N s/m trapezoidal spring \
         ({f:.2} Hz) should be unstable: {past:?}",
        0.5 * b_e
    );
    let at = run(k_max, Trapezoidal);
    assert!(at.stable, "the designed k = {k_max:.0} N/m: {at:?}");
    // The same spring by backward Euler damps itself: stable past the bound.
    let be = run(k, BackwardEuler);
    assert!(be.stable, "backward Euler: {be:?}");
}

/// The interface the designer analyses is the one the simulator runs, seen
/// from the VE port: drive the VE velocity with a sinusoid through the
/// board's impedance-display servo around the simulated Excalibur (hand
/// off) and the force the coupling applies is `-v / p22` of the designer,
/// within 1e-3, across the 82 Hz violation and on both sides of the bound.
#[test]
fn the_simulated_ve_port_impedance_is_the_designers() {
    use twoport_control::ve::{Causality, Port, VeOutput, VeTransfer, VirtualEnvironment};
    use twoport_control::{
        Encoder, ImpedanceGains, Integrator, Position, SafetyConfig, Servo, SineProbe, ZTransfer,
    };
    /// A VE that is a velocity source, moves as it says, and records the
    /// force it meets.
    struct VelocitySource {
        v: f32,
        f: f32,
        x: Integrator,
    }
    impl VirtualEnvironment for VelocitySource {
        fn causality(&self) -> Causality {
            Causality::Admittance
        }
        fn step(&mut self, port: Port) -> VeOutput {
            let o = port.at(self.v);
            self.f = o.force_n;
            self.x.step(self.v);
            o
        }
        fn reset(&mut self, x: Position) {
            self.x.reset(x);
        }
        fn position(&self) -> Position {
            self.x.position()
        }
        fn offset_m(&self, from: Position) -> f32 {
            self.x.offset_m(from)
        }
        fn tf(&self) -> VeTransfer {
            VeTransfer::Admittance(ZTransfer::first_order([0.0, 0.0], 0.0))
        }
    }
    let plant = excalibur_plant();
    for k in [51_074.0, 61_289.0] {
        for bin in [320u32, 329, 337] {
            let f_hz = bin as f64 / 4.0;
            let mut s = base(Display::Impedance);
            if let Coupling::Impedance { k: k_c, .. } = &mut s.coupling {
                *k_c = k;
            }
            s.duration_s = 20.0;
            s.human.script = vec![];
            let mut sim = Simulation::new(s).unwrap();
            let safety = SafetyConfig {
                max_velocity_mps: 100.0,
                ..SafetyConfig::excalibur()
            };
            let enc = Encoder::new(32, 1000, 0, Position::ZERO).unwrap(); // the sim's ideal 1 nm counts
            let ve = VelocitySource {
                v: 0.0,
                f: 0.0,
                x: Integrator::new(1e-3, Position::ZERO),
            };
            let mut servo = Servo::new(
                [ImpedanceGains::new(k as f32, 90.0).into()],
                [enc],
                [safety],
                ve,
            )
            .unwrap();
            servo.enable().unwrap();
            let th = 2.0 * std::f64::consts::PI * bin as f64 / 4000.0;
            let z_net = SineProbe::measure(th.cos(), th.sin(), 6000, 4000, |u| {
                servo.world_mut().v = (1e-3 * u) as f32;
                sim.step_external(&mut |frame| servo.tick(frame));
                (1e-3 * u, -servo.world().f as f64)
            });
            let want = designer_p22(&plant, k, &[f_hz])[0].inv();
            let err = (z_net - want).norm() / want.norm();
            assert!(
                err < 1e-3,
                "k {k} at {f_hz} Hz: simulated {z_net}, designer {want}"
            );
        }
    }
}
