//! The plant step alone, for each integrator and sub-step count: one 1 ms
//! tick of the 5-DOF Excalibur (10 states, maximum grasp) with held inputs.

use criterion::{criterion_group, criterion_main, Criterion};
use host_sim::engine::human::GraspKind;
use host_sim::engine::plant::{Method, SimDevice, Stepper};
use std::hint::black_box;
use twoport_design::DeviceModel;

fn plant(c: &mut Criterion) {
    let model =
        DeviceModel::from_toml(include_str!("../models/excalibur.toml"), "excalibur").unwrap();
    let dev = SimDevice::flexible(&model).unwrap();
    let sys = dev.system(GraspKind::Maximum.grasp(), false);
    for (method, subs) in [
        (Method::ExactZoh, &[1u32, 8][..]),
        (Method::Rk4, &[8, 16, 64][..]),
        (Method::SemiImplicitEuler, &[16, 64][..]),
        (Method::Euler, &[64][..]),
    ] {
        for &n in subs {
            let mut st = Stepper::new(&sys, method, 1e-3 / n as f64).unwrap();
            let mut x = vec![0.0; sys.states()];
            c.bench_function(&format!("plant tick: {} x {n}", method.name()), |b| {
                b.iter(|| {
                    for _ in 0..n {
                        st.step(&mut x, black_box([1.0, 0.5]), None);
                    }
                    // Keep the state bounded for the explicit methods.
                    x.iter_mut().for_each(|v| *v = v.clamp(-1.0, 1.0));
                    black_box(&x);
                })
            });
        }
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20);
    targets = plant
}
criterion_main!(benches);
