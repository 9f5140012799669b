//! Processor-in-the-loop against the board loop in-process (CI runs the same
//! check against the firmware in QEMU through `cargo xtask pil --check`).

use host_sim::link::{self, LinkFaults, LocalBoard};
use host_sim::pil::{self, Lockstep};
use host_sim::{Scene, Simulation};
use std::path::Path;
use twoport_link::Axes;

fn scene() -> Scene {
    Scene::load(Path::new("../scenes/stiff_wall.toml"), &[]).unwrap()
}

/// `ticks` of the stiff wall with the in-process Excalibur board.
fn run(ticks: u64, faults: LinkFaults) -> pil::Run {
    pil::run(scene(), ticks, LocalBoard::excalibur().unwrap(), faults).unwrap()
}

#[test]
fn corrupted_frames_are_dropped_and_the_loop_goes_on() {
    let clean = run(3000, LinkFaults::default());
    let faults = LinkFaults {
        corrupt_every: 7,
        link_loss_at: None,
    };
    let noisy = run(3000, faults);
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
        clean.duties.iter().any(|d| d[0].unsigned_abs() > 1000),
        "the wall pushes"
    );
}

#[test]
fn link_loss_gives_zero_force_within_the_watchdog_deadline() {
    let deadline = u64::from(twoport_board::excalibur::HEARTBEAT_TIMEOUT_TICKS);
    // In the wall (the hand holds it there from 2 s to 6 s).
    for t0 in [3000, 3005, 3999] {
        let faults = LinkFaults {
            corrupt_every: 0,
            link_loss_at: Some(t0),
        };
        let r = run(4500, faults);
        assert!(r.duties[t0 as usize - 1][0] != 0, "force before the loss");
        let z = r.zero_after_loss_ticks.unwrap();
        assert!(z <= deadline, "zero after {z} ticks, deadline {deadline}");
        assert!(r.duties[(t0 + deadline) as usize..]
            .iter()
            .all(|d| d[0] == 0));
    }
}

#[test]
fn the_board_loop_matches_the_scenes_own_servo_within_pwm_resolution() {
    // The scene's servo is the same law with the same gains, but its force
    // goes to the plant unquantised and it has no enable ramp or link;
    // the board's goes through the 16-bit duty (6.1 mN steps) after a 100 ms
    // ramp-in. Away from the start the trajectories agree closely.
    let r = run(6000, LinkFaults::default());
    let mut sim = Simulation::new(scene()).unwrap();
    let mut worst = 0.0f64;
    for s in &r.samples {
        let l = sim.step();
        if s.t_s > 0.5 {
            worst = worst.max((s.handle_m[0] - l.handle_m[0]).abs());
        }
    }
    assert!(worst < 2e-5, "{worst} m apart");
}

/// Why a PIL run of the stiff-wall scene with `set` refuses to start.
fn refusal(set: &str) -> host_sim::Error {
    let s = Scene::load(Path::new("../scenes/stiff_wall.toml"), &[set.to_string()]).unwrap();
    pil::run(
        s,
        10,
        LocalBoard::excalibur().unwrap(),
        LinkFaults::default(),
    )
    .err()
    .unwrap()
}

#[test]
fn a_scene_with_another_encoder_is_refused_by_name() {
    let e = refusal("effects.encoder.bits=32");
    assert!(matches!(e, host_sim::Error::Pil(_)), "{e:?}");
    assert!(e.to_string().contains("effects.encoder"), "{e}");
}

