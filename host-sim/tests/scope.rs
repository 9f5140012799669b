//! The scope as a person uses it: its controls drive the running simulation
//! (egui_kittest, no window needed), and its memory stays bounded.
#![cfg(feature = "gui")]

use eframe::egui::accesskit::Role;
use egui_kittest::kittest::Queryable;
use egui_kittest::Harness;
use host_sim::scope::app::{ScopeState, Speed, RING_SAMPLES};
use host_sim::scope::board::BoardChoice;
use host_sim::scope::board::WithBoard;
use host_sim::scope::signals::{BoardSignal, Signal};
use std::path::Path;
use twoport_control::servo::{Gains, ImpedanceGains};
use twoport_link::{Axes, BoardMode, Message};

fn harness() -> Harness<'static, (ScopeState, BoardChoice)> {
    harness_on("../scenes/stiff_wall.toml")
}

fn harness_on(scene: &str) -> Harness<'static, (ScopeState, BoardChoice)> {
    let state = ScopeState::open(Path::new(scene)).unwrap();
    let mut h = Harness::new_ui_state(
        |ui, s: &mut (ScopeState, BoardChoice)| {
            let (state, link) = s;
            host_sim::scope::ui::scope(ui, state, link)
        },
        (state, BoardChoice::default()),
    );
    h.set_size(eframe::egui::vec2(1280.0, 860.0));
    h.run();
    h
}

fn imp(k_npm: f32, b_nspm: f32) -> Gains {
    ImpedanceGains { k_npm, b_nspm }.into()
}

#[test]
fn the_stiffness_slider_changes_the_running_simulations_gain() {
    let mut h = harness();
    assert_eq!(h.state().0.running_gains(), imp(43_500.0, 90.0));
    h.get_by_role_and_label(Role::Slider, "k_c (N/m)")
        .set_value_accesskit(30_000.0);
    h.run();
    assert_eq!(h.state().0.running_gains(), imp(30_000.0, 90.0));
    assert_eq!(h.state().0.gains, imp(30_000.0, 90.0));
}

#[test]
fn the_light_turns_red_past_the_bound() {
    let mut h = harness();
    assert!(h
        .query_by_label_contains("proven absolutely stable")
        .is_some());
    // The designer's bound at b = 90 N s/m is 51,074 N/m.
    h.get_by_role_and_label(Role::Slider, "k_c (N/m)")
        .set_value_accesskit(60_000.0);
    h.run();
    assert!(h
        .query_by_label_contains("proven absolutely stable")
        .is_none());
    let _red = h.get_by_label_contains("NOT proven stable: worst at");
    let light = h.state().0.light.as_ref().unwrap();
    assert!(!light.proven);
    assert!(
        light.margin < 0.0 && light.worst_hz > 1.0,
        "{} at {} Hz",
        light.margin,
        light.worst_hz
    );
    // The margin to the boundary at this damping, read beside the light.
    let past = light.gain_margin.unwrap();
    assert!((past + (60_000.0 / 51_073.4 - 1.0)).abs() < 1e-3, "{past}");
    let _ = h.get_by_label_contains("past the boundary at this damping, 51073 N/m");
    // And back inside it turns green again, with its margin.
    h.get_by_role_and_label(Role::Slider, "k_c (N/m)")
        .set_value_accesskit(50_000.0);
    h.run();
    let light = h.state().0.light.as_ref().unwrap();
    assert!(light.proven);
    let inside = light.gain_margin.unwrap();
    assert!(
        (inside - (1.0 - 50_000.0 / 51_073.4)).abs() < 1e-3,
        "{inside}"
    );
    let _ = h.get_by_label_contains("gain margin 2.1%: the boundary at this damping is 51073 N/m");
}

#[test]
fn the_grasp_buttons_and_the_wall_act_on_the_simulation() {
    let mut h = harness();
    h.get_by_label("hands off").click();
    h.run();
    assert_eq!(
        h.state().0.grasp,
        Some(host_sim::engine::human::GraspKind::HandsOff)
    );
    h.get_by_role_and_label(Role::Slider, "surface (m)")
        .set_value_accesskit(0.02);
    h.run();
    assert_eq!(h.state().0.wall.map(|w| w.0), Some(0.02));
}

