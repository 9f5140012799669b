//! The simulator on three axes, on the shipped scenes: Table I's states in 3-D
//! run stably at the proven coupling and 4x past it does not; a block is
//! picked and set down, three are stacked knob on knob, and the 50-block
//! world runs; bad scene files are refused by name.

use host_sim::engine::human::AxisValue;
use host_sim::{Report, Scene, Simulation};
use std::path::Path;

fn run(file: &str, sets: &[&str]) -> (Report, Simulation<3>) {
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    let scene = Scene::load(&Path::new("../scenes/xyz").join(file), &sets).unwrap();
    let mut sim = Simulation::with_axes(scene).unwrap();
    let r = sim.run(|_| {});
    (r, sim)
}

/// Each of the eighteen Table I cases in 3-D (both displays) is stable at
/// the x axis's proven design on every axis; at 4x its stiffness (the
/// impedance coupling's `k`, the admittance regulator's `kp`) the
/// bilateral case is not.
#[test]
fn table1_in_3d_is_stable_at_the_proven_gains() {
    for display in ["impedance", "admittance"] {
        for state in ["free", "unilateral", "bilateral"] {
            for grasp in ["hands_off", "relaxed", "maximum"] {
                let case = format!("table1/{display}_{state}_{grasp}.toml");
                let (r, sim) = run(&case, &[]);
                assert!(r.stable, "{case}: {r:?}");
                assert!(r.peak_force_n > 1.0, "{case}: the scene did something");
                if state == "unilateral" && grasp != "hands_off" {
                    // The hand reached 20 mm down: the cursor rests on the
                    // floor.
                    let z = sim.servo().ve_position()[2].nm();
                    assert_eq!(z, 1_000_000, "{case}: the cursor on the floor");
                }
            }
        }
    }
    for (display, stiffer) in [
        ("impedance", "coupling.k=204000"),
        ("admittance", "coupling.kp=204000"),
    ] {
        let (r, _) = run(
            &format!("table1/{display}_bilateral_maximum.toml"),
            &[stiffer],
        );
        assert!(!r.stable, "{display}, 4x the proven stiffness: {r:?}");
    }
}

/// A one-axis scene made three-axis: every number of its script given on
/// each axis.
fn on_three_axes(mut scene: Scene) -> Scene {
    scene.axes = 3;
    for e in &mut scene.human.script {
        *e = e.along(|v| AxisValue::Each(vec![v.on(0); 3]));
    }
    scene
}

fn bits(samples: &[[f64; 2]]) -> Vec<[u64; 2]> {
    samples.iter().map(|s| s.map(f64::to_bits)).collect()
}

/// The N-axis engine has one code path: a one-axis scene run on each of
/// three independent axes moves every axis exactly as the one-axis run
/// moves its one, bit for bit, on both displays (the admittance display
/// through the load cell), and with every one-axis effect on every axis
/// (encoder, ADC, saturation, Coulomb friction, cogging, cable slack,
/// delay, hard stop).
#[test]
fn each_of_three_axes_runs_as_the_one_axis_scene() {
    let effects = [
        "effects.encoder={resolution_m=1e-6,bits=16}",
        "effects.saturation={limit_n=25.0}",
        "effects.coulomb={force_n=0.5,smoothing_mps=1e-3}",
        "effects.cogging={amplitude_n=0.2,period_m=0.002}",
        "effects.cable_slack={width_m=1e-5}",
        "effects.delay={ticks=1}",
        "effects.hard_stop={position_m=-0.02,solid=\"below\",stiffness_npm=2e5,damping_nspm=50.0}",
        "effects.load_cell=true",
        "effects.adc={lsb_n=0.01,noise_rms_n=0.0,seed=7}",
        "duration_s=2.0",
    ];
    for (file, sets) in [
        ("impedance_bilateral_maximum.toml", &[][..]),
        ("admittance_bilateral_maximum.toml", &[][..]),
        ("impedance_unilateral_maximum.toml", &effects[..]),
        ("admittance_unilateral_relaxed.toml", &effects[..]),
    ] {
        let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
        let scene = Scene::load(&Path::new("../scenes/table1").join(file), &sets).unwrap();
        let mut one = Vec::new();
        let r1 = Simulation::new(scene.clone())
            .unwrap()
            .run(|s| one.push([s.handle_m[0], s.actuator_n[0]]));
        let mut three = [Vec::new(), Vec::new(), Vec::new()];
        let r3 = Simulation::<3>::with_axes(on_three_axes(scene))
            .unwrap()
            .run(|s| {
                for (a, v) in three.iter_mut().enumerate() {
                    v.push([s.handle_m[a], s.actuator_n[a]]);
                }
            });
        assert!(r1.peak_force_n > 1.0, "{file}: the scene did something");
        assert_eq!(r1.stable, r3.stable, "{file}");
        assert_eq!(r3.effects.len(), r1.effects.len(), "{file}");
        for (a, v) in three.iter().enumerate() {
            assert!(
                bits(v) == bits(&one),
                "{file}: axis {a} differs from the one-axis run"
            );
        }
    }
}