/// The homing scene: the board refuses nothing, homes onto the hard stop
/// with at most 5 N, lands within the stop's give of the plant's position,
/// arms, and then holds the wall at its surface against the hand.
#[test]
fn a_board_homes_onto_the_hard_stop_then_arms_and_holds_the_wall() {
    let s = Scene::load(Path::new("../scenes/homing.toml"), &[]).unwrap();
    let r = pil::run(
        s,
        4500,
        LocalBoard::excalibur().unwrap(),
        LinkFaults::default(),
    )
    .unwrap();
    assert_eq!(r.start, Some(pil::Start::Home));
    let (n, err_m) = r.homing.expect("homed");
    // 20 mm at 20 mm/s, the stall and the ramp-in.
    assert!((1000..2000).contains(&n), "{n} ticks");
    assert!(err_m.abs() < pil::HOMING_TOLERANCE_M, "{err_m} m");
    assert!(r.armed_at_tick > n);
    let c = pil::compare(&r, &r);
    assert!(pil::failures(&r, &c, 4500, LinkFaults::default(), 50).is_empty());
    // Before arming nothing pushes harder than the homing limit; after the
    // hand has pushed the handle into the wall, the wall pushes back hard.
    let io = twoport_board::IoScale::EXCALIBUR;
    let peak_before = r.duties[..r.armed_at_tick as usize]
        .iter()
        .map(|d| io.force_n(d[0]).abs())
        .fold(0.0, f32::max);
    assert!(peak_before <= 5.01, "{peak_before} N");
    let peak_after = r.duties[r.armed_at_tick as usize..]
        .iter()
        .map(|d| io.force_n(d[0]).abs())
        .fold(0.0, f32::max);
    assert!(peak_after > 10.0, "{peak_after} N");
    // The hand, led 10 mm past the wall, is held at its surface (the
    // board's frame is the plant's to within the homing tolerance).
    let x = r.samples.last().unwrap().handle_m[0];
    assert!((0.0095..0.0106).contains(&x), "handle at {x} m");
}

/// Without homing or a calibration, a board refuses to arm; the run says
/// so by name instead of running a board that does nothing.
#[test]
fn an_uncalibrated_board_refuses_to_arm_by_name() {
    let mut session =
        link::Session::open(LocalBoard::excalibur().unwrap(), LinkFaults::default()).unwrap();
    let mut sim = Simulation::new(scene()).unwrap();
    session.step(&mut sim).unwrap();
    let e = session.arm().unwrap_err();
    assert!(
        matches!(
            e,
            link::LinkError::Refused {
                why: twoport_link::ModeRefusal::NotCalibrated,
                ..
            }
        ),
        "{e}"
    );
    session.calibrate(Axes::one(0)).unwrap();
    assert_eq!(session.arm().unwrap().mode, twoport_link::BoardMode::Armed);
}

/// An in-process board that reboots (a fresh image, as after a watchdog
/// reset) once `after` frames have been sent to it.
struct Rebooting {
    board: LocalBoard,
    sent: u32,
    after: u32,
}

impl link::BoardPort for Rebooting {
    fn send(&mut self, bytes: &[u8]) -> Result<(), link::LinkError> {
        self.sent += 1;
        if self.sent == self.after {
            self.board = LocalBoard::excalibur()?;
        }
        self.board.send(bytes)
    }
    fn recv(&mut self, buf: &mut [u8], t: std::time::Duration) -> Result<usize, link::LinkError> {
        self.board.recv(buf, t)
    }
}

/// A board that reboots and answers the next frame at once is seen to
/// have reset by its answer (it has no session), not by a time-out; the
/// session refuses every call after it, and a new one opens.
#[test]
fn a_rebooted_board_is_seen_by_its_session_not_by_timing() {
    let port = Rebooting {
        board: LocalBoard::excalibur().unwrap(),
        sent: 0,
        after: 40,
    };
    let mut s = link::Session::open(port, LinkFaults::default()).unwrap();
    assert_ne!(s.session(), twoport_link::NO_SESSION);
    let mut sim = Simulation::new(scene()).unwrap();
    let mut failed = None;
    for k in 0..100u32 {
        if let Err(e) = s.step(&mut sim) {
            failed = Some((k, e));
            break;
        }
    }
    let (k, e) = failed.expect("the reboot went unseen");
    let ours = s.session();
    assert_eq!(
        e,
        host_sim::Error::Link(link::LinkError::Reset(ours)),
        "{e}"
    );
    // (The handshake took one frame, and heartbeats go out every 10 ticks.)
    assert!((30..40).contains(&k), "seen at tick {k}");
    assert_eq!(s.status().unwrap_err(), link::LinkError::Reset(ours));
}

