//! Processor-in-the-loop against the board loop in-process (CI runs the same
//! check against the firmware in QEMU through `cargo xtask pil --check`).

use host_sim::pil::{self, Faults, LocalBoard};
use host_sim::{Scene, Simulation};
use std::path::Path;

fn scene() -> Scene {
    Scene::load(Path::new("../scenes/stiff_wall.toml"), &[]).unwrap()
}

#[test]
fn corrupted_frames_are_dropped_and_the_loop_goes_on() {
    let clean = pil::run(
        scene(),
        3000,
        LocalBoard::excalibur().unwrap(),
        Faults::default(),
    )
    .unwrap();
    let faults = Faults {
        corrupt_every: 7,
        link_loss_at: None,
    };
    let noisy = pil::run(scene(), 3000, LocalBoard::excalibur().unwrap(), faults).unwrap();
    assert!(noisy.corrupted_sent > 800);
    assert_eq!(
        u64::from(noisy.board_stats.rx.dropped()),
        noisy.corrupted_sent
    );
    // Nothing the garbage did reached the force.
    let c = pil::compare(&noisy, &clean);
    assert_eq!(c.ticks, 3000);
    assert_eq!(c.duty_mismatches, 0);
    assert_eq!(c.max_position_error_m, 0.0);
    assert!(
        clean.duties.iter().any(|d| d.unsigned_abs() > 1000),
        "the wall pushes"
    );
}

#[test]
fn link_loss_gives_zero_force_within_the_watchdog_deadline() {
    let deadline = u64::from(twoport_board::excalibur::HEARTBEAT_TIMEOUT_TICKS);
    // In the wall (the hand holds it there from 2 s to 6 s).
    for t0 in [3000, 3005, 3999] {
        let faults = Faults {
            corrupt_every: 0,
            link_loss_at: Some(t0),
        };
        let r = pil::run(scene(), 4500, LocalBoard::excalibur().unwrap(), faults).unwrap();
        assert!(r.duties[t0 as usize - 1] != 0, "force before the loss");
        let z = r.zero_after_loss_ticks.unwrap();
        assert!(z <= deadline, "zero after {z} ticks, deadline {deadline}");
        assert!(r.duties[(t0 + deadline) as usize..].iter().all(|d| *d == 0));
    }
}

#[test]
fn the_board_loop_matches_the_scenes_own_servo_within_pwm_resolution() {
    // The scene's servo is the same law with the same gains, but its force
    // goes to the plant unquantised and it has no enable ramp or link;
    // the board's goes through the 16-bit duty (6.1 mN steps) after a 100 ms
    // ramp-in. Away from the start the trajectories agree closely.
    let r = pil::run(
        scene(),
        6000,
        LocalBoard::excalibur().unwrap(),
        Faults::default(),
    )
    .unwrap();
    let mut sim = Simulation::new(scene()).unwrap();
    let mut worst = 0.0f64;
    for s in &r.samples {
        let l = sim.step();
        if s.t_s > 0.5 {
            worst = worst.max((s.handle_m - l.handle_m).abs());
        }
    }
    assert!(worst < 2e-5, "{worst} m apart");
}

#[test]
fn a_scene_with_another_encoder_is_refused_by_name() {
    let s = Scene::load(
        Path::new("../scenes/stiff_wall.toml"),
        &["effects.encoder.bits=32".to_string()],
    )
    .unwrap();
    let e = pil::run(s, 10, LocalBoard::excalibur().unwrap(), Faults::default())
        .err()
        .unwrap();
    assert!(e.contains("effects.encoder"), "{e}");
}