/// The hand reaches over the cube and presses the cursor onto its knobs
/// (the device's zero is where the world's cursor starts, 10 mm above
/// the floor); the cube is carried 90 mm along -x and set down on the
/// floor there.
#[test]
fn a_block_is_picked_carried_and_set_down() {
    let scene = Scene::load(Path::new("../scenes/xyz/pick_block.toml"), &[]).unwrap();
    let mut sim = Simulation::<3>::with_axes(scene).unwrap();
    let mut pressed = None;
    let r = sim.run(|s| {
        if (s.t_s - 2.5).abs() < 1e-9 {
            pressed = Some(s.ve_m);
        }
    });
    let [x, _, z] = pressed.expect("a sample at 2.5 s");
    // On the cube's 30 mm top, on its 2 mm knobs, at the hand's x.
    assert!((x - 0.055).abs() < 1e-3, "cursor at x = {x} m");
    assert!((0.0315..0.0335).contains(&z), "cursor at z = {z} m");
    assert!(r.stable, "{r:?}");
    let b = r.blocks_m[0];
    assert!((b[0] + 0.05).abs() < 1e-4 && b[2] == 0.0, "{b:?}");
    // The held block's 0.98 N of weight was felt, and nothing near the
    // amplifier's limit.
    assert!(r.peak_force_n > 0.98 && r.peak_force_n < 50.0, "{r:?}");
}

/// Three blocks end in one column, each mated square on the one below.
#[test]
fn three_blocks_are_stacked_knob_on_knob() {
    let (r, _) = run("stack_three.toml", &[]);
    assert!(r.stable, "{r:?}");
    let base = r.blocks_m[0];
    for (i, b) in r.blocks_m.iter().enumerate() {
        // Square on the column: the same x and y to the nanometre.
        assert_eq!([b[0], b[1]], [base[0], base[1]], "block {i}");
        // Each on the top of the one below (a size of 30 mm as f32 is a
        // nanometre short).
        assert!((b[2] - 0.03 * i as f64).abs() < 3e-9, "block {i} at {b:?}");
    }
    assert!((base[0] + 0.045).abs() < 1e-8 && (base[1] - 0.025).abs() < 1e-8);
}

/// The 50-block world runs stably, and its one move stacks block 5 on
/// block 4; with the axes coupled by a tenth of each other's force it is
/// still stable.
#[test]
fn the_fifty_block_world_runs() {
    for sets in [&[][..], &["plant.cross_coupling=0.1"][..]] {
        let (r, _) = run("fifty_blocks.toml", sets);
        assert!(r.stable, "{sets:?}: {r:?}");
        assert_eq!(r.blocks_m.len(), 50);
        let (four, five) = (r.blocks_m[4], r.blocks_m[5]);
        assert_eq!([five[0], five[1]], [four[0], four[1]], "{sets:?}");
        assert!((five[2] - 0.02).abs() < 1e-9, "{sets:?}: {five:?}");
    }
}