#[test]
fn pause_and_step_advance_one_tick() {
    let mut h = harness();
    h.get_by_label("pause").click();
    h.run();
    let t = h.state().0.time_s();
    h.get_by_label("step").click();
    h.run();
    assert!((h.state().0.time_s() - t - 1e-3).abs() < 1e-9);
}

#[test]
fn the_scope_memory_is_bounded() {
    // Without a passivity layer its two signals stay empty; with one,
    // every ring fills to its bound and no further.
    for (scene, layer) in [
        ("../scenes/stiff_wall.toml", false),
        ("../scenes/passivity/stiff_wall_4x.toml", true),
    ] {
        let mut s = ScopeState::open(Path::new(scene)).unwrap();
        assert_eq!(s.has_layer(), layer);
        s.speed = Speed::Fastest;
        for _ in 0..3 * RING_SAMPLES {
            assert!(s.tick());
        }
        for sig in Signal::ALL {
            let of_layer = matches!(sig, Signal::LayerEnergy | Signal::LayerAdded);
            let want = if of_layer && !layer { 0 } else { RING_SAMPLES };
            assert_eq!(s.ring(sig).len(), want, "{scene}: {sig:?}");
            assert_eq!(s.ring(sig).capacity(), RING_SAMPLES);
        }
    }
}

/// An hour at 1 kHz: the buffers hold their bound (release, CI).
#[test]
#[ignore = "3.6e6 ticks; CI runs it in release"]
fn an_hour_of_running_does_not_grow_the_buffers() {
    let mut s = ScopeState::open(Path::new("../scenes/stiff_wall.toml")).unwrap();
    let ticks = 3_600_000u64;
    let mut done = 0;
    while done < ticks {
        // The scene ends at 10 s: start it again as a person would.
        if !s.tick() {
            s.reset();
        }
        done += 1;
        if done % 600_000 == 0 {
            for sig in Signal::ALL {
                assert!(s.ring(sig).len() <= RING_SAMPLES);
            }
        }
    }
}

/// Board mode against the firmware in QEMU: `cargo xtask scope-board`
/// starts QEMU and passes its pty in `TWOPORT_PTY`.
#[test]
#[ignore = "needs the firmware in QEMU; run by `cargo xtask scope-board`"]
fn board_mode_shows_telemetry_and_the_boards_gain_answers() {
    let pty = std::env::var("TWOPORT_PTY").expect("TWOPORT_PTY names the board's pty");
    let mut s = ScopeState::open(Path::new("../scenes/stiff_wall.toml")).unwrap();
    s.connect(&pty, true);
    assert!(s.board.is_some(), "{:?}", s.message);
    // It boots disarmed and uncalibrated, and says why it will not arm.
    s.tell_board(Message::Arm);
    for _ in 0..5 {
        assert!(s.tick(), "{:?}", s.message);
    }
    let b = s.board.as_ref().unwrap();
    assert_eq!(b.status.map(|st| st.mode), Some(BoardMode::Disarmed));
    assert_eq!(b.refusal.as_deref(), Some("Arm refused: NotCalibrated"));
    // Calibrated where it stands (at rest at 0), it arms.
    s.tell_board(Message::Calibrate {
        position_pm: Axes::one(0),
    });
    s.tell_board(Message::Arm);
    for _ in 5..2000 {
        assert!(s.tick(), "{:?}", s.message);
    }
    let b = s.board.as_ref().unwrap();
    let st = b.status.expect("the board's status");
    assert_eq!(
        (st.mode, st.calibrated, st.faults),
        (BoardMode::Armed, true, 0)
    );
    let t = b.telemetry.expect("telemetry from the board");
    assert!(t.tick >= 1900, "tick {}", t.tick);
    assert!(s.board_ring(BoardSignal::Actuator).len() >= 150);
    // The loop's timing is plotted: the law and safety layer take a few
    // hundred of the emulated Cortex-M4F's instructions.
    assert!(s.board_ring(BoardSignal::LawCycles).len() >= 150);
    assert!(
        (100..5000).contains(&t.stage_cycles[1]),
        "{:?}",
        t.stage_cycles
    );
    // The hand, led to 30 mm, is held at the board's wall at 10 mm.
    let x_board = t.axes[0].position_pm as f64 * 1e-12;
    assert!(
        (0.0095..0.0106).contains(&x_board),
        "the hand has pushed into the wall: {x_board} m"
    );
    // Inside the proven region: accepted; outside: refused with the reason.
    s.set_gains(imp(40_000.0, 90.0));
    for _ in 0..5 {
        s.tick();
    }
    assert_eq!(s.board.as_ref().unwrap().reply.as_deref(), Some("accepted"));
    s.set_gains(imp(60_000.0, 90.0));
    for _ in 0..5 {
        s.tick();
    }
    let r = s.board.as_ref().unwrap().reply.clone().unwrap();
    assert!(r.starts_with("refused on axis 0: NotProvenStable"), "{r}");
    s.disconnect();
    // Free running (a board on its own sensors): the scope only feeds the
    // watchdog and talks; the gain answers still come back.
    s.connect(&pty, false);
    assert!(
        s.board.as_ref().is_some_and(|b| !b.lockstep),
        "{:?}",
        s.message
    );
    s.set_gains(imp(45_000.0, 90.0));
    // The answer comes when QEMU gets to it: wait in wall time (10 s at
    // most), not in a count of frames, which a loaded machine outruns.
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(10);
    while std::time::Instant::now() < deadline {
        s.advance(0.001);
        if s.board.as_ref().unwrap().reply.is_some() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(1));
    }
    assert_eq!(s.board.as_ref().unwrap().reply.as_deref(), Some("accepted"));
    s.disconnect();
}

