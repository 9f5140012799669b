//! Designer speed: the Excalibur 2x2 frequency response on 10,000 points
//! (goal <= 2 ms), the discrete terms, a full design of both displays
//! (goal <= 20 ms), a design over 8 poses against one (goal: at most 8
//! times), `verify` on the Excalibur (goal <= 2 s), and the workspace
//! certificate of the PHANToM and the Falcon-like delta (goal <= 1 s).

use criterion::{criterion_group, criterion_main, Criterion};
use num_complex::Complex64;
use std::f64::consts::PI;
use std::hint::black_box;
use twoport_design::analysis::*;
use twoport_design::network::HumanBound;
use twoport_design::plant::Scratch;
use twoport_design::{DeviceModel, Plant};

fn excalibur() -> Plant {
    Analysis::excalibur().plant().clone()
}

fn responses(c: &mut Criterion) {
    let plant = excalibur();
    let w = log_grid(2.0 * PI * 0.1, plant.nyquist(), 10_000);
    let mut scratch = plant.scratch();
    type Method = fn(&Plant, f64, &mut Scratch) -> ([[Complex64; 2]; 2], [Complex64; 2]);
    let methods: [(&str, Method); 2] = [
        (
            "Y(s) and F(s), modal form, 10,000 points",
            Plant::continuous,
        ),
        (
            "Y(s) and F(s), complex LU per point, 10,000 points",
            Plant::continuous_lu,
        ),
    ];
    for (name, method) in methods {
        c.bench_function(name, |b| {
            b.iter(|| {
                let mut acc = 0.0;
                for &omega in &w {
                    let (y, f) = method(&plant, omega, &mut scratch);
                    acc += y[0][0].re + f[1].re;
                }
                black_box(acc)
            })
        });
    }
    c.bench_function(
        "all plant terms incl. ZOH-exact X_aa^d, F_ma^d, 10,000 points",
        |b| b.iter(|| black_box(plant.response(&w))),
    );
}

fn designs(c: &mut Criterion) {
    let model =
        DeviceModel::from_toml(include_str!("../models/excalibur.toml"), "excalibur").unwrap();
    let human = Some(HumanBound::PAPER);
    c.bench_function(
        "full design of both displays (model to k_c at b 90, m_c at b 500)",
        |b| {
            b.iter(|| {
                let plant = Plant::new(&model, 1e-3).unwrap();
                let a = Analysis::new(&plant, GridSpec::DEFAULT);
                let k = max_stiffness(&a, &a.impedance_bound(human), 90.0).unwrap();
                let kp = regulator_tf(k, 90.0, 1e-3).unwrap();
                let m = min_mass(&a, &a.admittance_bound(&kp, human), 500.0).unwrap();
                black_box((k, m))
            })
        },
    );
    let a = Analysis::excalibur();
    let bi = a.impedance_bound(human);
    c.bench_function("best (k, b) pair, impedance display", |b| {
        b.iter(|| black_box(best_impedance(&a, &bi)))
    });
}

/// One pose against eight (the Excalibur's bound at slightly scaled
/// masses, so no two poses are the same), measured in one run.
fn poses(c: &mut Criterion) {
    let human = Some(HumanBound::PAPER);
    let base = excalibur_model();
    let analyses: Vec<Analysis> = (0..8)
        .map(|i| {
            let mut m = base.clone();
            m.m *= 1.0 + 0.02 * i as f64;
            Analysis::new(&Plant::new(&m, 1e-3).unwrap(), GridSpec::DEFAULT)
        })
        .collect();
    let design = |n: usize| {
        let bounds: Vec<Vec<f64>> = analyses[..n]
            .iter()
            .map(|a| a.impedance_bound(human))
            .collect();
        let poses: Vec<(&Analysis, &[f64])> = analyses[..n]
            .iter()
            .zip(&bounds)
            .map(|(a, b)| (a, b.as_slice()))
            .collect();
        max_stiffness_poses(&poses, 90.0)
    };
    c.bench_function("impedance design at b 90 (bound and search), 1 pose", |b| {
        b.iter(|| black_box(design(1)))
    });
    c.bench_function(
        "impedance design at b 90 (bound and search), 8 poses",
        |b| b.iter(|| black_box(design(8))),
    );
}

fn verify(c: &mut Criterion) {
    use twoport_control::{Gains, ImpedanceGains};
    use twoport_design::verify::verify;
    let m = excalibur_model();
    let g = Gains::from(ImpedanceGains::new(51_074.0, 90.0));
    let mut group = c.benchmark_group("verify");
    group.sample_size(10);
    group.bench_function("verify, Excalibur impedance display at the design", |b| {
        b.iter(|| black_box(verify(&m, 1e-3, &g, Some(HumanBound::PAPER)).unwrap()))
    });
    group.finish();
}

/// The workspace certificate of each shipped linkage: a branch and bound
/// over every pose inside the limits, to a gap of 1e-4 (goal: 1 s for a
/// 3-DOF arm).
fn linkage(c: &mut Criterion) {
    use twoport_design::linkage::{certified_design, LinkageFile};
    for (name, text) in [
        (
            "PHANToM 1.5",
            include_str!("../models/linkages/phantom_premium_1_5.toml"),
        ),
        (
            "Falcon-like delta",
            include_str!("../models/linkages/falcon_like.toml"),
        ),
        (
            "Haply-2DIY-like pantograph",
            include_str!("../models/linkages/haply_2diy.toml"),
        ),
        ("Hapkit", include_str!("../models/linkages/hapkit.toml")),
    ] {
        let file = LinkageFile::from_toml(text, name).unwrap();
        c.bench_function(&format!("{name}: workspace certificate"), |b| {
            b.iter(|| black_box(certified_design(&file, 0.0, 0.0, None).unwrap().k_c_npm))
        });
    }
}

fn excalibur_model() -> DeviceModel {
    DeviceModel::from_toml(include_str!("../models/excalibur.toml"), "excalibur").unwrap()
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20);
    targets = responses, designs, poses, verify, linkage
}
criterion_main!(benches);
