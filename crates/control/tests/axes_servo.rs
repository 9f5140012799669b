//! The servo on several axes: three axes of independent VEs fed the same
//! frames are each the one-axis servo bit for bit; with three, every axis's tick matches its own laws' z-domain forms while
//! the others work, and a fault on any axis gives zero force on all of them
//! in the tick that finds it.

use twoport_control::safety::AxisError;
use twoport_control::servo::{LawsRef, SensorFrame};
use twoport_control::ve::{CursorMass, VeTransfer, VirtualEnvironment};
use twoport_control::world::{PerAxis, World};
use twoport_control::{
    AdmittanceGains, Complex64, Faults, Gains, GainsError, ImpedanceGains, Position, SafetyConfig,
    Servo, SineProbe,
};

mod common;

use common::{encoder, raw, wall, T};

fn cursor(m_kg: f32) -> CursorMass {
    CursorMass::new(m_kg, T, Position::ZERO).unwrap()
}

fn impedance(k_npm: f32, b_nspm: f32) -> Gains {
    ImpedanceGains::new(k_npm, b_nspm).into()
}

fn admittance(kp_npm: f32, m_kg: f32) -> Gains {
    AdmittanceGains::new(kp_npm, 90.0, m_kg, 500.0).into()
}

fn three<W: World<f32, 3>>(gains: [Gains; 3], world: W) -> Servo<W, f32, 3> {
    Servo::new(gains, [encoder(); 3], [SafetyConfig::excalibur(); 3], world).unwrap()
}

/// A deterministic wandering trajectory (µm) and load (N), with a dead-man
/// release, a bad encoder value and a missed tick on the way.
fn script(k: u32) -> (u32, u32, f32, bool) {
    let x = ((k as f32 * 0.013).sin() * 1500.0 + (k as f32 * 0.11).sin() * 40.0) as i32;
    let f = (k as f32 * 0.007).cos() * 30.0;
    let tick = if k >= 2500 { k + 1 } else { k };
    let raw = if k == 1800 { 0x1_0000 } else { raw(x) };
    (tick, raw, f, !(900..905).contains(&k))
}

/// Both displays: a one-axis servo on a VE, and a three-axis one on three
/// copies of it fed the same frame on every axis, give the same bits in
/// every output of every axis, through faults, clears and enables.
#[test]
fn each_axis_of_independent_axes_is_the_one_axis_servo_bit_for_bit() {
    type Make<V> = fn() -> V;
    fn run<V: VirtualEnvironment + Copy + core::fmt::Debug>(gains: Gains, ve: Make<V>) {
        let safety = SafetyConfig {
            require_dead_man: true,
            ..SafetyConfig::excalibur()
        };
        let mut one = Servo::new([gains], [encoder()], [safety], ve()).unwrap();
        let mut axes =
            Servo::new([gains; 3], [encoder(); 3], [safety; 3], PerAxis([ve(); 3])).unwrap();
        let (mut faults_seen, mut forces_seen) = (0, 0);
        for k in 0..4000u32 {
            if k % 700 == 0 {
                one.clear();
                axes.clear();
                assert_eq!(one.enable(), axes.enable());
            }
            let (tick, raw, f, dead_man) = script(k);
            let a = one.tick(&SensorFrame {
                tick,
                encoder_raw: [raw],
                load_cell_n: [f],
                dead_man_closed: dead_man,
            });
            let b = axes.tick(&SensorFrame {
                tick,
                encoder_raw: [raw; 3],
                load_cell_n: [f; 3],
                dead_man_closed: dead_man,
            });
            for i in 0..3 {
                let bits = |x: f32| x.to_bits();
                let what = format!("{:?} tick {k} axis {i}", gains.display());
                assert_eq!(
                    bits(a.actuator_force_n[0]),
                    bits(b.actuator_force_n[i]),
                    "{what}"
                );
                assert_eq!(
                    bits(a.commanded_force_n[0]),
                    bits(b.commanded_force_n[i]),
                    "{what}"
                );
                assert_eq!(bits(a.velocity_mps[0]), bits(b.velocity_mps[i]), "{what}");
                assert_eq!(
                    bits(a.ve_velocity_mps[0]),
                    bits(b.ve_velocity_mps[i]),
                    "{what}"
                );
                assert_eq!(bits(a.ve_force_n[0]), bits(b.ve_force_n[i]), "{what}");
                assert_eq!(
                    bits(a.coupling_force_n[0]),
                    bits(b.coupling_force_n[i]),
                    "{what}"
                );
                assert_eq!(a.position[0], b.position[i], "{what}");
                assert_eq!(a.reference[0], b.reference[i], "{what}");
                assert_eq!((a.faults, a.limited[0]), (b.faults, b.limited[i]), "{what}");
            }
            faults_seen += !a.faults.is_empty() as u32;
            forces_seen += (a.actuator_force_n[0].abs() > 0.01) as u32;
        }
        // The script exercised both the running and the faulted paths.
        assert!(
            faults_seen > 100 && forces_seen > 1000,
            "{faults_seen} {forces_seen}"
        );
    }
    run(impedance(51_000.0, 90.0), || wall(20_000.0));
    run(impedance(30_000.0, 40.0), || cursor(0.5));
    run(admittance(51_000.0, 5.0), || wall(20_000.0));
    run(admittance(20_000.0, 2.0), || cursor(0.5));
}

