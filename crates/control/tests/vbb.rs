//! The 3-D building-block world: free space is the cursor's mass, faces
//! stop the body without penetration or bounce, friction holds inside its
//! cone, blocks are carried, stacked and dropped, and the world never gives
//! back more energy than its ports put in.

use proptest::prelude::*;
use twoport_control::ve::{CursorMass, Port, VirtualEnvironment};
use twoport_control::world::vbb::{Block, Vbb, VbbConfig, G_MPS2};
use twoport_control::world::World;
use twoport_control::Position;

const T: f32 = 1e-3;

type World8 = Vbb<f32, 8>;

/// The Excalibur's world with smooth-topped blocks.
fn world(blocks: &[Block]) -> World8 {
    let cfg = VbbConfig {
        knobs: None,
        ..VbbConfig::excalibur(T)
    };
    Vbb::new(cfg, blocks).unwrap()
}

fn cube(x_m: f32, y_m: f32, z_m: f32, side_m: f32, mass_kg: f32) -> Block {
    Block::new([x_m, y_m, z_m], [side_m; 3], mass_kg).unwrap()
}

fn ports(f0_n: [f32; 3], z_nspm: f32) -> [Port; 3] {
    f0_n.map(|f0_n| Port { f0_n, z_nspm })
}

fn mm(p: Position) -> f32 {
    p.nm() as f32 * 1e-6
}

/// Far from every face, each axis is the implicit cursor of the one-axis
/// world: the same velocities, to f32 rounding, under any port.
#[test]
fn free_space_is_the_cursor_mass_on_every_axis() {
    let mut w = world(&[]);
    w.place_cursor([0.0, 0.0, 0.1]);
    let mut one = CursorMass::new(0.25, T, Position::ZERO).unwrap();
    for k in 0..300 {
        let f = (k as f32 * 0.05).sin() * 3.0;
        let p = ports([f, -f, 0.5 * f], 40.0);
        let out = w.step_axes(&p);
        let want = one.step(p[0]);
        let err = (out[0].velocity_mps - want.velocity_mps).abs();
        assert!(err <= 1e-6, "tick {k}: {err} m/s apart");
        assert_eq!(out[1].velocity_mps, -out[0].velocity_mps);
    }
}

/// Driven hard into the floor, the cursor stops at it (its half-width
/// above), the floor's push is the drive, and when the drive stops it rests:
/// no penetration, no bounce.
#[test]
fn a_face_stops_the_body_without_penetration_or_bounce() {
    let mut w = world(&[]);
    w.place_cursor([0.0, 0.0, 0.02]);
    let floor_contact_nm = 1_000_000; // the cursor's half-width
    let mut lowest = i32::MAX;
    for _ in 0..300 {
        let out = w.step_axes(&ports([0.0, 0.0, -50.0], 10.0));
        lowest = lowest.min(w.cursor()[2].nm());
        assert!(out[2].velocity_mps <= 0.0, "it never bounces up");
    }
    assert_eq!(lowest, floor_contact_nm);
    for _ in 0..50 {
        let out = w.step_axes(&ports([0.0; 3], 10.0));
        assert_eq!(out[2].velocity_mps, 0.0);
    }
    assert_eq!(w.cursor()[2].nm(), floor_contact_nm);
}

/// Pressed onto the floor with 10 N (friction 0.3), a 2 N sideways pull
/// holds it; a 5 N pull slides it with (5 - 3) N of net force.
#[test]
fn friction_holds_inside_its_cone_and_slides_outside() {
    let mut w = world(&[]);
    w.place_cursor([0.0, 0.0, 0.001]);
    for _ in 0..10 {
        w.step_axes(&ports([0.0, 0.0, -10.0], 1e-3));
    }
    let x0 = w.cursor()[0];
    for _ in 0..200 {
        let out = w.step_axes(&ports([2.0, 0.0, -10.0], 1e-3));
        assert_eq!(out[0].velocity_mps, 0.0);
    }
    assert_eq!(w.cursor()[0], x0);
    let mut v = 0.0;
    for _ in 0..100 {
        v = w.step_axes(&ports([5.0, 0.0, -10.0], 1e-3))[0].velocity_mps;
    }
    // a = (5 - 0.3 x 10) / 0.25 = 8 m/s^2 for 0.1 s.
    assert!((v - 0.8).abs() < 0.01, "{v} m/s");
}

