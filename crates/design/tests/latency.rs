//! A latency inside the tick: the force a tick computes is applied `τ = αT`
//! after its sample. The proof takes it through the modified z-transform
//! and the alias sums; here it is checked against an independent
//! discretisation (the rigid device's motion in closed form, stepped across
//! the switch inside the tick), against the whole-tick delay it tends to,
//! against `verify`'s exact loop, and against the passivity boundary of a
//! delayed virtual wall on a heavy device, `b > K (T/2 + τ)`.

use nalgebra::DMatrix;
use twoport_control::{Gains, ImpedanceGains};
use twoport_design::analysis::{max_stiffness, Analysis, GridSpec};
use twoport_design::verify::{radius, verify, Hand, Termination, Ve};
use twoport_design::{DeviceModel, Plant};

const T: f64 = 1e-3;

/// A rigid 1-DOF device whose force lags its sample by `latency_s`.
fn rigid(mass_kg: f64, damping_nspm: f64, latency_s: f64) -> DeviceModel {
    DeviceModel::from_toml(
        &format!(
            "period_s = 0.001\npeak_force_n = 50.0\ncontinuous_force_n = 20.0\n\
             latency_s = {latency_s:e}\nM = [[{mass_kg}]]\nD = [[{damping_nspm}]]\n\
             K = [[0.0]]\nG = [[1.0, -1.0]]\nC_v = [[1.0], [-1.0]]\n"
        ),
        "rigid",
    )
    .unwrap()
}

fn with_delay(mut m: DeviceModel, ticks: u32) -> DeviceModel {
    m.delay_samples = ticks;
    m
}

/// The greatest proven coupling stiffness at `b_c = 0`, every passive hand
/// and VE (N/m).
fn proven(m: &DeviceModel) -> f64 {
    let a = Analysis::new(&Plant::new(m, T).unwrap(), GridSpec::DEFAULT);
    max_stiffness(&a, &a.impedance_bound(None), 0.0).unwrap()
}

fn imp(k: f64, b: f64) -> Gains {
    ImpedanceGains::new(k as f32, b as f32).into()
}

/// The virtual wall `f = K x + B (x - x_prev)/T` on the rigid device `m x''
/// + b x' = -f`, its force applied `τ` after the sample, stepped over one
/// tick in closed form (the velocity and position of a mass-damper under a
/// constant force): the one-tick map on `(x, v, x_prev, f_prev)`.
fn wall_map(m: f64, b: f64, tau: f64, (k, bw): (f64, f64)) -> DMatrix<f64> {
    let step = |(x, v): (f64, f64), f: f64, h: f64| {
        let e = (-b * h / m).exp();
        let v_inf = -f / b;
        let v1 = v_inf + (v - v_inf) * e;
        let x1 = x + v_inf * h + (v - v_inf) * m / b * (1.0 - e);
        (x1, v1)
    };
    let mut a = DMatrix::zeros(4, 4);
    for c in 0..4 {
        let mut s = [0.0; 4];
        s[c] = 1.0;
        let [x, v, x_prev, f_prev] = s;
        let f = k * x + bw * (x - x_prev) / T;
        let mid = step((x, v), f_prev, tau);
        let (x1, v1) = step(mid, f, T - tau);
        for (r, val) in [x1, v1, x, f].into_iter().enumerate() {
            a[(r, c)] = val;
        }
    }
    a
}

fn spectral_radius(a: &DMatrix<f64>) -> f64 {
    a.complex_eigenvalues()
        .iter()
        .map(|l| l.norm())
        .fold(0.0, f64::max)
}

/// The exact loop `verify` builds (the delayed hold as a matrix
/// exponential over the two parts of the tick, the state holding the
/// previous force) has the radius of the wall stepped in closed form, at
/// every latency and on both sides of the boundary (to 1e-7: the two
/// eigenvalue problems differ in size and balancing, and a double root
/// near the boundary costs half the digits).
#[test]
fn the_delayed_hold_is_the_rigid_device_stepped_in_closed_form() {
    let (m, b) = (1.0, 20.0);
    for alpha in [0.0, 0.1, 0.25, 0.5, 0.75, 0.9] {
        let model = rigid(m, b, alpha * T);
        for (k, bw) in [(5_000.0, 0.0), (20_000.0, 2.0), (60_000.0, 5.0)] {
            let term = Termination {
                hand: Hand::OFF,
                ve: Ve::Constraint,
            };
            let r = radius(&model, T, &imp(k, bw), &term)
                .unwrap()
                .spectral_radius;
            // (The board's gains are f32.)
            let (kf, bf) = (f64::from(k as f32), f64::from(bw as f32));
            let want = spectral_radius(&wall_map(m, b, alpha * T, (kf, bf)));
            assert!(
                (r - want).abs() < 1e-7,
                "α {alpha}, K {k}, B {bw}: verify's loop {r}, stepped {want}"
            );
        }
    }
}