/// `z` at DFT bin `p` of a 4,000-tick window.
fn z_at(p: usize) -> Complex64 {
    let th = 2.0 * std::f64::consts::PI * p as f64 / 4000.0;
    Complex64::new(th.cos(), th.sin())
}

fn impedance_of(t: VeTransfer, z: Complex64) -> Complex64 {
    match t {
        VeTransfer::Impedance(t) => t.eval(z),
        VeTransfer::Admittance(t) => t.eval(z).inv(),
    }
}

fn assert_response(axis: usize, p: usize, got: Complex64, want: Complex64) {
    let err = (got - want).norm() / want.norm();
    assert!(
        err <= 1e-4,
        "axis {axis} bin {p}: measured {got}, composed {want}"
    );
}

/// Impedance display, three axes with their own gains against three
/// cursors: each axis in turn is driven with a sinusoid while the others
/// hold 1 mm off, and its force per position is its own
/// `Z_cI / (1 + Z_cI Y_e)` times the estimator's `(1 - z^-1)/T`: the world
/// solved every axis's loop in the same tick, exactly.
#[test]
fn impedance_axes_each_match_their_composed_z_form() {
    let gains = [
        impedance(51_000.0, 90.0),
        impedance(20_000.0, 150.0),
        impedance(5_000.0, 10.0),
    ];
    let masses = [0.25, 0.5, 1.0];
    for axis in 0..3 {
        for p in [1usize, 10, 100, 700, 1500, 1999] {
            let mut s = three(gains, PerAxis(masses.map(cursor)));
            s.enable().unwrap();
            let z = z_at(p);
            let mut probe = SineProbe::new(z.re, z.im);
            for k in 0..7000u32 {
                let mut counts = [1000i32; 3];
                counts[axis] = (300.0 * probe.excitation()).round() as i32;
                let out = s.tick(&SensorFrame {
                    tick: k,
                    encoder_raw: counts.map(raw),
                    load_cell_n: [0.0; 3],
                    dead_man_closed: true,
                });
                assert!(out.faults.is_empty(), "{}", out.faults);
                let x = counts[axis] as f64 * 1e-6;
                if k >= 3000 {
                    probe.record(x, out.actuator_force_n[axis] as f64);
                } else {
                    probe.skip();
                }
            }
            let Some(LawsRef::Impedance(c)) = s.laws(axis) else {
                panic!("an impedance servo");
            };
            let (zc, ye) = (
                c.tf().eval(z),
                impedance_of(s.world().axis_tf(axis), z).inv(),
            );
            let want = zc / (1.0 + zc * ye) * (1.0 - z.inv()) / T as f64;
            assert_response(axis, p, probe.response(), want);
        }
    }
}