/// Move the cursor with a stiff position servo (a spring and damper to a
/// target), as a hand on the device would.
fn drive_to(w: &mut World8, target_m: [f32; 3], ticks: u32) {
    for _ in 0..ticks {
        let x = w.cursor();
        let p: [Port; 3] = [0, 1, 2].map(|a| Port {
            f0_n: 400.0 * (target_m[a] - x[a].m()),
            z_nspm: 40.0,
        });
        w.step_axes(&p);
    }
}

/// Two 30 mm cubes on the floor, A at the origin and B 30 mm to its
/// right, the cursor on B's top holding it; and A.
fn holding_b_beside_a() -> (World8, Block) {
    let (a, b) = (
        cube(0.0, 0.0, 0.0, 0.03, 0.1),
        cube(0.06, 0.0, 0.0, 0.03, 0.1),
    );
    let mut w = world(&[a, b]);
    w.place_cursor([0.075, 0.015, 0.031]);
    assert!(w.grab());
    assert_eq!(w.held(), Some(1));
    (w, a)
}

/// Grab a block, lift it, carry it over another, lower it until the other
/// holds it, let go: it stays on top. Grab it again, lift and let go in the
/// air: it falls to the floor.
#[test]
fn a_block_is_carried_stacked_on_another_and_dropped() {
    let (mut w, a) = holding_b_beside_a();
    drive_to(&mut w, [0.075, 0.015, 0.08], 800);
    assert!(mm(w.blocks()[1].min[2]) > 40.0, "lifted");
    drive_to(&mut w, [0.015, 0.015, 0.08], 800);
    // Lower it onto A: A's top stops it at 30 mm however hard the hand
    // pushes down.
    let a_top = a.min[2].nm() + a.size_nm[2];
    drive_to(&mut w, [0.015, 0.015, 0.0], 800);
    assert_eq!(w.blocks()[1].min[2].nm(), a_top);
    w.release();
    drive_to(&mut w, [0.015, 0.015, 0.1], 300);
    assert_eq!(w.blocks()[1].min[2].nm(), a_top, "stacked");
    assert_eq!(w.blocks()[0].min[2].nm(), 0);

    // Off again, into the air, and dropped beside A: it falls to the floor.
    drive_to(&mut w, [0.015, 0.015, 0.0605], 500);
    assert!(w.grab());
    drive_to(&mut w, [0.075, 0.015, 0.12], 1500);
    let z0 = mm(w.blocks()[1].min[2]);
    assert!(z0 > 60.0, "{z0} mm");
    w.release();
    for _ in 0..1000 {
        w.step_axes(&ports([0.0; 3], 40.0));
    }
    assert_eq!(w.blocks()[1].min[2].nm(), 0, "on the floor");
}

/// The body cannot be pushed into a block from the side either: a held
/// block driven at another stops at its face.
#[test]
fn a_held_block_slides_on_faces_but_never_enters_them() {
    let (mut w, a) = holding_b_beside_a();
    // Drive B through A's place, along the floor.
    drive_to(&mut w, [-0.05, 0.015, 0.031], 1500);
    let b_min_x = w.blocks()[1].min[0].nm();
    let a_max_x = a.min[0].nm() + a.size_nm[0];
    assert_eq!(b_min_x, a_max_x, "B's left face on A's right face");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(40))]

    /// Passivity at the ports: with the held block's weight (or without a
    /// block) and any port sequence, the energy the ports put in is never
    /// less than the kinetic and potential energy the body gained.
    #[test]
    fn the_world_never_gives_back_more_than_it_was_given(
        seed in any::<u64>(),
        z_n in 5.0f32..105.0,
        holding in any::<bool>(),
    ) {
        let blocks = [
            cube(0.0, 0.0, 0.0, 0.03, 0.2),
            cube(0.03, 0.0, 0.0, 0.03, 0.5),
            cube(0.0, 0.04, 0.0, 0.03, 0.1),
        ];
        // (With the knobs: mating and parting change the constraints.)
        let mut w: World8 = Vbb::new(VbbConfig::excalibur(T), &blocks).unwrap();
        w.place_cursor([0.015, 0.015, 0.031]);
        if holding {
            prop_assert!(w.grab());
        }
        let m = w.body_mass_kg() as f64;
        let m_b = m - 0.25;
        let z_of = |w: &World8| w.held().map_or(0.0, |i| w.blocks()[i].min[2].m() as f64);
        let z0 = z_of(&w);
        // Forces of up to 30 N from a linear congruential sequence.
        let mut state = seed;
        let mut force = move || {
            state = state.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
            ((state >> 40) as f32 / (1u64 << 24) as f32 - 0.5) * 60.0
        };
        let mut e_in = 0.0f64;
        for _ in 0..2000 {
            let out = w.step_axes(&ports([force(), force(), force()], z_n));
            let ke: f64 = out.iter().map(|o| 0.5 * m * (o.velocity_mps as f64).powi(2)).sum();
            e_in += out.iter().map(|o| (o.force_n * o.velocity_mps * T) as f64).sum::<f64>();
            let pe = m_b * G_MPS2 as f64 * (z_of(&w) - z0);
            // f32 rounding of a step's energy: far below a millijoule.
            prop_assert!(e_in >= ke + pe - 1e-4, "in {} J, stored {} + {} J", e_in, ke, pe);
        }
    }
}

