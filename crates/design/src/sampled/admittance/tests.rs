use super::*;
use crate::model::DeviceModel;
use std::f64::consts::PI;

fn shipped(file: &str) -> DeviceModel {
    let path = format!("{}/../../models/{file}", env!("CARGO_MANIFEST_DIR"));
    DeviceModel::load(std::path::Path::new(&path)).unwrap()
}

/// With no alias terms both bounds are the paper's exact base-band
/// minimum (the Möbius image of the hand's disk is Llewellyn's).
#[test]
fn without_aliases_both_bounds_are_the_papers() {
    let model = DeviceModel::excalibur().unwrap();
    let plant = Plant::new(&model, 1e-3).unwrap();
    let kp = crate::analysis::regulator_tf(51_000.0, 90.0, 1e-3).unwrap();
    let pts = plant.response(&crate::analysis::log_grid(1.0, plant.nyquist(), 40));
    for h in [Some(HumanBound::PAPER), None] {
        for p in &pts {
            let paper = design_bound(&admittance_display(p, &kp, h));
            let base = Base::at(p, h).unwrap();
            let k = kp.eval(p.z) * p.delay;
            let tol = 1e-9 * paper.abs().max(1.0);
            let (_, pert) = perturbation_bound(p, &Reach::default(), &kp, h, base);
            assert!((pert - paper).abs() <= tol);
            let m = mobius_bound(p, &Disks::default(), k, base);
            assert!(
                (m - paper).abs() <= tol,
                "{} Hz: {m} vs {paper}",
                p.omega / (2.0 * PI)
            );
            let bound = admittance_bound(&plant, std::slice::from_ref(p), &kp, h)[0];
            assert!(bound >= paper);
        }
    }
}

/// `G = K I F_h/(1 + K X_h)` for a base-band hand `w0` and the aliases
/// `k = ±1..±n` at `ws[k]`, written out from the alias sums.
fn g_with_aliases(
    plant: &Plant,
    p: &PlantPoint,
    k: Complex64,
    w0: Complex64,
    ws: &[(f64, Complex64)],
) -> Complex64 {
    let one = Complex64::new(1.0, 0.0);
    let q = (one - p.z.inv()) / p.period_s;
    let mut work = plant.scratch();
    let base = Base::at(p, None).unwrap();
    let (mut x, mut f) = (p.xaa_d - q * base.a0 * w0, p.fma_d - q * base.f0 * w0);
    for &(om, w) in ws {
        let mut h = plant.hand_terms(om.abs(), &mut work);
        if om < 0.0 {
            h = h.map(|v| v.conj());
        }
        let s = Complex64::new(0.0, om);
        x -= q * h[2] * h[1] / (s * s) * w;
        f -= q * h[3] * h[1] / s * w;
    }
    k * f / (q * (one + k * x))
}

/// Every hand of the relaxation the bound covers (each alias free in its
/// disk) leaves `Re G` above `-bound`: sampled hands, the base band's on
/// the edge of its disk where it brings the regulated device nearest its
/// pole, on devices with and without a load cell's flexure and toward DC.
#[test]
fn the_bound_holds_for_sampled_hands_of_the_relaxation() {
    let cases = [
        (shipped("two_mass.toml"), (39_739.0, 42.9)),
        (DeviceModel::excalibur().unwrap(), (51_000.0, 90.0)),
    ];
    let mut rnd = crate::test_rng::uniform(0x9e37_79b9_7f4a_7c15u64);
    for (model, (kp_, bp)) in &cases {
        let plant = Plant::new(model, 1e-3).unwrap();
        let kp = crate::analysis::regulator_tf(*kp_, *bp, 1e-3).unwrap();
        let ws = 2.0 * PI / plant.period_s();
        for f in [0.05, 0.5, 5.0, 50.0, 240.0, 480.0] {
            let p = plant.response(&[2.0 * PI * f])[0];
            let bound = admittance_bound(&plant, &[p], &kp, None)[0];
            assert!(bound.is_finite(), "{}: {f} Hz", model.name);
            let base = Base::at(&p, None).unwrap();
            let k = kp.eval(p.z) * p.delay;
            let mut work = plant.scratch();
            let disk = |om: f64, work: &mut crate::plant::Scratch| {
                let y = plant.hand_terms(om.abs(), work)[0];
                0.5 / y.re
            };
            // The base-band hand nearest the regulated device's pole.
            let one = Complex64::new(1.0, 0.0);
            let q = (one - p.z.inv()) / p.period_s;
            let pole = (one + k * p.xaa_d) / (k * q * base.a0);
            let toward = (pole - base.r0).arg();
            for i in 0..3000 {
                let w0 = if i % 2 == 0 {
                    let ang = 2.0 * PI * rnd();
                    base.r0 * (1.0 + Complex64::from_polar(rnd().sqrt(), ang))
                } else {
                    let ang = toward + (2.0 * rnd() - 1.0) * 10f64.powf(-6.0 * rnd());
                    base.r0 * (1.0 + Complex64::from_polar(1.0 - 1e-3 * rnd(), ang))
                };
                let aliases: Vec<(f64, Complex64)> = (1..=3)
                    .flat_map(|n| [p.omega + ws * n as f64, p.omega - ws * n as f64])
                    .map(|om| {
                        let r = disk(om, &mut work);
                        (om, r * (1.0 + Complex64::from_polar(1.0, 2.0 * PI * rnd())))
                    })
                    .collect();
                let g = g_with_aliases(&plant, &p, k, w0, &aliases);
                assert!(
                    g.re >= -bound - 1e-9 * bound.abs().max(1.0),
                    "{}: {f} Hz: Re G {} below -{bound}",
                    model.name,
                    g.re
                );
            }
        }
    }
}

/// Toward DC without a human bound the perturbation bound grows as `1/ω²`
/// on the two-mass device and the Möbius bound stays near the paper's.
#[test]
fn the_mobius_bound_stays_finite_toward_dc() {
    let plant = Plant::new(&shipped("two_mass.toml"), 1e-3).unwrap();
    let kp = crate::analysis::regulator_tf(39_739.0, 42.9, 1e-3).unwrap();
    for f in [0.05, 0.5, 5.0] {
        let p = plant.response(&[2.0 * PI * f])[0];
        let base = Base::at(&p, None).unwrap();
        let cache = AliasCache::new(1);
        let reach = alias_reach(&plant, (0, &p), None, &cache).unwrap();
        let disks = alias_disks(&plant, (0, &p), None, &cache, (base, &reach));
        let k = kp.eval(p.z) * p.delay;
        let (paper, old) = perturbation_bound(&p, &reach, &kp, None, base);
        let new = mobius_bound(&p, &disks, k, base);
        assert!(
            new >= paper && new < paper + 0.1 * paper.abs(),
            "{f} Hz: {new} vs {paper}"
        );
        assert!(f > 1.0 || old > 10.0 * paper.abs(), "{f} Hz: {old}");
    }
}