/// Admittance display, three axes with their own gains against three walls:
/// each axis in turn gets a sinusoidal load while the others push a steady
/// 10 N, device held still; its actuator force per measured force is its
/// own `-K_p T/(1 - z^-1) / (Z_cA + Z_wall)`.
#[test]
fn admittance_axes_each_match_their_composed_z_form() {
    let gains = [
        admittance(51_000.0, 5.0),
        admittance(30_000.0, 3.0),
        admittance(10_000.0, 8.0),
    ];
    for axis in 0..3 {
        for p in [1usize, 10, 100, 400, 1000, 1999] {
            let mut s = three(
                gains,
                PerAxis([wall(20_000.0), wall(5_000.0), wall(40_000.0)]),
            );
            s.enable().unwrap();
            let z = z_at(p);
            let mut probe = SineProbe::new(z.re, z.im);
            for k in 0..7000u32 {
                let mut f = [10.0f32; 3];
                f[axis] = (20.0 + 5.0 * probe.excitation()) as f32;
                let out = s.tick(&SensorFrame {
                    tick: k,
                    encoder_raw: [0; 3],
                    load_cell_n: f,
                    dead_man_closed: true,
                });
                assert!(out.faults.is_empty(), "{}", out.faults);
                if k >= 3000 {
                    probe.record(f[axis] as f64, out.actuator_force_n[axis] as f64);
                } else {
                    probe.skip();
                }
            }
            let Some(LawsRef::Admittance {
                coupling,
                regulator,
            }) = s.laws(axis)
            else {
                panic!("an admittance servo");
            };
            let integ = T as f64 / (1.0 - z.inv());
            let zw = impedance_of(s.world().axis_tf(axis), z);
            let want = -regulator.tf().eval(z) * integ / (coupling.tf().eval(z) + zw);
            assert_response(axis, p, probe.response(), want);
        }
    }
}

/// Pressing 2 mm into a wall on every axis, then a fault that only one axis
/// can see: every axis's force is zero in that very tick, and stays zero
/// until the latch is cleared.
#[test]
fn a_fault_on_any_axis_zeroes_every_axis_in_the_same_tick() {
    // (what, the axis whose reading goes bad, the bad frame, the fault)
    type Spoil = fn(&mut SensorFrame<f32, 3>, usize);
    let cases: [(&str, Spoil, Faults); 4] = [
        (
            "encoder value too wide",
            |f, a| f.encoder_raw[a] = 0x1_0000,
            Faults::ENCODER_INVALID,
        ),
        (
            "encoder jump past the speed limit",
            |f, a| f.encoder_raw[a] = raw(-3000),
            Faults::VELOCITY_LIMIT,
        ),
        (
            "NaN load cell",
            |f, a| f.load_cell_n[a] = f32::NAN,
            Faults::SENSOR_NOT_FINITE,
        ),
        (
            "load cell at its rail",
            |f, a| f.load_cell_n[a] = 1.0e4,
            Faults::SENSOR_OUT_OF_RANGE,
        ),
    ];
    for (what, spoil, fault) in cases {
        for axis in 0..3 {
            let admittance_only = matches!(
                fault,
                Faults::SENSOR_NOT_FINITE | Faults::SENSOR_OUT_OF_RANGE
            );
            let (gains, press) = if admittance_only {
                ([admittance(51_000.0, 5.0); 3], [20.0f32; 3])
            } else {
                ([impedance(51_000.0, 90.0); 3], [0.0; 3])
            };
            let mut s = three(gains, PerAxis([wall(20_000.0); 3]));
            // The device rests 2 mm inside the wall on every axis.
            s.calibrate([Position::from_m(2e-3).unwrap(); 3]);
            s.enable().unwrap();
            let frame = |tick| SensorFrame {
                tick,
                encoder_raw: [0; 3],
                load_cell_n: press,
                dead_man_closed: true,
            };
            let mut tick = 0;
            let mut out = s.tick(&frame(tick));
            // Past the ramp-in.
            for _ in 0..200 {
                tick += 1;
                out = s.tick(&frame(tick));
            }
            assert!(out.faults.is_empty(), "{what}: {}", out.faults);
            assert!(
                out.actuator_force_n.iter().all(|f| f.abs() > 5.0),
                "{what}: {out:?}"
            );
            tick += 1;
            let mut bad = frame(tick);
            spoil(&mut bad, axis);
            let out = s.tick(&bad);
            assert_eq!(out.actuator_force_n, [0.0; 3], "{what} on axis {axis}");
            assert!(
                out.faults.contains(fault),
                "{what} on axis {axis}: {}",
                out.faults
            );
            for _ in 0..50 {
                tick += 1;
                assert_eq!(
                    s.tick(&frame(tick)).actuator_force_n,
                    [0.0; 3],
                    "{what}: latched"
                );
            }
            assert!(s.enable().is_err());
            s.clear();
            tick += 1;
            let out = s.tick(&frame(tick));
            assert!(out.faults.is_empty(), "{what}: {}", out.faults);
        }
    }
}