#[test]
fn the_scene_picker_lists_the_scenes_and_the_table_i_folder() {
    let s = ScopeState::open(Path::new("../scenes/stiff_wall.toml")).unwrap();
    let names: Vec<String> = s
        .scenes
        .iter()
        .map(|p| {
            p.strip_prefix(&s.scenes_root)
                .unwrap()
                .display()
                .to_string()
        })
        .collect();
    assert!(names.contains(&"stiff_wall.toml".to_string()), "{names:?}");
    assert!(names.contains(&"vbb_blocks.toml".to_string()), "{names:?}");
    assert_eq!(
        names.iter().filter(|n| n.starts_with("table1/")).count(),
        18
    );
}

/// The time axes start at the run's start, not at minus the window.
#[test]
fn the_time_axes_start_at_the_runs_start() {
    let mut h = harness();
    let (t0, t1) = h.state().0.view();
    assert_eq!(t0, 0.0);
    assert_eq!(t1, h.state().0.window_s);
    // Once the run is longer than the window, the window scrolls.
    let ticks = (1.5 * h.state().0.window_s / 1e-3) as usize;
    for _ in 0..ticks {
        h.state_mut().0.tick();
    }
    let (t0, t1) = h.state().0.view();
    assert!(
        t0 > 0.0 && (t1 - h.state().0.time_s()).abs() < 1e-9,
        "{t0} {t1}"
    );
}

/// The live design plot is log-log like the paper's figures: its curves
/// are drawn in decades, and at the worst frequency the gap between the
/// coupling and the bound is the margin the light reports, in decades a
/// person can see (the linear axis it replaced drew both flat on zero).
#[test]
fn the_design_plot_shows_the_margin_in_decades() {
    let h = harness();
    let light = h.state().0.light.as_ref().unwrap();
    let fig = light.figure.as_ref().unwrap();
    let drawn: Vec<Vec<[f64; 2]>> = fig
        .curves
        .iter()
        .map(|c| host_sim::scope::ui::log_log(&c.points))
        .collect();
    let decades = |c: &[[f64; 2]]| {
        let (lo, hi) = c
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| {
                (l.min(p[1]), h.max(p[1]))
            });
        hi - lo
    };
    // The bound with the human model (drawn thin) and the coupling (bold).
    let (bound, coupling) = (&drawn[drawn.len() - 2], &drawn[drawn.len() - 1]);
    assert!(decades(bound) > 3.0 && decades(coupling) > 1.0);
    // Every drawn value is a finite decade, and none was made up for a
    // non-positive bound.
    for c in &drawn {
        assert!(c.iter().all(|p| p[0].is_finite() && p[1].is_finite()));
    }
    let at = |c: &[[f64; 2]], f: f64| {
        c.iter()
            .min_by(|a, b| {
                (a[0] - f.log10())
                    .abs()
                    .total_cmp(&(b[0] - f.log10()).abs())
            })
            .unwrap()[1]
    };
    let gap = at(coupling, light.worst_hz) - at(bound, light.worst_hz);
    assert!(
        light.proven && gap >= -1e-6,
        "gap {gap} decades at {} Hz",
        light.worst_hz
    );
}