/// The watchdog in QEMU: `cargo xtask watchdog` runs the an386 image that
/// hangs its loop on purpose after 1,500 armed ticks (the hand pushing
/// into the wall) and passes its pty in `TWOPORT_PTY`. The board stops
/// answering; the CMSDK watchdog resets it; it comes back disarmed,
/// uncalibrated, with zero force, and the reset latched as a named fault
/// that refuses arming until it is cleared.
#[test]
#[ignore = "needs the watchdog-test image in QEMU; run by `cargo xtask watchdog`"]
fn a_hung_loop_is_reset_by_the_watchdog_and_comes_back_disarmed() {
    use twoport_control::Faults as F;
    use twoport_link::BoardMode;
    let pty = std::env::var("TWOPORT_PTY").expect("TWOPORT_PTY names the board's pty");
    let open = || {
        link::Session::open(
            link::SerialBoard::open(&pty).unwrap(),
            LinkFaults::default(),
        )
    };
    let mut s = open().unwrap();
    let mut sim = Simulation::new(scene()).unwrap();
    s.step(&mut sim).unwrap();
    s.calibrate(Axes::one(0)).unwrap();
    s.arm().unwrap();
    let io = twoport_board::IoScale::EXCALIBUR;
    // Whether the host's wait for the hung tick runs out before the board
    // comes back depends on the machine's load; either way the rebooted
    // board answers with no session, and the host says it has reset.
    let (mut last_force, mut first_failed, mut reset_at) = (0.0f32, None, None);
    for k in 1..3000u32 {
        match s.step(&mut sim) {
            Ok((_, duty)) => last_force = io.force_n(duty[0]),
            Err(host_sim::Error::Link(link::LinkError::Timeout { .. })) => {
                first_failed.get_or_insert(k);
            }
            Err(e) => {
                assert_eq!(
                    e,
                    host_sim::Error::Link(link::LinkError::Reset(s.session())),
                    "{e}"
                );
                first_failed.get_or_insert(k);
                reset_at = Some(k);
                break;
            }
        }
    }
    assert_eq!(
        first_failed,
        Some(1501),
        "the image hangs after 1,500 armed ticks"
    );
    assert!(reset_at.is_some(), "the host never saw the reset");
    assert!(
        last_force.abs() > 10.0,
        "pushing when it hung: {last_force} N"
    );
    drop(s);
    let mut s = open().expect("the board answers again after the reset");
    let st = s.status().unwrap();
    assert_eq!((st.mode, st.calibrated), (BoardMode::Disarmed, false));
    // The reset latched first. (The frame that showed the host the reset
    // carried the plant's position, 10 mm from where the rebooted
    // encoder's count starts: that tick's velocity latches too.)
    assert!(F(st.faults).contains(F::WATCHDOG_RESET), "{}", F(st.faults));
    assert_eq!(
        F(st.first_fault).to_string(),
        "watchdog reset: the loop hung"
    );
    let mut sim = Simulation::new(scene()).unwrap();
    for _ in 0..20 {
        assert_eq!(
            s.step(&mut sim).unwrap().1[0],
            0,
            "zero force after the reset"
        );
    }
    s.calibrate(Axes::one(0)).unwrap();
    let e = s.arm().unwrap_err();
    assert!(
        matches!(
            e,
            link::LinkError::Refused {
                why: twoport_link::ModeRefusal::Faulted { .. },
                ..
            }
        ),
        "{e}"
    );
    // Seen and cleared, it arms again.
    s.send(&twoport_link::Message::ClearFaults).unwrap();
    assert_eq!(s.status().unwrap().faults, 0);
    assert_eq!(s.arm().unwrap().mode, BoardMode::Armed);
}