/// I²t is per motor: one axis held at its peak folds back to its
/// continuous rating after its 2 s budget, while an axis at 60 N does not.
#[test]
fn each_motor_has_its_own_thermal_budget() {
    let mut s = three([admittance(51_000.0, 5.0); 3], PerAxis([cursor(0.25); 3]));
    s.enable().unwrap();
    let mut peak_axis_folded = None;
    for k in 0..4000u32 {
        // The device is held still: the position command runs away from it,
        // and the regulator asks for more than any limit.
        let out = s.tick(&SensorFrame {
            tick: k,
            encoder_raw: [0; 3],
            load_cell_n: [50.0, 0.0, 0.0],
            dead_man_closed: true,
        });
        assert!(out.faults.is_empty());
        if k > 200 && peak_axis_folded.is_none() && out.actuator_force_n[0].abs() < 199.0 {
            peak_axis_folded = Some(k);
        }
        assert_eq!(out.actuator_force_n[1], 0.0);
    }
    let folded = peak_axis_folded.expect("axis 0 must fold back") as f32 * T;
    assert!((folded - 2.05).abs() < 0.15, "folded at {folded} s");
    assert!(s.safety().thermal_load_of(0) >= 1.0);
    assert_eq!(s.safety().thermal_load_of(1), 0.0);
}

/// A refusal names the axis: mixed displays, a bad gain, limits that
/// disagree on the period; a refused change of gains changes none.
#[test]
fn refusals_name_the_axis_and_change_nothing() {
    let world = || PerAxis([cursor(0.5); 3]);
    let safety = [SafetyConfig::excalibur(); 3];
    let e = Servo::new(
        [
            impedance(1e4, 10.0),
            admittance(1e4, 5.0),
            impedance(1e4, 10.0),
        ],
        [encoder(); 3],
        safety,
        world(),
    )
    .unwrap_err();
    assert!(
        matches!(
            e,
            AxisError {
                axis: 1,
                error: GainsError::WrongDisplay { .. }
            }
        ),
        "{e}"
    );
    let e = Servo::new(
        [
            impedance(1e4, 10.0),
            impedance(1e4, 10.0),
            impedance(-1.0, 10.0),
        ],
        [encoder(); 3],
        safety,
        world(),
    )
    .unwrap_err();
    assert_eq!(e.axis, 2, "{e}");
    assert!(e.to_string().starts_with("axis 2: k_c (N/m) = -1"), "{e}");
    let mut slow = safety;
    slow[1].period_s = 2e-3;
    let e = Servo::new([impedance(1e4, 10.0); 3], [encoder(); 3], slow, world()).unwrap_err();
    assert_eq!(e.axis, 1, "{e}");

    let mut s = three([impedance(1e4, 10.0); 3], world());
    let before = s.gains();
    let e = s
        .set_gains([
            impedance(2e4, 20.0),
            impedance(2e4, 20.0),
            impedance(2e4, f32::NAN),
        ])
        .unwrap_err();
    assert_eq!(e.axis, 2);
    assert_eq!(s.gains(), before, "a refused change changes no axis");
    s.set_gains([
        impedance(2e4, 20.0),
        impedance(3e4, 30.0),
        impedance(4e4, 40.0),
    ])
    .unwrap();
    assert_eq!(s.gains()[2], impedance(4e4, 40.0));
}
