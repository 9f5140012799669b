//! The proof of a host VE's two-rate loop (`host_ve`) against what does
//! not share its method: the exact periodic loop's growth over one host
//! period (`verify::host`), a search of hands, and the clamped handle's
//! own boundary found by bisection. The Excalibur at 1, 4 and 10 kHz, and
//! a rigid device with and without a delay.
//!
//! Each case runs designs and searches that take a second or more in a
//! debug build, so they are ignored there; CI runs the file in release.

use twoport_design::host_ve::{check_host_ve, host_max_stiffness, HostLoop};
use twoport_design::network::HumanBound;
use twoport_design::verify::{host_radius, verify_host, Hand};
use twoport_design::{DeviceModel, Plant};

mod common;
use common::rigid;

fn excalibur(t: f64) -> (DeviceModel, Plant) {
    let m = DeviceModel::excalibur().unwrap();
    let p = Plant::new(&m, t).unwrap();
    (m, p)
}

/// The host's loop costs stiffness, more the longer the delay, and
/// damping on the host's body buys it back.
#[test]
#[cfg_attr(debug_assertions, ignore = "release only (CI runs it)")]
fn delay_costs_stiffness_and_host_damping_buys_it_back() {
    let (_, p) = excalibur(1e-3);
    let h = Some(HumanBound::PAPER);
    let k = |d: u32, damping: f64| {
        let host = HostLoop::new(1e-3, 1, d, (5.0, damping, 0.0)).unwrap();
        host_max_stiffness(&p, 90.0, h, &host).unwrap().unwrap()
    };
    let (k1, k3, k3_damped) = (k(1, 1.0), k(3, 1.0), k(3, 100.0));
    assert!(k3 < k1, "{k3} against {k1}");
    assert!(k3_damped > k3, "{k3_damped} against {k3}");
}

/// One case against the exact periodic loop: at the least damping the
/// proof asks for, the search of hands finds nothing; with no damping on
/// the body, a hand free to clamp the handle makes the loop grow; and the
/// clamped handle's own boundary (by bisection on the damping) lies below
/// what the proof asks for.
fn cross_check(m: &DeviceModel, p: &Plant, (k, b): (f64, f64), (n, d): (u32, u32), mass: f64) {
    let t = p.period_s();
    let clamp = Hand {
        mass_kg: 1e-3,
        stiffness_npm: 1e8,
        damping_nspm: 1e-3,
        grasp: None,
        hanging: Vec::new(),
    };
    {
        let (m, p) = (m, p);
        let host = |damping: f64| HostLoop::new(t, n, d, (mass, damping, 0.0)).unwrap();
        for human in [None, Some(HumanBound::PAPER)] {
            let need = check_host_ve(p, k, b, human, &host(0.0))
                .unwrap()
                .least_damping_nspm;
            assert!(need.is_finite() && need > 0.0, "T {t} N {n} d {d}: {need}");
            let at = host(1.01 * need);
            assert!(check_host_ve(p, k, b, human, &at).unwrap().proven);
            let v = verify_host(m, t, (k, b), human, &at).unwrap();
            assert!(
                !v.unstable && v.spectral_radius < 1.0,
                "T {t} N {n} d {d} human {}: B {need} proven, yet {v:?}",
                human.is_some()
            );
        }
        // With no damping on the body, a hand that is free to clamp
        // the handle makes the loop grow.
        let grows = verify_host(m, t, (k, b), None, &host(0.0)).unwrap();
        assert!(grows.unstable, "T {t} N {n} d {d}: {grows:?}");
        // The clamped handle's own boundary, by bisection on the
        // damping, lies below what the proof asks for.
        let rho = |damping: f64| {
            host_radius(m, t, (k, b), &clamp, &host(damping))
                .unwrap()
                .spectral_radius
        };
        let need = check_host_ve(p, k, b, None, &host(0.0))
            .unwrap()
            .least_damping_nspm;
        assert!(
            rho(0.0) > 1.0 && rho(need) < 1.0,
            "T {t}: {} {}",
            rho(0.0),
            rho(need)
        );
    }
}

/// The Excalibur at 1, 4 and 10 kHz, the host at 1 kHz or the servo's
/// rate, light and heavy bodies.
#[test]
#[cfg_attr(debug_assertions, ignore = "release only (CI runs it)")]
fn the_proof_holds_in_the_exact_periodic_loop_of_the_excalibur() {
    for (t, k, b, n, d, mass) in [
        (1e-3, 46_700.0, 72.2, 1u32, 2u32, 0.1),
        (1e-3, 46_700.0, 72.2, 1, 3, 10.0),
        (2.5e-4, 100_000.0, 300.0, 4, 4, 0.1),
        (1e-4, 300_000.0, 1000.0, 10, 10, 0.3),
    ] {
        let (m, p) = excalibur(t);
        cross_check(&m, &p, (k, b), (n, d), mass);
    }
}

/// A rigid, lightly damped device (1 kg, 20 N s/m), without and with a
/// tick of delay, the host at the servo's rate and at a quarter of it.
#[test]
#[cfg_attr(debug_assertions, ignore = "release only (CI runs it)")]
fn the_proof_holds_in_the_exact_periodic_loop_of_a_rigid_device() {
    use twoport_design::analysis::{max_stiffness, Analysis, GridSpec};
    for delay in [0, 1] {
        let m = rigid(1.0, 20.0, delay);
        let p = Plant::new(&m, 1e-3).unwrap();
        let a = Analysis::new(&p, GridSpec::DEFAULT);
        let b = 5.0;
        let k = 0.9 * max_stiffness(&a, &a.impedance_bound(None), b).unwrap();
        for (n, d, mass) in [(1u32, 2u32, 0.2), (4, 4, 0.5)] {
            cross_check(&m, &p, (k, b), (n, d), mass);
        }
    }
}