/// The proof is continuous in the latency: a latency a hair above zero
/// proves what none does (Colgate's `2b/T`), and one a hair below a tick
/// proves what a whole tick's delay does (`2b/(4T)`); past a tick it adds
/// to the whole ticks.
#[test]
#[cfg_attr(debug_assertions, ignore = "release only (CI runs it)")]
fn a_latency_tends_to_none_and_to_a_whole_tick() {
    let (m, b) = (1.0, 20.0);
    let none = proven(&rigid(m, b, 0.0));
    let tiny = proven(&rigid(m, b, 1e-6 * T));
    assert!((tiny - none).abs() < 2e-3 * none, "{tiny} vs {none}");
    let tick = proven(&with_delay(rigid(m, b, 0.0), 1));
    let almost = proven(&rigid(m, b, 0.999 * T));
    assert!((almost - tick).abs() < 2e-3 * tick, "{almost} vs {tick}");
    // 1.5 ticks of latency is a tick of delay and half a tick inside.
    let split = proven(&with_delay(rigid(m, b, 0.5 * T), 1));
    let whole = proven(&rigid(m, b, 1.5 * T));
    assert!((split - whole).abs() < 1e-9 * split, "{split} vs {whole}");
}

/// On the rigid device every passive hand and VE leave the exact loop
/// stable up to `k_c = 2b/((1 + α)² T)` at `b_c = 0` (a lossless VE mass,
/// hands off, breaks it just past). The proof stays below that at every
/// latency, as it must, and within 12% of it: letting each alias's hand
/// take its worst value on its own costs most at `α = 1/3`, where the
/// proof gives `2b/((1 + 3α) T)`.
#[test]
#[cfg_attr(debug_assertions, ignore = "release only (CI runs it)")]
fn the_rigid_proof_with_a_latency_is_sound_and_close() {
    let (m, b) = (1.0, 20.0);
    for alpha in [0.25, 1.0 / 3.0, 0.5, 0.75] {
        let model = rigid(m, b, alpha * T);
        let k = proven(&model);
        let exact = 2.0 * b / ((1.0 + alpha) * (1.0 + alpha) * T);
        assert!(k <= exact && k >= 0.88 * exact, "α {alpha}: {k} vs {exact}");
        let at = verify(&model, T, &imp(k, 0.0), None).unwrap();
        assert!(!at.unstable, "α {alpha}: the proven {k} broken: {at:?}");
        let past = verify(&model, T, &imp(1.02 * exact, 0.0), None).unwrap();
        assert!(past.unstable, "α {alpha}: nothing breaks 1.02 x {exact}");
    }
}

/// A heavy rigid device behind a delayed virtual wall is stable up to
/// about the wall's passivity boundary `b > K (T/2 + τ)` (Colgate's
/// `b > KT/2` with the delay; Hulin, Albu-Schäffer and Hirzinger), which
/// the exact loop's boundary approaches as the mass grows.
#[test]
fn a_heavy_devices_wall_boundary_is_the_delayed_passivity_bound() {
    let (m, b) = (200.0, 20.0);
    let wall = Termination {
        hand: Hand::OFF,
        ve: Ve::Constraint,
    };
    for alpha in [0.0, 0.25, 0.5, 0.75, 1.5] {
        let model = rigid(m, b, alpha * T);
        let rho = |k: f64| {
            radius(&model, T, &imp(k, 0.0), &wall)
                .unwrap()
                .spectral_radius
        };
        let (mut lo, mut hi) = (1.0f64, 1e6f64);
        for _ in 0..60 {
            let mid = (lo * hi).sqrt();
            if rho(mid) < 1.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let passive = b / (T / 2.0 + alpha * T);
        assert!(
            (lo - passive).abs() < 0.01 * passive,
            "α {alpha}: boundary {lo} vs b/(T/2 + τ) = {passive}"
        );
    }
}

/// The admittance display with half a tick of latency, on the Excalibur
/// with the human bound: the design (its own regulator, the impedance
/// design's gains) holds against `verify`'s exact loop with the force held
/// half a tick late, and 2.5% lighter it breaks; the latency costs mass
/// (and softens the regulator the impedance design gives).
#[test]
#[cfg_attr(debug_assertions, ignore = "release only (CI runs it)")]
fn an_admittance_design_with_a_latency_holds_and_breaks_just_past() {
    use twoport_control::AdmittanceGains;
    use twoport_design::network::HumanBound;
    use twoport_design::Designer;
    let mut m = DeviceModel::excalibur().unwrap();
    let none = Designer::new(vec![m.clone()], None, Some(HumanBound::PAPER)).unwrap();
    let m0 = none
        .design_admittance(None, None, 0.0)
        .unwrap()
        .coupling
        .unwrap()
        .0;
    m.latency_s = 0.5 * T;
    let d = Designer::new(vec![m], None, Some(HumanBound::PAPER)).unwrap();
    let design = d.design_admittance(None, None, 0.0).unwrap();
    let (mass, b) = design.coupling.unwrap();
    let r = design.regulator.unwrap();
    assert!(mass > 1.2 * m0, "{mass} kg against {m0} kg with none");
    let g = |mass: f64| -> Gains {
        AdmittanceGains::new(r.kp as f32, r.bp as f32, mass as f32, b as f32).into()
    };
    // (The board's gains are f32: a hair heavier than the boundary.)
    let at = d.verify(&g(mass * (1.0 + 1e-6))).unwrap().verdict;
    assert!(!at.unstable, "{at:?}");
    let past = d.verify(&g(0.975 * mass)).unwrap().verdict;
    assert!(past.unstable, "{past:?}");
}
