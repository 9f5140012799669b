//! Processor-in-the-loop on three axes, against the three-axis image's loop
//! in-process (CI runs the same check against the firmware in QEMU on both
//! boards through `cargo xtask pil scenes/xyz/pil_blocks.toml --check`).

use host_sim::link::{self, LinkFaults, LocalBoard};
use host_sim::pil;
use host_sim::{Scene, Simulation};
use std::path::Path;

const SCENE: &str = "../scenes/xyz/pil_blocks.toml";

fn scene(sets: &[&str]) -> Scene {
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    Scene::load(Path::new(SCENE), &sets).unwrap()
}

/// The board's loop drives the plant as the scene's own servo does: the
/// same world (the image's blocks) and coupling, so the handle follows
/// the same path within what the board's 1 µm encoder and f32 duty add.
/// With corrupted frames on the link and the heartbeats stopping at 5 s,
/// every axis is at zero force within the watchdog's deadline.
#[test]
fn three_axes_run_in_lockstep_and_all_stop_after_a_link_loss() {
    let faults = LinkFaults {
        corrupt_every: 50,
        link_loss_at: Some(5000),
    };
    let board = LocalBoard::excalibur_xyz().unwrap();
    let r = pil::run_axes::<_, 3>(scene(&[]), 6000, board, faults).unwrap();
    let c = pil::compare(&r, &r);
    assert!(pil::failures(&r, &c, 6000, faults, 50).is_empty());
    assert_eq!(u64::from(r.board_stats.rx.dropped()), r.corrupted_sent);
    assert!(r.telemetry.iter().all(|t| t.axes.len() == 3));
    // The hand presses the cube's top, slides across it, pushes the
    // brick's side and presses the floor: every axis pushes at some time.
    for a in 0..3 {
        let peak = r.samples[..5000]
            .iter()
            .map(|s| s.actuator_n[a].abs())
            .fold(0.0, f64::max);
        assert!(peak > 2.0, "axis {a}: {peak} N at most");
    }
    assert!(r.duties[5050..].iter().all(|d| d.iter().all(|d| *d == 0)));

    let mut own = Simulation::<3>::with_axes(scene(&[])).unwrap();
    let mut worst = [0.0f64; 3];
    for s in &r.samples[..5000] {
        let o = own.step();
        for (a, w) in worst.iter_mut().enumerate() {
            *w = w.max((o.handle_m[a] - s.handle_m[a]).abs());
        }
    }
    assert!(worst.iter().all(|w| *w < 50e-6), "{worst:?} m apart");
}

#[test]
fn a_host_of_another_axis_count_is_refused_by_the_board() {
    let board = LocalBoard::excalibur_xyz().unwrap();
    let e = link::Session::open(board, LinkFaults::default())
        .err()
        .expect("a one-axis host");
    assert!(matches!(e, link::LinkError::Handshake(_)), "{e:?}");
    let e = e.to_string();
    assert!(e.contains('3') && e.contains('1'), "{e}");
}

/// The board runs its own world: a scene whose blocks are not the image's,
/// or that grabs (which no link message carries), is refused by name.
#[test]
fn a_scene_the_image_cannot_match_is_refused() {
    let board = || LocalBoard::excalibur_xyz().unwrap();
    let text = std::fs::read_to_string(SCENE).unwrap();
    let heavier = text.replacen("mass_kg = 0.1 }", "mass_kg = 0.2 }", 1);
    let moved = Scene::parse(&heavier, SCENE, &[]).unwrap();
    let e = pil::run_axes::<_, 3>(moved, 10, board(), LinkFaults::default()).unwrap_err();
    assert!(matches!(e, host_sim::Error::Pil(_)), "{e:?}");
    assert!(e.to_string().contains("BLOCKS"), "{e}");
    let grabs = scene(&["ve.grab_at_s=[1.0]"]);
    let e = pil::run_axes::<_, 3>(grabs, 10, board(), LinkFaults::default()).unwrap_err();
    assert!(e.to_string().contains("grab_at_s"), "{e}");
}