/// The best pair against a host body is on the proof's boundary (proven,
/// and not at 1% more stiffness), below the single-rate best pair, and a
/// longer delay lowers it.
#[test]
#[cfg_attr(debug_assertions, ignore = "release only (CI runs it)")]
fn the_best_pair_against_a_host_body_is_on_its_boundary() {
    use twoport_design::host_ve::host_best_pair;
    let (_, p) = excalibur(1e-3);
    let h = Some(HumanBound::PAPER);
    let host = |d: u32| HostLoop::new(1e-3, 1, d, (1.0, 10.0, 0.0)).unwrap();
    let (k, b) = host_best_pair(&p, h, &host(2), 72.2).unwrap().unwrap();
    assert!(check_host_ve(&p, k, b, h, &host(2)).unwrap().proven);
    assert!(!check_host_ve(&p, 1.01 * k, b, h, &host(2)).unwrap().proven);
    assert!(k < 51_889.0 && b <= 72.2, "{k} at {b}");
    let (k4, _) = host_best_pair(&p, h, &host(4), 72.2).unwrap().unwrap();
    assert!(k4 < k, "{k4} against {k}");
}

/// Many rigid, lightly damped devices (a fixed pseudo-random sweep: mass,
/// damping, the coupling at 90% of its limit, the host's period and
/// delay, the body's mass): with the least damping the proof asks for on
/// the body, the exact periodic loop decays with a clamped, a free, a
/// middling and a heavy hand.
#[test]
#[cfg_attr(debug_assertions, ignore = "release only (CI runs it)")]
fn random_rigid_devices_hold_where_the_proof_says() {
    use twoport_design::analysis::{max_stiffness, Analysis, GridSpec};
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let mut next = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let hand = |m: f64, k: f64| Hand {
        mass_kg: m,
        stiffness_npm: k,
        damping_nspm: 1e-3,
        grasp: None,
        hanging: Vec::new(),
    };
    let mut checked = 0;
    for _ in 0..12 {
        let (mass, damping) = (0.2 + 1.8 * next(), 2.0 + 38.0 * next());
        let m = rigid(mass, damping, 0);
        let p = Plant::new(&m, 1e-3).unwrap();
        let a = Analysis::new(&p, GridSpec::DEFAULT);
        let b = damping * (0.05 + 0.45 * next());
        let Some(limit) = max_stiffness(&a, &a.impedance_bound(None), b) else {
            continue;
        };
        let k = 0.9 * limit;
        let n = [1u32, 2, 4][(3.0 * next()) as usize % 3];
        let d = 1 + (2.0 * f64::from(n) * next()) as u32;
        let body = 0.05 * 100f64.powf(next());
        let host = |bh: f64| HostLoop::new(1e-3, n, d, (body, bh, 0.0)).unwrap();
        let need = check_host_ve(&p, k, b, None, &host(0.0))
            .unwrap()
            .least_damping_nspm;
        assert!(need.is_finite(), "m {mass} d {damping} b {b}: {need}");
        let at = host(1.01 * need + 1e-6);
        assert!(check_host_ve(&p, k, b, None, &at).unwrap().proven);
        let w = (k / body).sqrt();
        for h in [
            hand(1e-3, 1e8),
            hand(1e-4, 0.1),
            hand(0.1, 1e4),
            hand(10.0, 10.0 * w * w),
        ] {
            let r = host_radius(&m, 1e-3, (k, b), &h, &at).unwrap();
            assert!(
                !r.unstable,
                "m {mass} d {damping} k {k} b {b} N {n} d {d} body {body} B {need}: {h:?} gives {r:?}"
            );
        }
        checked += 1;
    }
    assert!(checked >= 10, "{checked} devices checked");
}

/// The proof's damping is close to what the exact loop needs: on a rigid
/// device with two ticks of delay, a light and a heavy body at 90 % of
/// the damping the proof asks for meet a hand that makes the loop grow.
/// (The half-plane test this proof sharpened asked 77.7 N s/m of both,
/// where 45 to 50 suffice, and near DC it asked `(k τ)²/(4 b)` of any
/// body.)
#[test]
#[cfg_attr(debug_assertions, ignore = "release only (CI runs it)")]
fn the_host_bodys_damping_is_within_ten_percent_of_the_exact_loops() {
    use twoport_design::analysis::{max_stiffness, Analysis, GridSpec};
    let m = rigid(1.0, 20.0, 0);
    let p = Plant::new(&m, 1e-3).unwrap();
    let a = Analysis::new(&p, GridSpec::DEFAULT);
    let b = 5.0;
    let k = 0.9 * max_stiffness(&a, &a.impedance_bound(None), b).unwrap();
    for body in [0.2, 1.0] {
        let host = |damping: f64| HostLoop::new(1e-3, 1, 2, (body, damping, 0.0)).unwrap();
        let need = check_host_ve(&p, k, b, None, &host(0.0))
            .unwrap()
            .least_damping_nspm;
        assert!(need > 0.0 && need < 60.0, "body {body}: {need}");
        let at = verify_host(&m, 1e-3, (k, b), None, &host(1.01 * need)).unwrap();
        assert!(!at.unstable, "body {body} at {need}: {at:?}");
        let below = verify_host(&m, 1e-3, (k, b), None, &host(0.9 * need)).unwrap();
        assert!(below.unstable, "body {body}, 90 % of {need}: {below:?}");
    }
}
