//! The world view as a person uses it (egui_kittest, no window): the
//! world view shows the blocks and the cursor, the grab button picks up
//! the block the cursor rests on and lets it go, and dragging the hand
//! moves the cursor and the block with it.
#![cfg(feature = "gui")]

use egui_kittest::kittest::Queryable;
use egui_kittest::Harness;
use host_sim::scope::board::WithBoard;
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

/// Board mode on three axes: the three-axis image, in-process (the bytes
/// the firmware gets over its serial link), drives the world scene's plant
/// in lockstep. Refused until calibrated, then calibrated where the
/// world's cursor starts and armed, it pushes on every axis as the hand
/// presses the cube and the floor; the view plots its telemetry on every
/// axis and shows its state.
#[test]
fn board_mode_drives_a_three_axis_board_and_plots_every_axis() {
    use host_sim::link::LocalBoard;
    use twoport_link::{BoardMode, Message};
    let scene = Scene::load(Path::new("../scenes/xyz/pil_blocks.toml"), &[]).unwrap();
    let mut s = WorldState::<3>::new(scene).unwrap();
    let board = LocalBoard::excalibur_xyz().unwrap();
    s.connect_port(Box::new(board), "in-process", true);
    assert!(s.board.is_some(), "{:?}", s.message);
    s.tell_board(Message::Arm);
    s.advance(0.01);
    let b = s.board.as_ref().unwrap();
    assert_eq!(b.refusal.as_deref(), Some("Arm refused: NotCalibrated"));
    let at_rest = s.at_rest_pm().unwrap();
    s.tell_board(Message::Calibrate {
        position_pm: at_rest,
    });
    s.tell_board(Message::Arm);
    for _ in 0..50 {
        s.advance(0.1);
    }
    assert_eq!(s.message, None);
    let b = s.board.as_ref().unwrap();
    assert_eq!(b.status.map(|st| st.mode), Some(BoardMode::Armed));
    assert_eq!(b.telemetry.expect("telemetry").axes.len(), 3);
    let peak = |r: &host_sim::scope::rings::Ring| r.iter().map(|p| p.1.abs()).fold(0.0, f64::max);
    for a in 0..3 {
        assert!(
            peak(&s.board_forces[a]) > 2.0,
            "axis {a}: the board's force"
        );
        assert!(peak(&s.forces[a]) > 2.0, "axis {a}: the plant's force");
    }
    let mut h = Harness::new_ui_state(host_sim::scope::world_ui::world, s);
    h.set_size(eframe::egui::vec2(1280.0, 860.0));
    h.run();
    let _ = h.get_by_label_contains("board: in-process (lockstep)");
    let _ = h.get_by_label_contains("Armed, calibrated");
    h.get_by_label("disconnect").click();
    h.run();
    assert!(h.state().board.is_none());
}

/// A two-axis linkage scene opens in the world view (its x-y plane): the
/// pantograph's arm is drawn, both its legs ending at the handle, and a
/// drag moves the handle.
#[test]
fn a_two_axis_linkage_scene_shows_its_arm() {
    let path = Path::new("../scenes/linkages/haply_wall.toml");
    let file = Path::new("../models/linkages/haply_2diy.toml");
    let sets = [format!("plant.linkage=\"{}\"", file.display())];
    let scene = Scene::load(path, &sets).unwrap();
    let mut state = WorldState::<2>::new(scene).unwrap();
    for _ in 0..10 {
        state.advance(0.1);
    }
    let arm = state.arm().unwrap();
    assert_eq!(arm.len(), 2, "two legs");
    assert_eq!(arm[0].last(), arm[1].last(), "the legs meet at the handle");
    let before = state.last.unwrap().handle_m;
    let mut h = Harness::new_ui_state(host_sim::scope::world_ui::world, state);
    h.set_size(eframe::egui::vec2(1280.0, 860.0));
    h.run();
    let _ = h.get_by_label_contains("top: x right, y up");
    // (The script presses 30 mm past the wall: 45 mm back takes it off.)
    h.state_mut().drag([0.045, 0.0, 0.0]);
    for _ in 0..10 {
        h.state_mut().advance(0.1);
    }
    let after = h.state().last.unwrap().handle_m;
    assert!(
        (after[0] - before[0]).abs() > 1e-3,
        "{before:?} -> {after:?}"
    );
}
