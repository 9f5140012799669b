//! The published numbers of Adams & Hannaford (2002), the last table of
//! docs/two-port.md, each within its stated tolerance.

use std::f64::consts::PI;
use std::sync::OnceLock;
use twoport_design::analysis::*;
use twoport_design::network::HumanBound;
use twoport_design::Plant;

const HUMAN: Option<HumanBound> = Some(HumanBound::PAPER);
const PAPER_K: f64 = 51_000.0;
const PAPER_B: f64 = 90.0;
const PAPER_M: f64 = 5.0;
const PAPER_BA: f64 = 500.0;

struct Excalibur {
    plant: Plant,
    a: Analysis,
}

fn excalibur() -> &'static Excalibur {
    static E: OnceLock<Excalibur> = OnceLock::new();
    E.get_or_init(|| {
        let a = Analysis::excalibur();
        Excalibur {
            plant: a.plant().clone(),
            a,
        }
    })
}

fn paper_kp() -> twoport_control::ZTransfer {
    regulator_tf(PAPER_K, PAPER_B, 1e-3).unwrap()
}

fn within(what: &str, got: f64, want: f64, tol: f64) {
    let rel = (got - want).abs() / want;
    assert!(
        rel <= tol,
        "{what}: {got} vs paper {want} ({:.2}% > {:.1}%)",
        rel * 100.0,
        tol * 100.0
    );
}

#[test]
fn impedance_coupling_stiffness_at_b_90() {
    let e = excalibur();
    let k = max_stiffness(&e.a, &e.a.impedance_bound(HUMAN), PAPER_B).unwrap();
    within("greatest k_cI at b_cI = 90", k, PAPER_K, 0.03);
}

#[test]
fn admittance_coupling_mass_at_b_500() {
    let e = excalibur();
    let m = min_mass(&e.a, &e.a.admittance_bound(&paper_kp(), HUMAN), PAPER_BA).unwrap();
    within("least m_cA at b_cA = 500", m, PAPER_M, 0.03);
}

/// "Dramatically" larger without the human model: ten times the mass or
/// infeasible, at the paper's damping and at the best damping.
#[test]
fn admittance_design_without_human_model_is_dramatically_larger() {
    let e = excalibur();
    let bound = e.a.admittance_bound(&paper_kp(), None);
    if let Some(m) = min_mass(&e.a, &bound, PAPER_BA) {
        assert!(
            m >= 10.0 * PAPER_M,
            "m = {m} kg at b = 500 without the human model"
        );
    }
    if let Some((m, b)) = best_admittance(&e.a, &bound) {
        assert!(
            m >= 10.0 * PAPER_M,
            "best pair without human: {m} kg at {b} N s/m"
        );
    }
}

/// A coupling 2% inside the published values passes the check; 10% past
/// them (stiffer, lighter) fails.
#[test]
fn check_separates_two_percent_inside_from_ten_percent_outside() {
    let e = excalibur();
    let imp = |k: f64| check_impedance(&e.a, k, PAPER_B, HUMAN).unwrap();
    let adm = |m: f64| {
        check_admittance(&e.plant, &e.a, (PAPER_K, PAPER_B), (m, PAPER_BA), HUMAN).unwrap()
    };
    let soft = imp(0.98 * PAPER_K);
    assert!(soft.absolutely_stable && soft.min_margin >= 0.0, "{soft:?}");
    let stiff = imp(1.10 * PAPER_K);
    assert!(
        !stiff.absolutely_stable && stiff.min_margin < 0.0,
        "{stiff:?}"
    );
    let heavy = adm(1.02 * PAPER_M);
    assert!(heavy.absolutely_stable, "{heavy:?}");
    let light = adm(PAPER_M / 1.10);
    assert!(!light.absolutely_stable, "{light:?}");
    assert!(heavy.regulator_pole_radius < 1.0);
}

/// The margin reported is Llewellyn's verdict: where the relative slack is
/// clearly negative, `η - 1` is negative at the same frequency, and the
/// other way round.
#[test]
fn relative_margin_has_the_sign_of_llewellyn_eta() {
    let e = excalibur();
    for k in [0.9 * PAPER_K, 1.2 * PAPER_K] {
        let eta = llewellyn_impedance(&e.a, k, PAPER_B, HUMAN).unwrap();
        let tf = impedance_coupling_tf(k, PAPER_B, 1e-3).unwrap();
        let bound = e.a.impedance_bound(HUMAN);
        for ((p, eta), b) in e.a.points.iter().zip(&eta).zip(&bound) {
            let rel = relative_margin(tf.eval(p.z).inv().re, *b);
            if rel.abs() > 1e-6 && eta.abs() > 1e-6 {
                assert_eq!(
                    rel > 0.0,
                    *eta > 0.0,
                    "k {k} at {} Hz: rel {rel}, eta-1 {eta}",
                    p.omega / (2.0 * PI)
                );
            }
        }
    }
}

/// The same on the admittance display: at the paper's regulator, a mass
/// clearly inside and one clearly past the boundary.
#[test]
fn admittance_margin_has_the_sign_of_llewellyn_eta() {
    let e = excalibur();
    let bound = e.a.admittance_bound(&paper_kp(), HUMAN);
    for m in [1.1 * PAPER_M, PAPER_M / 1.2] {
        let eta = llewellyn_admittance(&e.a, (PAPER_K, PAPER_B), (m, PAPER_BA), HUMAN).unwrap();
        let zc = admittance_coupling_tf(m, PAPER_BA, 1e-3).unwrap();
        let (mut compared, mut past) = (0, 0);
        for ((p, eta), b) in e.a.points.iter().zip(&eta).zip(&bound) {
            let rel = relative_margin(zc.eval(p.z).re, *b);
            if rel.abs() > 1e-6 && eta.abs() > 1e-6 {
                compared += 1;
                past += usize::from(rel < 0.0);
                assert_eq!(
                    rel > 0.0,
                    *eta > 0.0,
                    "m {m} at {} Hz: rel {rel}, eta-1 {eta}",
                    p.omega / (2.0 * PI)
                );
            }
        }
        assert!(compared > 100, "m {m}: {compared} points compared");
        // The light mass fails somewhere: both signs are compared.
        assert_eq!(past > 0, m < PAPER_M, "m {m}: {past} points past");
    }
}