/// A board homing on its encoder's index: it stops at the first pulse,
/// 6 mm down, long before the stop, calibrated to the count, and arms.
#[test]
fn a_board_homes_on_the_index_pulse_before_the_stop() {
    let s = Scene::load(Path::new("../scenes/homing_index.toml"), &[]).unwrap();
    let mut cfg = twoport_board::excalibur::HOMING;
    cfg.index_position = Some(twoport_control::Position::from_nm(-6_000_000));
    let board = LocalBoard::excalibur().unwrap().with_homing([cfg]);
    let r = pil::run(s, 3000, board, LinkFaults::default()).unwrap();
    let (n, err_m) = r.homing.expect("homed");
    // 6 mm at 20 mm/s and the ramp-in.
    assert!((250..600).contains(&n), "{n} ticks");
    // To the count, and the stop never reached.
    assert!(err_m.abs() < 2e-6, "{err_m} m");
    let lowest = r.samples[..n as usize]
        .iter()
        .map(|s| s.handle_m[0])
        .fold(0.0, f64::min);
    assert!(lowest > -0.008, "went down to {lowest} m");
    assert!(r.armed_at_tick > n);
}

/// The identification scene: the board plays its experiment 0.3 s after
/// arming and streams every tick; the record is whole and its force is
/// the hold minus the multisine (the board's law, bit for bit), and the
/// board disarms when the last period ends.
#[test]
fn the_board_plays_the_scenes_experiment_and_streams_every_tick() {
    let scene = Scene::load(Path::new("../scenes/identify/excalibur.toml"), &[]).unwrap();
    let spec = scene.identify.unwrap();
    let x = spec.experiment(1e-3).unwrap();
    let scene = Scene {
        identify: Some(host_sim::engine::scene::IdentifySpec { periods: 3, ..spec }),
        ..scene
    };
    let r = pil::run(
        scene,
        4000,
        LocalBoard::excalibur().unwrap(),
        LinkFaults::default(),
    )
    .unwrap();
    let (played, at) = r.experiment.unwrap();
    assert_eq!(played, twoport_link::ExperimentRequest { periods: 3, ..x });
    assert_eq!(at, r.armed_at_tick + 300);
    let log = r.experiment_log(true).unwrap().unwrap();
    assert_eq!(log.force_n.len(), 3000);
    let m = twoport_control::multisine::Multisine::new(1000, 1, 450, spec.peak_n as f32).unwrap();
    for (n, (f, x)) in log.force_n.iter().zip(&log.position_m).enumerate().skip(1) {
        let v = (x - log.position_m[n - 1]) / 1e-3;
        let hold = 2000.0 * x + 20.0 * v;
        let want = m.at(n as u32) as f64 - hold;
        assert!((f - want).abs() < 2e-3, "tick {n}: {f} against {want}");
    }
    let last = r.telemetry.last().unwrap();
    assert_eq!(last.mode, twoport_link::BoardMode::Disarmed);
    let c = pil::compare(&r, &r);
    assert!(pil::failures(&r, &c, 4000, LinkFaults::default(), 0).is_empty());
}

