//! The board's code on the host: each law's `step` and a whole servo tick
//! (goal: 20 ns or less). Inputs vary every iteration so nothing folds away.
//!
//! A law's or tick's output struct is made observable by reference
//! (`black_box(&out)`), as a caller reads it in place. Returning it by value
//! from the timed closure copies it, and that copy's wide loads of fields
//! just stored 4 bytes at a time defeat store forwarding: 5-8 ns a call
//! that belong to the harness, not to the law.

use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;
use twoport_control::servo::SensorFrame;
use twoport_control::ve::{
    BilateralConstraint, CursorMass, Port, Solid, UnilateralWall, VirtualEnvironment,
};
use twoport_control::world::vbb::{Block, Vbb, VbbConfig};
use twoport_control::world::{PerAxis, World};
use twoport_control::{
    AdmittanceCoupling, AdmittanceGains, Encoder, FirstDifference, Gains, ImpedanceCoupling,
    ImpedanceGains, Integrator, Position, PositionRegulator, SafetyConfig, Servo,
};

const T: f32 = 1e-3;

/// A wobbling position (±1 mm), different every tick.
fn wobble(k: u32) -> Position {
    Position::from_nm(((k as i64 * 7919) % 2_000_001 - 1_000_000) as i32)
}

fn laws(c: &mut Criterion) {
    let mut k = 0u32;
    let mut est = FirstDifference::new(T, Position::ZERO).unwrap();
    c.bench_function("first-difference estimator step", |b| {
        b.iter(|| {
            k = k.wrapping_add(1);
            black_box(est.step(black_box(wobble(k))))
        })
    });
    let mut x = Integrator::new(T, Position::ZERO);
    c.bench_function("velocity integrator step", |b| {
        b.iter(|| {
            k = k.wrapping_add(1);
            black_box(x.step(black_box((k % 100) as f32 * 1e-3)))
        })
    });
    let mut reg = PositionRegulator::new(51_000.0, 90.0, T).unwrap();
    let held = Integrator::new(T, Position::ZERO);
    c.bench_function("position regulator K_p step", |b| {
        b.iter(|| {
            k = k.wrapping_add(1);
            black_box(reg.step(black_box(wobble(k)), held.exact()))
        })
    });
    let mut zc = ImpedanceCoupling::new(51_000.0, 90.0, T).unwrap();
    let mut fixed = BilateralConstraint::new(Position::ZERO);
    c.bench_function("impedance coupling Z_cI step, bilateral VE", |b| {
        b.iter(|| {
            k = k.wrapping_add(1);
            let out = zc.step(black_box(wobble(k)), 0.01, &mut fixed);
            black_box(&out);
        })
    });
    let mut wall =
        UnilateralWall::new(1e5, 50.0, Position::ZERO, Solid::Above, T, Position::ZERO).unwrap();
    c.bench_function("unilateral wall VE step (exact loop solve)", |b| {
        b.iter(|| {
            k = k.wrapping_add(1);
            let out = wall.step(Port {
                f0_n: black_box((k % 50) as f32 - 25.0),
                z_nspm: 141.0,
            });
            black_box(&out);
        })
    });
    let mut za = AdmittanceCoupling::new(5.0, 500.0, T).unwrap();
    let mut cursor = CursorMass::new(0.25, T, Position::ZERO).unwrap();
    c.bench_function("admittance coupling Z_cA step, cursor VE", |b| {
        b.iter(|| {
            k = k.wrapping_add(1);
            let out = za.step(black_box((k % 20) as f32 - 10.0), &mut cursor);
            black_box(&out);
        })
    });
}

fn encoder() -> Encoder {
    Encoder::new(16, 1_000_000, 0, Position::ZERO).unwrap()
}

/// An enabled servo on Excalibur's limits.
fn enabled<V: VirtualEnvironment>(gains: Gains, ve: V) -> Servo<V> {
    let mut s = Servo::new([gains], [encoder()], [SafetyConfig::excalibur()], ve).unwrap();
    s.enable().unwrap();
    s
}

/// The impedance display's whole tick with the VE `ve`.
fn impedance_tick<V: VirtualEnvironment>(c: &mut Criterion, ve_name: &str, ve: V) {
    let mut s = enabled(ImpedanceGains::new(51_000.0, 90.0).into(), ve);
    let mut k = 0u32;
    c.bench_function(
        &format!("impedance servo tick: encoder, estimator, Z_cI, {ve_name}, safety"),
        |b| {
            b.iter(|| {
                k = k.wrapping_add(1);
                let out = s.tick(&SensorFrame::held(k, [black_box(k % 1000)], [0.0]));
                black_box(&out);
            })
        },
    );
}