fn at_hz(e: &Excalibur, f: f64) -> Analysis {
    Analysis::on(&e.plant, &[2.0 * PI * f])
}

/// Below 10 Hz both displays act as a grounded spring of about 20,000 N/m:
/// `ω |Z_max(jω)|` at 1 Hz within 18,500..20,500 N/m.
#[test]
fn upper_impedance_bound_is_a_20_kn_per_m_spring_for_both_displays() {
    let e = excalibur();
    let a = at_hz(e, 1.0);
    let w = 2.0 * PI;
    let imp = impedance_range_impedance(&a, PAPER_K, PAPER_B).unwrap()[0].1;
    let adm = impedance_range_admittance(&a, (PAPER_K, PAPER_B), (PAPER_M, PAPER_BA)).unwrap()[0].1;
    for (what, z) in [("impedance", imp), ("admittance", adm)] {
        let k = w * z.norm();
        assert!(
            (18_500.0..=20_500.0).contains(&k),
            "{what} display: w|Z_max| = {k} N/m"
        );
    }
}

/// The impedance display's free-motion impedance below 10 Hz is the bare
/// device: 20 N s/m of damping and 3.9 kg, each within 5%.
#[test]
fn impedance_display_lower_bound_is_the_device() {
    let e = excalibur();
    let a = at_hz(e, 1.0);
    let z = impedance_range_impedance(&a, PAPER_K, PAPER_B).unwrap()[0].0;
    within("damping Re Z_min", z.re, 20.0, 0.05);
    within("inertia Im Z_min / w", z.im / (2.0 * PI), 3.9, 0.05);
}

/// The admittance display's free-motion impedance is dominated by the
/// 5.0 kg coupling mass: the rest is the handle mass ahead of the load
/// cell (0.16 kg of q5) and the regulator's finite stiffness, so the
/// inertia lies between the coupling mass and 10% above it. The paper's
/// "zero damping" is against the impedance display's 20 N s/m: less than a
/// quarter of it.
#[test]
fn admittance_display_lower_bound_is_the_coupling_mass() {
    let e = excalibur();
    let a = at_hz(e, 1.0);
    let z = impedance_range_admittance(&a, (PAPER_K, PAPER_B), (PAPER_M, PAPER_BA)).unwrap()[0].0;
    let inertia = z.im / (2.0 * PI);
    assert!(
        (PAPER_M..=1.10 * PAPER_M).contains(&inertia),
        "free motion {inertia} kg"
    );
    let device = impedance_range_impedance(&a, PAPER_K, PAPER_B).unwrap()[0].0;
    assert!(
        z.re.abs() < 0.25 * device.re,
        "damping {} vs the device's {}",
        z.re,
        device.re
    );
}

/// Fig. 10(b): with K_p stiffness 10,000 N/m the paper reaches a 1.5 kg
/// coupling at 450 N s/m, free motion near 1.7 kg and a rigid bound near
/// 8,000 N/m. It gives no b_p. At b_p = 90 the softer regulator already
/// allows a lighter coupling than the 51,000 N/m one (the trend); the
/// paper's 1.5 kg is reached near b_p = 500 N s/m, where the other two
/// numbers also match within 15%.
#[test]
fn softer_regulator_trades_stiffness_for_lighter_free_motion() {
    let e = excalibur();
    let m_at = |kp: f64, bp: f64| {
        let bound =
            e.a.admittance_bound(&regulator_tf(kp, bp, 1e-3).unwrap(), HUMAN);
        min_mass(&e.a, &bound, 450.0).unwrap()
    };
    assert!(m_at(10_000.0, PAPER_B) < 0.8 * m_at(PAPER_K, PAPER_B));
    let kp = (10_000.0, 500.0);
    let m = m_at(kp.0, kp.1);
    within(
        "least m_cA at K_p 10,000 + 500 (1 - 1/z)/T, b_cA 450",
        m,
        1.5,
        0.10,
    );
    let a = at_hz(e, 1.0);
    let (zmin, zmax) = impedance_range_admittance(&a, kp, (1.5, 450.0)).unwrap()[0];
    within(
        "rigid bound w |Z_max|",
        2.0 * PI * zmax.norm(),
        8_000.0,
        0.15,
    );
    within("free-motion inertia", zmin.im / (2.0 * PI), 1.7, 0.15);
}

/// Doubling the frequency grid moves no design result by more than 0.5%.
#[test]
fn design_results_are_converged_in_the_frequency_grid() {
    let e = excalibur();
    let fine = Analysis::new(&e.plant, GridSpec::DEFAULT.doubled());
    let results = |a: &Analysis| {
        let bi = a.impedance_bound(HUMAN);
        let ba = a.admittance_bound(&paper_kp(), HUMAN);
        [
            max_stiffness(a, &bi, PAPER_B).unwrap(),
            max_stiffness(a, &bi, 30.0).unwrap(),
            min_mass(a, &ba, PAPER_BA).unwrap(),
            min_mass(a, &ba, 1000.0).unwrap(),
        ]
    };
    for (c, f) in results(&e.a).iter().zip(results(&fine)) {
        assert!((c - f).abs() <= 0.005 * f, "default grid {c}, doubled {f}");
    }
}