/// Before its first tick the board says what it can do: the image's
/// period, the Excalibur's limits and its shipped region's envelope,
/// telemetry every 10 ticks. A scene at another period is refused, naming
/// both periods.
#[test]
fn the_board_states_its_spec_and_a_scene_at_another_period_is_refused() {
    use twoport_board::excalibur;
    let r = run(5, LinkFaults::default());
    let spec = r.spec.unwrap();
    assert_eq!(spec.period_ns, 1_000_000);
    assert_eq!(spec.stream_every, excalibur::TELEMETRY_EVERY);
    assert!(!spec.linkage);
    let axis = spec.axes[0];
    let s = excalibur::safety();
    assert_eq!(
        (axis.peak_force_n, axis.continuous_force_n),
        (s.peak_force_n, s.continuous_force_n)
    );
    assert_eq!(axis.region, excalibur::proven_region().unwrap().envelope());
    let twoport_link::ProvenRegion::MaxStiffness { k_max_npm, .. } = axis.region else {
        panic!("{:?}", axis.region)
    };
    // The image's coupling is inside it, and the spec states the latency
    // the region is proven for.
    assert!(k_max_npm >= excalibur::COUPLING.k_npm, "{k_max_npm}");
    assert_eq!(spec.latency_budget_s, excalibur::region::LATENCY_S);

    let e = refusal("period_s=0.0005");
    assert!(e.to_string().contains("period_s"), "{e}");
    assert!(e.to_string().contains("0.001"), "{e}");
}

/// The 4 kHz image with the VE on the host at 1 kHz: the board states its
/// 0.25 ms period, takes an update every 4 ticks (the last telemetry holds
/// one sent within a telemetry period), and holds the host's wall at
/// 10 mm, stiffer than the 1 kHz image holds its own.
#[test]
fn the_fast_image_holds_a_wall_sent_from_the_host_at_1_khz() {
    use twoport_board::excalibur::fast;
    let s = Scene::load(Path::new("../scenes/pil/fast_host_ve.toml"), &[]).unwrap();
    let host = pil::HostVe {
        every_ticks: 4,
        deadline_ticks: 40,
    };
    let ticks = 12_000; // 3 s: the hand moves in and shakes against the wall
    let r = pil::run_with::<_, 1>(
        s,
        ticks,
        link::LocalFast::excalibur_fast().unwrap(),
        LinkFaults::default(),
        Some(host),
    )
    .unwrap();
    assert_eq!(r.spec.unwrap().period_ns, 250_000);
    assert_eq!(
        u64::from(r.ve_updates_sent),
        (ticks - r.armed_at_tick).div_ceil(4)
    );
    let held = r.telemetry.last().unwrap().ve_seq;
    let every = fast::TELEMETRY_EVERY / 4;
    assert!(
        held > 0 && r.ve_updates_sent - held <= every,
        "{held} of {}",
        r.ve_updates_sent
    );
    assert!(r.telemetry.iter().all(|t| t.faults == 0));
    // The VE point reaches the host's surface and never passes it.
    let ve_max = r
        .telemetry
        .iter()
        .filter(|t| t.mode == twoport_link::BoardMode::Armed)
        .map(|t| t.axes[0].ve_position_pm)
        .max();
    assert_eq!(ve_max, Some(10_000_000_000));
    // The same hand pushes the handle less deep into it than into the
    // 1 kHz image's own wall (0.86 mm against 1.28 mm, the rest the
    // flexible handle's give).
    let deepest = |s: &[host_sim::Sample]| s.iter().map(|s| s.handle_m[0]).fold(f64::MIN, f64::max);
    let slow = run(ticks / 4, LinkFaults::default());
    let (fast_in, slow_in) = (deepest(&r.samples) - 0.010, deepest(&slow.samples) - 0.010);
    assert!(
        0.0 < fast_in && fast_in < 0.8 * slow_in,
        "{fast_in} m in, against {slow_in} m"
    );
}

/// A host VE needs the scene's wall to send.
#[test]
fn a_host_ve_run_without_a_wall_is_refused_by_name() {
    let s = Scene::load(
        Path::new("../scenes/table1/impedance_bilateral_maximum.toml"),
        &[],
    )
    .unwrap();
    let e = pil::run_with::<_, 1>(
        s,
        10,
        LocalBoard::excalibur().unwrap(),
        LinkFaults::default(),
        Some(pil::HostVe {
            every_ticks: 1,
            deadline_ticks: 10,
        }),
    )
    .err()
    .unwrap();
    assert!(e.to_string().contains("ve.kind = \"wall\""), "{e}");
}
