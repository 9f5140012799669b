//! Hard numerical cases (issue 7 §3): long runs, extreme gains, extreme
//! humans, ill-conditioned models. Each answer is either right or a clear
//! refusal; never a NaN, never a panic.

use std::f64::consts::PI;
use twoport_control::servo::SensorFrame;
use twoport_control::ve::{Solid, UnilateralWall};
use twoport_control::{AdmittanceGains, Encoder, Position, SafetyConfig, Servo};
use twoport_design::analysis::*;
use twoport_design::network::HumanBound;
use twoport_design::{DeviceModel, Plant};

const T: f32 = 1e-3;
const EXCALIBUR: &str = include_str!("../models/excalibur.toml");

/// 24 h at 1 kHz (8.64e7 ticks) of the f32 admittance display pushing a
/// wall with 10 N plus a zero-mean 1 Hz wave: the orbit is periodic, so the
/// position command at the same phase after 1 h and after 24 h must agree
/// to one encoder count (1 um). Any creep of the integrated position (a
/// biased remainder, a rounding fixed point away from zero) shows as drift.
#[test]
#[ignore = "8.64e7 ticks: run with --release --ignored (CI does)"]
fn admittance_display_does_not_creep_in_24_hours() {
    let count_nm = 1000;
    let enc = Encoder::new(16, count_nm as i64 * 1000, 0, Position::ZERO).unwrap();
    let wall =
        UnilateralWall::new(2e4, 50.0, Position::ZERO, Solid::Above, T, Position::ZERO).unwrap();
    let mut s = Servo::new(
        [AdmittanceGains::new(51_000.0, 90.0, 5.0, 500.0).into()],
        [enc],
        [SafetyConfig::excalibur()],
        wall,
    )
    .unwrap();
    s.enable().unwrap();
    let period = 1000u32;
    let wave: Vec<f32> = (0..period)
        .map(|k| (10.0 + 3.0 * (2.0 * PI * k as f64 / period as f64).cos()) as f32)
        .collect();
    let hour = 3_600_000u32;
    let (mut at_1h, mut last) = (None, Position::ZERO);
    for k in 0..24 * hour {
        let out = s.tick(&SensorFrame::held(k, [0], [wave[(k % period) as usize]]));
        assert!(out.faults.is_empty(), "tick {k}: {}", out.faults);
        if k % period == 0 {
            last = out.reference[0];
            if k == hour {
                at_1h = Some(out.reference[0]);
            }
        }
    }
    let drift = (last - at_1h.unwrap()).abs();
    eprintln!("position command drift from hour 1 to hour 24: {drift} nm");
    assert!(drift <= count_nm, "drifted {drift} nm > one count");
    // And it sits where the wall puts it: 10 N mean into 2e4 N/m is 0.5 mm
    // (the wave's phase adds its own offset, well under 0.3 mm).
    assert!((last.m() - 0.5e-3).abs() < 0.3e-3, "{} m", last.m());
}

fn excalibur() -> (Plant, Analysis) {
    let a = Analysis::excalibur();
    (a.plant().clone(), a)
}

