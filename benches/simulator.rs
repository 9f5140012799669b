//! Simulator speed: one simulated second (1,000 ticks) of the linear 5-DOF
//! Excalibur scene with exact ZOH (goal: 20,000x real time, i.e. 50 us per
//! simulated second), the added cost of each effect, and the tick's parts
//! alone (the plant's step, the servo's tick), all measured in one run so
//! they compare as ratios: what the whole tick costs beyond its parts is
//! the hand, the bookkeeping and the recording.

use criterion::{criterion_group, criterion_main, BatchSize, Criterion};
use host_sim::engine::human::GraspKind;
use host_sim::engine::plant::{Method, SimDevice, Stepper};
use host_sim::engine::servo::SceneServo;

use host_sim::{Scene, Simulation};
use std::hint::black_box;
use std::path::Path;
use twoport_control::servo::SensorFrame;
use twoport_control::{Encoder, Position, SafetyConfig};
use twoport_design::DeviceModel;

const SCENE: &str = "scenes/table1/impedance_bilateral_maximum.toml";

fn scene(sets: &[&str]) -> Scene {
    let root = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/.."));
    let sets: Vec<String> = sets
        .iter()
        .map(|s| s.to_string())
        .chain(["duration_s=1000".to_string()])
        .collect();
    let mut s = Scene::load(&root.join(SCENE), &sets).unwrap();
    s.plant.model = root.join("models/excalibur.toml");
    s
}

fn one_second(c: &mut Criterion, name: &str, sets: &[&str]) {
    let s = scene(sets);
    ticks_of(
        c,
        name,
        || Simulation::new(s.clone()).unwrap(),
        |sim| {
            black_box(sim.step());
        },
    );
}

/// 1,000 ticks (one simulated second) of fresh simulations from `make`.
fn ticks_of<S>(c: &mut Criterion, name: &str, make: impl Fn() -> S, mut tick: impl FnMut(&mut S)) {
    c.bench_function(name, |b| {
        b.iter_batched_ref(
            &make,
            |sim| {
                for _ in 0..1000 {
                    tick(sim);
                }
            },
            BatchSize::LargeInput,
        )
    });
}

/// 1,000 of the tick's parts alone, as the linear scene runs them.
fn parts(c: &mut Criterion) {
    let s = scene(&[]);
    let model = DeviceModel::from_toml(include_str!("../models/excalibur.toml"), "excalibur")
        .expect("the shipped model");
    let dev = SimDevice::flexible(&model).expect("a device");
    let sys = dev.system(GraspKind::Maximum.grasp(), false);
    let mut st = Stepper::new(&sys, Method::ExactZoh, 1e-3).expect("a stepper");
    let mut x = vec![0.0; sys.states()];
    c.bench_function("part: 1,000 plant steps (10 states, exact ZOH)", |b| {
        b.iter(|| {
            for _ in 0..1000 {
                st.step(&mut x, black_box([1.0, 0.5]), None);
            }
            black_box(&x);
        })
    });
    let enc = Encoder::new(32, 1000, 0, Position::ZERO).expect("an encoder");
    let mut servo = SceneServo::new(&s, enc, SafetyConfig::excalibur()).expect("the scene's servo");
    let mut tick = 0u32;
    c.bench_function("part: 1,000 servo ticks (board f32 laws)", |b| {
        b.iter(|| {
            for _ in 0..1000 {
                tick = tick.wrapping_add(1);
                let f = SensorFrame {
                    tick,
                    encoder_raw: [black_box(tick % 64)],
                    load_cell_n: [0.0],
                    dead_man_closed: true,
                };
                black_box(servo.tick(&f));
            }
        })
    });
}

fn effects(c: &mut Criterion) {
    one_second(c, "1 s of the linear 5-DOF scene, exact ZOH", &[]);
    one_second(c, "1 s, rigid 1-DOF plant", &["effects.flexibility=false"]);
    one_second(
        c,
        "1 s + encoder quantisation",
        &["effects.encoder.resolution_m=1e-6"],
    );
    one_second(
        c,
        "1 s + load cell and ADC noise",
        &[
            "effects.load_cell=true",
            "effects.adc.lsb_n=0.01",
            "effects.adc.noise_rms_n=0.05",
        ],
    );
    one_second(c, "1 s + saturation", &["effects.saturation.limit_n=200.0"]);
    one_second(c, "1 s + 2-tick delay", &["effects.delay.ticks=2"]);
    one_second(
        c,
        "1 s + Coulomb friction (RK4 x 20)",
        &["effects.coulomb.force_n=2.0"],
    );
    one_second(
        c,
        "1 s + cogging (RK4 x 20)",
        &[
            "effects.cogging.amplitude_n=0.5",
            "effects.cogging.period_m=0.002",
        ],
    );
    one_second(
        c,
        "1 s + cable slack (RK4 x 20)",
        &["effects.cable_slack.width_m=1e-5"],
    );
}

/// One simulated second of a three-axis linear scene (Table I's bilateral
/// maximum in 3-D: three 5-DOF Excalibur plants, the 3-axis servo; goal
/// 5,000x real time, 200 us) and of the 50-block world.
fn three_axes(c: &mut Criterion) {
    let root = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/.."));
    for (name, file) in [
        (
            "1 s, 3 axes, Table I bilateral maximum in 3-D",
            "scenes/xyz/table1/impedance_bilateral_maximum.toml",
        ),
        (
            "1 s, 3 axes, the 50-block world",
            "scenes/xyz/fifty_blocks.toml",
        ),
    ] {
        let mut s = Scene::load(&root.join(file), &["duration_s=1000".to_string()]).unwrap();
        s.plant.model = root.join("models/excalibur.toml");
        ticks_of(
            c,
            name,
            || Simulation::<3>::with_axes(s.clone()).unwrap(),
            |sim| {
                black_box(sim.step());
            },
        );
    }
}

/// The whole 17 s of stacking three blocks (grabs, carries, sets down and
/// mates), with each thing a world scene can name added one at a time to
/// a world without friction or knobs: what each costs.
fn three_axis_effects(c: &mut Criterion) {
    let root = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/.."));
    let bare = ["ve.friction=0.0", "ve.knobs=false"];
    let with = |set: &str| -> Vec<String> {
        let key = set.split('=').next().unwrap_or("");
        bare.iter()
            .filter(|b| !b.starts_with(key))
            .chain([&set])
            .map(|s| s.to_string())
            .collect()
    };
    for (name, sets) in [
        ("17 s stacking, no friction or knobs", with("")),
        ("17 s stacking + friction 0.3", with("ve.friction=0.3")),
        ("17 s stacking + knobs", with("ve.knobs=true")),
        ("17 s stacking + explicit cursor", with("ve.explicit=true")),
        (
            "17 s stacking + 10 % cross-axis coupling",
            with("plant.cross_coupling=0.1"),
        ),
    ] {
        let sets: Vec<String> = sets.into_iter().filter(|s| !s.is_empty()).collect();
        let mut s = Scene::load(&root.join("scenes/xyz/stack_three.toml"), &sets).unwrap();
        s.plant.model = root.join("models/excalibur.toml");
        c.bench_function(name, |b| {
            b.iter_batched_ref(
                || Simulation::<3>::with_axes(s.clone()).unwrap(),
                |sim| {
                    while sim.ticks() < sim.total_ticks() {
                        black_box(sim.step());
                    }
                },
                BatchSize::LargeInput,
            )
        });
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20);
    targets = effects, parts, three_axes, three_axis_effects
}
criterion_main!(benches);