/// The live design plot draws only what a log axis can show: the human
/// bound of the default scene is not positive over a band of frequencies
/// (any coupling meets it there), so it is drawn as separate runs that
/// stop at that band, no value is drawn below the frame, and the legend
/// names the band.
#[test]
fn the_design_plot_draws_only_what_a_log_axis_can_show() {
    use host_sim::scope::ui::LogCurve;
    // A synthetic bound: positive, dipping through zero, positive again.
    let pts: Vec<(f64, f64)> = (1..=100)
        .map(|i| {
            let f = i as f64;
            (f, (f - 50.0).abs() - 10.0 + 1e-30)
        })
        .collect();
    let c = LogCurve::new(&pts, -3.0);
    assert_eq!(c.runs.len(), 2, "{:?}", c.not_positive);
    assert_eq!(c.not_positive, [(41.0, 59.0)]);
    assert!(c.points().all(|p| p[1] >= -3.0 && p[1].is_finite()));
    assert_eq!(c.legend("bound"), "bound\n≤ 0 (not drawn) at 41-59 Hz");

    let h = harness();
    let light = h.state().0.light.as_ref().unwrap();
    let fig = light.figure.as_ref().unwrap();
    let bound = &fig.curves[fig.curves.len() - 2];
    let c = LogCurve::new(&bound.points, -8.0);
    assert!(!c.not_positive.is_empty(), "{}", bound.label);
    for (a, b) in &c.not_positive {
        assert!(*a <= *b && *b < 1000.0, "{a} to {b} Hz");
    }
    // The band the filled wedge used to cover, between about 30 and 60 Hz.
    assert!(
        c.not_positive.iter().any(|(a, b)| *a < 40.0 && *b > 60.0),
        "{:?}",
        c.not_positive
    );
    assert!(c.runs.len() >= 2);
    assert!(c
        .legend(&bound.label)
        .contains("≤ 0 (not drawn) at 0.05-11.7, 34.7-80.5 Hz"));
}

/// A scene with an identification experiment offers it: the button plays
/// it (the board's loop in-process) and fits the record, and the panel
/// shows the fit's line and its figures; a scene without one says so.
#[test]
#[cfg_attr(debug_assertions, ignore = "release only (CI runs it)")]
fn the_identification_panel_plays_the_experiment_and_shows_the_fit() {
    let mut h = harness_on("../scenes/identify/excalibur.toml");
    assert!(h.state().0.identification.is_none());
    h.get_by_label("Play the experiment and fit").click();
    h.run();
    let id = match &h.state().0.identification {
        Some(Ok(id)) => id,
        other => panic!(
            "{:?}",
            other.as_ref().map(|r| r.as_ref().map(|i| &i.summary))
        ),
    };
    assert!(id.summary.starts_with("3 modes"), "{}", id.summary);
    assert!(id.summary.contains("cogging"), "{}", id.summary);
    let names: Vec<&str> = id.figures.iter().map(|f| f.0).collect();
    assert_eq!(names, ["encoder", "load_cell", "coherence"]);
    let _shown = h.get_by_label_contains("3 modes (modes, the handle on its load cell)");
    let _plot = h.get_by_label_contains("Actuator force to encoder");

    let mut plain = ScopeState::open(Path::new("../scenes/stiff_wall.toml")).unwrap();
    plain.identify();
    let e = plain.identification.unwrap().err().unwrap();
    assert!(e.contains("no [identify] section"), "{e}");
}