/// A scene of another count, too many blocks, an unknown key or a bad
/// script event is refused with the file and what is wrong.
#[test]
fn bad_three_axis_scenes_are_refused_by_name() {
    let base = std::fs::read_to_string("../scenes/xyz/table1/impedance_free_relaxed.toml").unwrap();
    let block = "{ at_m = [0.0, 0.05, 0.0], size_m = [0.01, 0.01, 0.01], mass_kg = 0.1 },";
    let many = format!("kind = \"world\"\nblocks = [{}]", block.repeat(51));
    for (change, want) in [
        (base.replace("axes = 3", "axes = 4"), "axes = 4"),
        (
            base.replace("kind = \"world\"", &many),
            "51 blocks, the world holds 50",
        ),
        (
            base.replace("duration_s = 5.5", "duration_s = 5.5\nspeed = 2"),
            "unknown field `speed`",
        ),
        (
            base.replace("over_s = 0.8", "over_s = -1.0"),
            "human.script[0]: move needs",
        ),
        (
            base.replace("kind = \"world\"", "kind = \"world\"\ngrab_at_s = [-1.0]"),
            "ve.grab_at_s: -1 is not a time",
        ),
    ] {
        let e = Scene::parse(&change, "bad.toml", &[])
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("bad.toml: ") && e.contains(want), "{e}");
    }
}

/// The paper's explicit integration, an option: a 20 g cursor rings with
/// it where the passive default is stable, and a 0.1 kg one is stable
/// with both (one axis's lightest stable explicit cursor is 0.093 kg).
#[test]
fn the_explicit_world_needs_a_heavier_cursor() {
    for (explicit, mass, stable) in [
        ("false", "0.02", true),
        ("true", "0.02", false),
        ("true", "0.1", true),
    ] {
        let sets = [
            &format!("ve.explicit={explicit}")[..],
            &format!("ve.cursor_mass_kg={mass}")[..],
        ];
        let (r, _) = run("table1/impedance_free_maximum.toml", &sets);
        assert_eq!(r.stable, stable, "explicit {explicit}, {mass} kg: {r:?}");
    }
}

/// Each axis runs its own coupling, with the passivity layer built for it:
/// on an admittance display with a coupling mass per axis, each axis of the
/// three-axis run moves bit for bit as the one-axis run with that axis's
/// coupling. (The layer does not act in this stable scene, so its
/// per-axis cap is built here but not exercised.)
#[test]
fn each_axis_runs_its_own_coupling() {
    let masses = [5.0, 8.0, 12.0];
    let couplings = masses.map(|m| format!("{{kp=51000.0,bp=90.0,m={m},b=500.0}}"));
    let sets = |extra: Vec<String>| -> Vec<String> {
        [
            "passivity.enabled=true".to_string(),
            "duration_s=2.0".to_string(),
        ]
        .into_iter()
        .chain(extra)
        .collect()
    };
    let path = Path::new("../scenes/table1/admittance_bilateral_maximum.toml");
    let mut scene = on_three_axes(Scene::load(path, &sets(vec![])).unwrap());
    scene.coupling_per_axis = Some(
        couplings
            .iter()
            .map(|c| {
                Scene::load(path, &sets(vec![format!("coupling={c}")]))
                    .unwrap()
                    .coupling
            })
            .collect(),
    );
    let mut three = [Vec::new(), Vec::new(), Vec::new()];
    let r = Simulation::<3>::with_axes(scene).unwrap().run(|s| {
        for (a, v) in three.iter_mut().enumerate() {
            v.push([s.handle_m[a], s.actuator_n[a]]);
        }
    });
    assert!(r.passivity.is_some(), "{r:?}");
    for (a, c) in couplings.iter().enumerate() {
        let one_scene = Scene::load(path, &sets(vec![format!("coupling={c}")])).unwrap();
        let mut one = Vec::new();
        Simulation::new(one_scene)
            .unwrap()
            .run(|s| one.push([s.handle_m[0], s.actuator_n[0]]));
        assert!(
            bits(&three[a]) == bits(&one),
            "axis {a} (m = {})",
            masses[a]
        );
    }
}