/// The three-axis impedance servo on the world: a device pressed 2 mm
/// below a block's top (where the cursor stops) feels the coupling's
/// spring push it up, 51,000 N/m x 2 mm, and nothing sideways.
#[test]
fn the_three_axis_servo_renders_a_blocks_top() {
    use twoport_control::servo::{ImpedanceGains, SensorFrame, Servo};
    use twoport_control::{Encoder, SafetyConfig};
    let top = cube(-0.015, -0.015, 0.0, 0.03, 0.1);
    let top_nm = top.size_nm[2];
    let w = world(&[top]);
    let enc = Encoder::new(16, 1_000_000, 0, Position::ZERO).unwrap();
    let g = ImpedanceGains::new(51_000.0, 90.0).into();
    let mut s = Servo::new([g; 3], [enc; 3], [SafetyConfig::excalibur(); 3], w).unwrap();
    // The device starts 10 mm above the cursor's contact with the top.
    let contact_nm = top_nm + 1_000_000;
    s.calibrate([0, 0, contact_nm + 10_000_000].map(Position::from_nm));
    s.enable().unwrap();
    let mut out = None;
    for k in 0..2000u32 {
        // Down 12 mm over 1.2 s, then hold: 2 mm below the contact.
        let dz_um = (k as i32).min(1200) * 10;
        let raw = (-dz_um) as u32 & 0xFFFF;
        out = Some(s.tick(&SensorFrame {
            tick: k,
            encoder_raw: [0, 0, raw],
            load_cell_n: [0.0; 3],
            dead_man_closed: true,
        }));
    }
    let out = out.unwrap();
    assert!(out.faults.is_empty(), "{}", out.faults);
    assert_eq!(s.world().cursor()[2].nm(), contact_nm);
    let f = out.actuator_force_n;
    assert!((f[2] + 102.0).abs() < 0.5, "{f:?}");
    assert!(f[0].abs() < 1e-3 && f[1].abs() < 1e-3, "{f:?}");
}

/// A block resting on the held one falls when the held one slides out
/// from under it, and then rests on the floor.
#[test]
fn a_block_falls_when_its_support_is_pulled_away() {
    let a = cube(0.0, 0.0, 0.0, 0.03, 0.1);
    let mut b = cube(0.0, 0.0, 0.0, 0.03, 0.1);
    b.min[2] = Position::from_nm(a.size_nm[2]);
    let mut w = world(&[a, b]);
    // The cursor against A's left face, below B.
    w.place_cursor([-0.001, 0.015, 0.015]);
    assert!(w.grab());
    assert_eq!(w.held(), Some(0));
    drive_to(&mut w, [-0.06, 0.015, 0.015], 1500);
    assert!(mm(w.blocks()[0].min[0]) < -40.0, "A slid out");
    for _ in 0..500 {
        w.step_axes(&ports([0.0; 3], 40.0));
    }
    assert_eq!(w.blocks()[1].min[2].nm(), 0, "B fell to the floor");
}

