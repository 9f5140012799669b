//! The three-axis engine on the shipped scenes: Table I's states in 3-D
//! run stably at the proven coupling and 4x past it does not; a block is
//! picked and set down, three are stacked knob on knob, and the 50-block
//! world runs; bad scene files are refused by name.

use host_sim::engine::xyz::{XyzReport, XyzScene, XyzSimulation};
use std::path::Path;
use twoport_control::world::World;

fn run(file: &str, sets: &[&str]) -> (XyzReport, XyzSimulation) {
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    let scene = XyzScene::load(&Path::new("../scenes/xyz").join(file), &sets).unwrap();
    let mut sim = XyzSimulation::new(scene).unwrap();
    let r = sim.run(|_| {});
    (r, sim)
}

/// Each of the nine Table I cases in 3-D is stable at the x axis's proven
/// coupling on every axis; at 4x its stiffness the bilateral case is not.
#[test]
fn table1_in_3d_is_stable_at_the_proven_gains() {
    for state in ["free", "unilateral", "bilateral"] {
        for grasp in ["hands_off", "relaxed", "maximum"] {
            let (r, sim) = run(&format!("table1/{state}_{grasp}.toml"), &[]);
            assert!(r.stable, "{state} {grasp}: {r:?}");
            assert!(
                r.peak_force_n > 1.0,
                "{state} {grasp}: the scene did something"
            );
            if state == "unilateral" && grasp != "hands_off" {
                // The hand reached 20 mm down: the cursor rests on the floor.
                let z = sim.servo().world().positions()[2].nm();
                assert_eq!(z, 1_000_000, "{grasp}: the cursor on the floor");
            }
        }
    }
    let (r, _) = run("table1/bilateral_maximum.toml", &["coupling.k=204000"]);
    assert!(!r.stable, "4x the proven stiffness: {r:?}");
}

/// The cube is carried 90 mm along -x and set down on the floor there.
#[test]
fn a_block_is_picked_carried_and_set_down() {
    let (r, _) = run("pick_block.toml", &[]);
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
    let base = std::fs::read_to_string("../scenes/xyz/table1/free_relaxed.toml").unwrap();
    let block = "{ at_m = [0.0, 0.05, 0.0], size_m = [0.01, 0.01, 0.01], mass_kg = 0.1 },";
    let many = format!("kind = \"blocks\"\nblocks = [{}]", block.repeat(51));
    for (change, want) in [
        (base.replace("axes = 3", "axes = 2"), "axes = 2"),
        (
            base.replace("kind = \"blocks\"", &many),
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
            base.replace("kind = \"blocks\"", "kind = \"blocks\"\ngrab_at_s = [-1.0]"),
            "ve.grab_at_s: -1 is not a time",
        ),
    ] {
        let e = XyzScene::parse(&change, "bad.toml", &[])
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
        let (r, _) = run("table1/free_maximum.toml", &sets);
        assert_eq!(r.stable, stable, "explicit {explicit}, {mass} kg: {r:?}");
    }
}
