//! Identification from a 30 s experiment: the board's multisine on the
//! flexible Excalibur (simulated once, outside the timing), then what
//! `identify` does with the record: the frequency responses over its
//! periods, and the fit of every order with the choice among them. The
//! goal is the fit of a 5-DOF model in at most 1 s. Then the refit of the
//! chosen order with a loaded record (0.5 kg on the handle) beside it,
//! and the fit of a 1-DOF device (the capstan handle's 30 s record), whose
//! goal is 0.1 s.

use criterion::{criterion_group, criterion_main, Criterion};
use host_sim::link::{LinkFaults, LocalBoard};
use host_sim::{pil, Scene};
use std::hint::black_box;
use std::path::Path;
use twoport_identify::fit::{self, chain::ModelBase, Measured};

fn identify(c: &mut Criterion) {
    let scene_path = |device: &str| {
        format!(
            "{}/../scenes/identify/{device}.toml",
            env!("CARGO_MANIFEST_DIR")
        )
    };
    let path = scene_path("excalibur");
    let record_of = |path: &str, sets: &[String], load_cell: bool| {
        let scene = Scene::load(Path::new(path), sets).unwrap();
        let ticks = (scene.duration_s / 1e-3).round() as u64;
        let run = pil::run(
            scene,
            ticks,
            LocalBoard::excalibur().unwrap(),
            LinkFaults::default(),
        )
        .unwrap();
        run.experiment_log(load_cell).unwrap().unwrap()
    };
    let log = record_of(&path, &[], true);
    let loaded_log = record_of(&path, &["plant.handle_mass_kg=0.5".into()], true);
    let base = ModelBase {
        name: "identified".into(),
        period_s: 1e-3,
        peak_force_n: 200.0,
        continuous_force_n: 100.0,
        load_cell_pole_rad_s: Some(235.0),
    };
    c.bench_function(
        "identify: responses of a 30 s record (450 harmonics)",
        |b| b.iter(|| Measured::from_log(black_box(&log), 2).unwrap()),
    );
    let data = Measured::from_log(&log, 2).unwrap();
    c.bench_function("identify: fit every order, Excalibur (5 DOF chosen)", |b| {
        b.iter(|| fit::fit_orders(black_box(&data), &base))
    });
    let both = data
        .with_loaded(0.5, Measured::from_log(&loaded_log, 2).unwrap())
        .unwrap();
    c.bench_function(
        "identify: fit every order, then refit with a loaded record",
        |b| b.iter(|| fit::fit_orders(black_box(&both), &base)),
    );
    // (The scene's paths are the repository root's.)
    let capstan = record_of(
        &scene_path("capstan"),
        &[format!(
            "plant.model=\"{}/../models/capstan.toml\"",
            env!("CARGO_MANIFEST_DIR")
        )],
        false,
    );
    let one = Measured::from_log(&capstan, 2).unwrap();
    let encoder_only = ModelBase {
        load_cell_pole_rad_s: None,
        peak_force_n: 10.0,
        continuous_force_n: 4.0,
        ..base.clone()
    };
    c.bench_function("identify: fit every order, capstan (1 DOF chosen)", |b| {
        b.iter(|| fit::fit_orders(black_box(&one), &encoder_only))
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = identify
}
criterion_main!(benches);