/// Knobs: a block set on another rests on its knobs; pressed down past the
/// mating force with the grids aligned it drops onto the top and is held
/// there, sideways and up, until pulled past the parting force. Off the
/// grid, no push mates it.
#[test]
fn knobs_carry_mate_hold_and_part() {
    let cfg = VbbConfig::excalibur(T);
    let k = cfg.knobs.unwrap();
    let (a, b) = (
        cube(0.0, 0.0, 0.0, 0.03, 0.1),
        cube(0.06, 0.0, 0.0, 0.03, 0.1),
    );
    let a_top = a.min[2].nm() + a.size_nm[2];
    for (offset_m, mates) in [(0.0, true), (0.005, false)] {
        let mut w: World8 = Vbb::new(cfg, &[a, b]).unwrap();
        w.place_cursor([0.075, 0.015, 0.032]);
        assert!(w.grab());
        drive_to(&mut w, [0.075, 0.015, 0.08], 800);
        drive_to(&mut w, [0.015 + offset_m, 0.015, 0.08], 800);
        // Lowered with 3 N (and its own 0.98 N): it rests on the knobs.
        let press = |w: &mut World8, f_n: f32, ticks: u32| {
            for _ in 0..ticks {
                let x = w.cursor();
                let hold = |a: usize, at: f32| 400.0 * (at - x[a].m());
                let p = [hold(0, 0.015 + offset_m), hold(1, 0.015), f_n];
                w.step_axes(&p.map(|f0_n| Port { f0_n, z_nspm: 40.0 }));
            }
        };
        press(&mut w, -3.0, 1500);
        assert_eq!(
            w.blocks()[1].min[2].nm(),
            a_top + k.height_nm,
            "on the knobs"
        );
        // Pressed with 6 N: aligned, it mates and drops onto the top.
        press(&mut w, -6.0, 300);
        let seated = w.blocks()[1].min[2].nm() == a_top;
        assert_eq!(seated, mates, "offset {offset_m} m");
        if !mates {
            continue;
        }
        // Held sideways by the knobs, and up against a 6 N pull.
        let x0 = w.blocks()[1].min[0];
        drive_to(&mut w, [0.05, 0.015, 0.03], 300);
        assert_eq!(w.blocks()[1].min[0], x0, "the knobs hold it sideways");
        press(&mut w, 6.0, 300);
        assert_eq!(w.blocks()[1].min[2].nm(), a_top, "held against 6 N");
        // Pulled with 12 N it parts and lifts.
        press(&mut w, 12.0, 300);
        assert!(w.blocks()[1].min[2].nm() > a_top + 5_000_000, "parted");
    }
}

/// A world with knobs of no pitch, a negative friction or more blocks
/// than it holds is refused by name.
#[test]
fn bad_worlds_are_refused_by_name() {
    let mut cfg = VbbConfig::excalibur(T);
    if let Some(k) = cfg.knobs.as_mut() {
        k.pitch_nm = 0;
    }
    let e = World8::new(cfg, &[]).unwrap_err();
    assert_eq!(e.name, "vbb.knobs.pitch_nm");
    let cfg = VbbConfig {
        friction: -0.1,
        ..VbbConfig::excalibur(T)
    };
    assert_eq!(World8::new(cfg, &[]).unwrap_err().name, "vbb.friction");
    let many = [cube(0.0, 0.0, 0.0, 0.01, 0.1); 9];
    let e = World8::new(VbbConfig::excalibur(T), &many).unwrap_err();
    assert_eq!(e.name, "vbb.blocks");
}

/// The paper's explicit scheme against the passive default: a 20 g cursor
/// pulled 1 mm off the device held still, through the paper's coupling.
/// Implicit, it settles onto the device; explicit, it rings up until the
/// amplifier's limit holds the force (the paper's cursor needed 0.25 kg).
#[test]
fn the_explicit_scheme_rings_where_the_implicit_one_settles() {
    use twoport_control::servo::{ImpedanceGains, SensorFrame, Servo};
    use twoport_control::{Encoder, SafetyConfig};
    // The largest force the coupling asked for over the last 100 of 500
    // ticks (N).
    let late_command = |explicit: bool| {
        let cfg = VbbConfig {
            cursor_mass_kg: 0.02,
            explicit,
            ..VbbConfig::excalibur(T)
        };
        let w: World8 = Vbb::new(cfg, &[]).unwrap();
        let start = w.cursor();
        let enc = Encoder::new(16, 1_000_000, 0, Position::ZERO).unwrap();
        let g = ImpedanceGains::new(51_000.0, 90.0).into();
        let safety = SafetyConfig {
            ramp_ticks: 1,
            ..SafetyConfig::excalibur()
        };
        let mut s = Servo::new([g; 3], [enc; 3], [safety; 3], w).unwrap();
        s.calibrate(start);
        s.enable().unwrap();
        // (After enable, which re-aligns the world to the device.)
        s.world_mut().place_cursor([0.001, 0.0, start[2].m()]);
        let mut worst = 0.0f32;
        for k in 0..500u32 {
            let out = s.tick(&SensorFrame {
                tick: k,
                encoder_raw: [0; 3],
                load_cell_n: [0.0; 3],
                dead_man_closed: true,
            });
            assert!(out.faults.is_empty(), "{}", out.faults);
            if k >= 400 {
                worst = worst.max(out.commanded_force_n[0].abs());
            }
        }
        worst
    };
    let implicit = late_command(false);
    assert!(implicit < 0.01, "implicit: {implicit} N");
    let explicit = late_command(true);
    assert!(explicit > 200.0, "explicit: {explicit} N");
}