/// The wall the ticks push into: 0.5 mm from the start, so the sweep is
/// in contact three quarters of the time (as on the board's probe).
fn wall() -> UnilateralWall {
    let (surface, start) = (Position::from_nm(500_000), Position::ZERO);
    UnilateralWall::new(1e5, 50.0, surface, Solid::Above, T, start).unwrap()
}

fn servos(c: &mut Criterion) {
    impedance_tick(c, "wall", wall());
    // The same tick with the simplest VE: what the wall's contact solve
    // and its own integrator add to the tick.
    impedance_tick(c, "bilateral VE", BilateralConstraint::new(Position::ZERO));
    let cursor = CursorMass::new(0.25, T, Position::ZERO).unwrap();
    let mut a = enabled(
        AdmittanceGains::new(51_000.0, 90.0, 5.0, 500.0).into(),
        cursor,
    );
    let mut k = 0u32;
    c.bench_function(
        "admittance servo tick: load cell, Z_cA, cursor, T/(1-1/z), K_p, safety",
        |b| {
            b.iter(|| {
                k = k.wrapping_add(1);
                let out = a.tick(&SensorFrame::held(
                    k,
                    [0],
                    [black_box(((k % 40) as f32 - 20.0) * 0.1)],
                ));
                black_box(&out);
            })
        },
    );
}

/// 50 blocks of 20 mm in a 10 x 5 grid on the floor, the cursor resting
/// on the middle one's top.
fn fifty_blocks() -> (Vbb<f32, 50>, [Position; 3]) {
    let mut blocks = Vec::with_capacity(50);
    for i in 0..50 {
        let (x, y) = (
            (i % 10) as f32 * 0.025 - 0.125,
            (i / 10) as f32 * 0.025 - 0.0625,
        );
        blocks.push(Block::new([x, y, 0.0], [0.02; 3], 0.1).unwrap());
    }
    let w = Vbb::new(VbbConfig::excalibur(T), &blocks).unwrap();
    let top = blocks[25];
    let at = |a: usize| top.min[a].offset_nm(top.size_nm[a] / 2);
    (
        w,
        [
            at(0),
            at(1),
            top.min[2].offset_nm(top.size_nm[2] + 1_000_000),
        ],
    )
}

/// The three-axis servo and the building-block world (goal: a world step
/// of at most 5 µs with 50 blocks).
fn three_axes(c: &mut Criterion) {
    let (mut w, rest) = fifty_blocks();
    w.reset_axes(&rest);
    let mut k = 0u32;
    c.bench_function("VBB world step, 50 blocks, cursor on a top", |b| {
        b.iter(|| {
            k = k.wrapping_add(1);
            let f = ((k % 64) as f32 - 40.0) * 0.5;
            let p = [0.3 * f, -0.2 * f, f].map(|f0_n| Port {
                f0_n,
                z_nspm: 140.0,
            });
            let out = w.step_axes(black_box(&p));
            black_box(&out);
        })
    });
    let (mut held, _) = fifty_blocks();
    held.reset_axes(&rest);
    assert!(held.grab());
    c.bench_function("VBB world step, 50 blocks, one held", |b| {
        b.iter(|| {
            k = k.wrapping_add(1);
            let f = ((k % 64) as f32 - 32.0) * 0.5;
            let p = [f, -f, 2.0].map(|f0_n| Port {
                f0_n,
                z_nspm: 140.0,
            });
            let out = held.step_axes(black_box(&p));
            black_box(&out);
        })
    });
    let g: Gains = ImpedanceGains::new(51_000.0, 90.0).into();
    let mut s = Servo::new(
        [g; 3],
        [encoder(); 3],
        [SafetyConfig::excalibur(); 3],
        PerAxis([wall(); 3]),
    )
    .unwrap();
    s.enable().unwrap();
    c.bench_function("3-axis impedance servo tick, a wall on each axis", |b| {
        b.iter(|| {
            k = k.wrapping_add(1);
            let raw = black_box(k % 1000 * 2);
            let out = s.tick(&SensorFrame {
                tick: k,
                encoder_raw: [raw; 3],
                load_cell_n: [0.0; 3],
                dead_man_closed: true,
            });
            black_box(&out);
        })
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(30);
    targets = laws, servos, three_axes
}
criterion_main!(benches);
