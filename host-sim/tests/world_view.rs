//! The three-axis scope as a person uses it (egui_kittest, no window): the
//! world view shows the blocks and the cursor, the grab button picks up
//! the block the cursor rests on and lets it go, and dragging the hand
//! moves the cursor and the block with it.
#![cfg(feature = "gui")]

use egui_kittest::kittest::Queryable;
use egui_kittest::Harness;
use host_sim::scope::world::WorldState;
use host_sim::Scene;
use std::path::Path;

/// The pick-block scene, run by its script to 2.4 s: the hand has pressed
/// the cursor onto the cube's knobs, and the script's grab is still to
/// come (it is taken out, so the button does it).
fn harness() -> Harness<'static, WorldState> {
    let mut scene = Scene::load(Path::new("../scenes/xyz/pick_block.toml"), &[]).unwrap();
    if let host_sim::engine::scene::VeSpec::World {
        grab_at_s,
        release_at_s,
        ..
    } = &mut scene.ve
    {
        grab_at_s.clear();
        release_at_s.clear();
    }
    // After the press, the hand stays where the script leaves it.
    scene.human.script.truncate(2);
    let mut state = WorldState::new(scene).unwrap();
    for _ in 0..24 {
        state.advance(0.1);
    }
    let mut h = Harness::new_ui_state(host_sim::scope::world_ui::world, state);
    h.set_size(eframe::egui::vec2(1280.0, 860.0));
    h.run();
    h
}

#[test]
fn the_grab_button_and_the_drag_move_the_block() {
    let mut h = harness();
    let _ = h.get_by_label_contains("cursor (");
    assert_eq!(h.state().held(), None);
    h.get_by_label("grab").click();
    h.run();
    assert_eq!(h.state().held(), Some(0), "the cursor rests on the cube");
    // Drag the hand 30 mm up and 20 mm along -x: the cube follows.
    let z0 = h.state().blocks()[0].min[2].nm();
    h.state_mut().drag([-0.02, 0.0, 0.03]);
    for _ in 0..15 {
        h.state_mut().advance(0.1);
    }
    h.run();
    let b = h.state().blocks()[0];
    assert!(b.min[2].nm() > z0 + 20_000_000, "lifted: {b:?}");
    assert!(
        b.min[0].nm() < 40_000_000 - 15_000_000,
        "carried along -x: {b:?}"
    );
    // Let go: it falls to the floor.
    h.get_by_label("let go of block 0").click();
    h.run();
    for _ in 0..10 {
        h.state_mut().advance(0.1);
    }
    assert_eq!(h.state().held(), None);
    assert_eq!(h.state().blocks()[0].min[2].nm(), 0);
    assert!(h.state().forces[2].len() > 3000, "the force history grows");
}