/// Gains far outside any sensible range are reported not stable, with
/// finite margins; a coupling that cannot exist is refused.
#[test]
fn extreme_gains_are_reported_unstable_never_nan() {
    let (p, a) = excalibur();
    let h = Some(HumanBound::PAPER);
    for (k, b) in [(1e12, 0.0), (1e9, 1e-6), (5e8, 1e5), (1e7, 0.0)] {
        let c = check_impedance(&a, k, b, h).expect("a valid coupling");
        assert!(!c.absolutely_stable, "k {k}, b {b}");
        assert!(
            c.min_margin.is_finite() && c.worst_frequency_hz.is_finite(),
            "{c:?}"
        );
    }
    assert!(
        check_impedance(&a, 0.0, 0.0, h).is_none(),
        "kT + b = 0 is no coupling"
    );
    for m in [1e-9, 1e-4] {
        let c = check_admittance(&p, &a, (51_000.0, 90.0), (m, 500.0), h).unwrap();
        assert!(
            !c.absolutely_stable && c.min_margin.is_finite(),
            "m {m}: {c:?}"
        );
    }
    // A regulator far too stiff for the device destabilises it: said so.
    let c = check_admittance(&p, &a, (1e9, 1e5), (5.0, 500.0), h).unwrap();
    assert!(!c.absolutely_stable && c.regulator_pole_radius.is_finite());
    // And the simulator: a coupling of 1e9 N/m is unstable, with finite
    // numbers and the force never past the actuator's peak.
    let root = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/.."));
    let mut s = host_sim::Scene::load(
        &root.join("scenes/table1/impedance_bilateral_maximum.toml"),
        &["coupling.k=1e9".into()],
    )
    .unwrap();
    s.plant.model = root.join("models/excalibur.toml");
    let r = host_sim::Simulation::new(s)
        .unwrap()
        .run(|x| assert!(x.actuator_n[0].is_finite() && x.handle_m[0].is_finite()));
    assert!(
        !r.stable && r.peak_force_n <= 200.0 && r.energy_in_j.is_finite(),
        "{r:?}"
    );
}

/// The human bound from nearly nothing to nearly rigid: every design is a
/// finite number or an explicit infeasible, and a stiffer human never
/// allows a stiffer coupling than a softer one.
#[test]
fn zero_and_near_infinite_human_impedance() {
    let (_, a) = excalibur();
    let mut last = f64::INFINITY;
    for (b, k) in [
        (1e-9, 1e-9),
        (3.0, 10.0),
        (300.0, 1000.0),
        (3e4, 1e5),
        (3e9, 1e10),
    ] {
        let bound = a.impedance_bound(Some(HumanBound {
            damping_nspm: b,
            stiffness_npm: k,
        }));
        assert!(bound.iter().all(|x| !x.is_nan()), "human {b} + {k}/s");
        let kmax = max_stiffness(&a, &bound, 90.0).expect("some coupling is stable");
        assert!(
            kmax.is_finite() && kmax <= last * 1.001,
            "human {b} + {k}/s: {kmax} after {last}"
        );
        last = kmax;
    }
    // Near-rigid human = no human bound at all (any passive human).
    let none = max_stiffness(&a, &a.impedance_bound(None), 90.0).unwrap();
    assert!((last - none).abs() <= 0.01 * none, "{last} vs {none}");
}

fn scaled(from: &str, to: &str) -> Result<(Plant, Analysis), String> {
    assert!(EXCALIBUR.contains(from), "{from}");
    let m = DeviceModel::from_toml(&EXCALIBUR.replacen(from, to, 1), "ill")
        .map_err(|e| e.to_string())?;
    let p = Plant::new(&m, 1e-3).map_err(|e| e.to_string())?;
    let a = Analysis::new(&p, GridSpec::DEFAULT);
    Ok((p, a))
}

/// Ill-conditioned models: a 1e9 N/m structural stiffness, a nearly
/// massless coordinate, a nearly singular mass matrix. Each gives a clear
/// error or finite answers, never a silent NaN.
#[test]
fn ill_conditioned_models_answer_or_refuse_clearly() {
    let cases = [
        ("stiffness 1e9", "5.3954e7", "5.3954e9"),
        ("near-massless handle", "0.1600]", "1.0e-9]"),
        (
            "nearly singular M",
            "[0.0,    0.0,    2.4489, 0.2799",
            "[0.0,    0.0,    0.2799, 0.2799",
        ),
        (
            "singular M",
            "[0.0,    0.0,    2.4489, 0.2799, 0.0]",
            "[0.0,    0.0,    0.3343, 0.2799, 0.0]",
        ),
        // M^-1 K overflows to infinity: the matrix exponential's scaling
        // and squaring once looped forever here (found by the fuzzer).
        ("stiffness 1e300", "5.3954e7", "5.3954e300"),
        ("handle mass 1e-300", "0.1600]", "1.0e-300]"),
        (
            "stiffness 1e15 (norm far past the step)",
            "5.3954e7",
            "5.3954e15",
        ),
    ];
    for (what, from, to) in cases {
        match scaled(from, to) {
            Ok((_, a)) => {
                assert!(
                    a.points.iter().all(|p| p
                        .y
                        .iter()
                        .flatten()
                        .all(|v| !v.re.is_nan() && !v.im.is_nan())),
                    "{what}: NaN in Y"
                );
                let bound = a.impedance_bound(Some(HumanBound::PAPER));
                assert!(
                    bound.iter().all(|x| !x.is_nan()),
                    "{what}: NaN in the bound"
                );
                if let Some(k) = max_stiffness(&a, &bound, 90.0) {
                    assert!(k.is_finite() && k > 0.0, "{what}: {k}");
                }
            }
            Err(e) => assert!(
                e.contains("M ")
                    || e.contains("positive definite")
                    || e.contains("not finite")
                    || e.contains("far faster than the sample period"),
                "{what}: unclear error {e}"
            ),
        }
    }
}

/// A model whose `M^-1 K` overflows to infinity (a 1e-300 kg coordinate
/// on a 5e7 N/m spring scaled to 5e300): refused with a clear error at once.
/// The matrix exponential's scaling and squaring once spun forever on such
/// an argument (the model-file fuzzer found it).
#[test]
fn a_model_whose_dynamics_overflow_is_refused() {
    let text = EXCALIBUR
        .replacen("0.1600]", "1.0e-300]", 1)
        .replacen("5.3236e7", "5.3236e300", 1);
    let m = DeviceModel::from_toml(&text, "overflow").unwrap();
    let Err(e) = Plant::new(&m, 1e-3) else {
        panic!("a model whose dynamics overflow must be refused");
    };
    let e = e.to_string();
    assert!(
        e.contains("not finite") || e.contains("far faster than the sample period"),
        "{e}"
    );
}

/// At Nyquist and at every resonance (aliased ones included) the sampled
/// terms are finite and the Hessenberg evaluation agrees with a dense LU of
/// (zI - A_d) to 1e-9 of each term's largest value over frequency. (Relative
/// to its own tiny value at Nyquist, F_ma^d differs by 5e-6:
/// the Hessenberg basis spreads the single output row over every state and
/// the small result comes out of a cancellation, 4e-11 in absolute terms.)
#[test]
fn sampled_terms_at_nyquist_and_resonances_agree_with_a_second_method() {
    let (p, _) = excalibur();
    let mut w = p.scratch();
    let sweep = p.response(
        &(0..400)
            .map(|i| 0.5 * (p.nyquist() / 0.5f64).powf(i as f64 / 399.0))
            .collect::<Vec<_>>(),
    );
    let sx = sweep.iter().map(|q| q.xaa_d.norm()).fold(0.0, f64::max);
    let sf = sweep.iter().map(|q| q.fma_d.norm()).fold(0.0, f64::max);
    let mut omegas: Vec<f64> = vec![p.nyquist(), p.nyquist() * (1.0 - 1e-9)];
    omegas.extend(
        p.modes()
            .iter()
            .map(|m| m.omega_n)
            .filter(|w| *w < p.nyquist()),
    );
    omegas.extend(p.discrete_angles().iter().map(|t| t / p.period_s()));
    for omega in omegas {
        let pt = p.at(omega, &mut w);
        for v in [pt.xaa_d, pt.fma_d, pt.y[0][0], pt.f[1]] {
            assert!(v.re.is_finite() && v.im.is_finite(), "{omega} rad/s");
        }
        let (x2, f2) = p.sampled_by_lu(omega);
        assert!(
            (pt.xaa_d - x2).norm() <= 1e-9 * sx,
            "X_aa^d at {omega}: {} vs {x2}",
            pt.xaa_d
        );
        assert!(
            (pt.fma_d - f2).norm() <= 1e-9 * sf,
            "F_ma^d at {omega}: {} vs {f2}",
            pt.fma_d
        );
    }
}
