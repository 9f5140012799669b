//! What a host application uses (protocol 8): the board's specification,
//! the telemetry rate, and the VE on the host with the coupling on the
//! board.

use twoport_control::{Faults, SafetyConfig};
use twoport_link::{
    Axes, AxisSpec, BoardMode, Contact, Message, ModeRefusal, ModeRequest, ProvenRegion, Spec,
    Telemetry, VeSource, VeUpdate,
};

mod common;
mod wire;
use common::TestBoard;
use wire::{frame, replies, send};

fn safety() -> SafetyConfig {
    SafetyConfig {
        heartbeat_timeout_ticks: 50,
        require_dead_man: true,
        ..SafetyConfig::excalibur()
    }
}

fn board() -> TestBoard {
    common::board(51_000.0, safety(), 10)
}

/// Calibrated where it stands (at `raw`, tick 0) and armed.
fn armed(mut b: TestBoard, raw: u32) -> TestBoard {
    b.tick(&frame(0, raw));
    send(
        &mut b,
        100,
        Message::Calibrate {
            position_pm: Axes::one(0),
        },
    );
    send(&mut b, 101, Message::Arm);
    assert_eq!(b.mode(), BoardMode::Armed, "{:?}", replies(&mut b));
    replies(&mut b);
    b
}

fn telemetry(msgs: &[Message]) -> Vec<Telemetry> {
    msgs.iter()
        .filter_map(|m| match m {
            Message::Telemetry(t) => Some(*t),
            _ => None,
        })
        .collect()
}

fn update(seq: u32, pm: i64) -> Message {
    Message::VeUpdate(VeUpdate {
        seq,
        position_pm: Axes::one(pm),
        contact: Axes::one(Contact::Held),
    })
}

const HOST: VeSource = VeSource::Host {
    ramp_ticks: 1,
    deadline_ticks: 3,
};

/// The board says what it can do: its period, each axis's limits and its
/// proven region's envelope, its VE, and the telemetry rate, which the
/// host sets and which takes effect from the next tick, in any mode.
#[test]
fn the_spec_names_the_limits_and_the_region_and_the_stream_follows_the_host() {
    let mut b = board();
    send(&mut b, 0, Message::GetSpec);
    let s = safety();
    let want = Spec {
        period_ns: 1_000_000,
        stream_every: 10,
        linkage: false,
        ve: VeSource::Board,
        link_bytes_per_s: None,
        count_hz: None,
        worst_latency_cycles: 0,
        latency_budget_s: 0.0,
        axes: Axes::one(AxisSpec {
            peak_force_n: s.peak_force_n,
            continuous_force_n: s.continuous_force_n,
            max_velocity_mps: s.max_velocity_mps,
            region: ProvenRegion::MaxStiffness {
                b_min_nspm: 30.0,
                b_max_nspm: 90.0,
                k_max_npm: 51_400.0,
                b_at_k_max_nspm: 60.0,
            },
            workspace_nm: None,
        }),
    };
    assert_eq!(replies(&mut b), vec![Message::Spec(want)]);
    let ticks = |b: &mut TestBoard, from: u32, n: u32| -> Vec<u32> {
        for t in from..from + n {
            b.tick(&frame(t, 0));
        }
        telemetry(&replies(b)).iter().map(|t| t.tick).collect()
    };
    assert_eq!(ticks(&mut b, 0, 20), vec![9, 19]);
    // Every tick, disarmed.
    send(&mut b, 1, Message::SetStream { every_ticks: 1 });
    assert_eq!(replies(&mut b), vec![Message::Stream { every_ticks: 1 }]);
    assert_eq!(ticks(&mut b, 20, 3), vec![20, 21, 22]);
    // Every third, counted from the request.
    send(&mut b, 2, Message::SetStream { every_ticks: 3 });
    replies(&mut b);
    assert_eq!(ticks(&mut b, 23, 7), vec![25, 28]);
    // None.
    send(&mut b, 3, Message::SetStream { every_ticks: 0 });
    replies(&mut b);
    assert_eq!(ticks(&mut b, 30, 50), Vec::<u32>::new());
    send(&mut b, 4, Message::SetVe(HOST));
    send(&mut b, 5, Message::GetSpec);
    let r = replies(&mut b);
    assert!(
        matches!(
            r.as_slice(),
            [
                Message::Ve(HOST),
                Message::Spec(Spec {
                    stream_every: 0,
                    ve: HOST,
                    ..
                })
            ]
        ),
        "{r:?}"
    );
}

/// The VE source changes only disarmed, and a host VE needs a deadline.
#[test]
fn the_ve_moves_to_the_host_only_disarmed_and_with_a_deadline() {
    let mut b = armed(board(), 0);
    send(&mut b, 1, Message::SetVe(HOST));
    assert_eq!(
        replies(&mut b),
        vec![Message::ModeRefused {
            asked: ModeRequest::SetVe,
            why: ModeRefusal::NotDisarmed {
                mode: BoardMode::Armed
            }
        }]
    );
    assert_eq!(b.ve_source(), VeSource::Board);
    send(&mut b, 2, Message::Disarm);
    replies(&mut b);
    let none = VeSource::Host {
        ramp_ticks: 1,
        deadline_ticks: 0,
    };
    send(&mut b, 3, Message::SetVe(none));
    assert_eq!(
        replies(&mut b),
        vec![Message::ModeRefused {
            asked: ModeRequest::SetVe,
            why: ModeRefusal::BadDeadline
        }]
    );
    // A ramp of 0 ticks is a ramp of 1, and the answer says so.
    let zero_ramp = VeSource::Host {
        ramp_ticks: 0,
        deadline_ticks: 3,
    };
    send(&mut b, 4, Message::SetVe(zero_ramp));
    assert_eq!(replies(&mut b), vec![Message::Ve(HOST)]);
    send(&mut b, 5, Message::SetVe(VeSource::Board));
    assert_eq!(replies(&mut b), vec![Message::Ve(VeSource::Board)]);
}

/// The law the board runs on a host's point is the law it runs on its own
/// VE: a held point at the origin and the image's bilateral constraint at
/// the origin give the same output, bit for bit, tick after tick, as the
/// handle moves.
#[test]
fn a_held_point_is_the_law_on_the_constraint_it_stands_for() {
    let own = armed(board(), 0);
    let mut host = board();
    send(&mut host, 0, Message::SetVe(HOST));
    let mut host = armed(host, 0);
    let mut own = own;
    for t in 1..400u32 {
        // The handle, in counts of 1 um: out to 2 mm and back.
        let raw = (2000.0 * (t as f32 * 0.02).sin().abs()) as u32;
        send(&mut host, t as u16, update(t, 0));
        for b in [&mut own, &mut host] {
            send(b, 0, Message::Heartbeat);
        }
        let a = own.tick(&frame(t, raw));
        let b = host.tick(&frame(t, raw));
        assert_eq!(a, b, "tick {t}");
    }
    assert!(own.last_output().actuator_force_n[0].abs() > 1.0);
}

/// An update moves the point at the next tick (over its ramp) and the
/// coupling pulls the handle toward it; the telemetry says which update
/// is held and where. The board holds the last update for its deadline,
/// then faults to zero force and disarms, naming the fault. Older updates,
/// updates for other axes and points out of range are ignored.
#[test]
fn updates_move_the_point_and_a_late_host_faults_to_zero_force() {
    let mut b = board();
    send(&mut b, 0, Message::SetVe(HOST));
    send(&mut b, 1, Message::SetStream { every_ticks: 1 });
    let mut b = armed(b, 0);
    // 0.5 mm above the handle.
    send(&mut b, 2, update(7, 500_000_000));
    // Older, of two axes, out of range: none of them is taken.
    send(&mut b, 3, update(6, -500_000_000));
    send(
        &mut b,
        4,
        Message::VeUpdate(VeUpdate {
            seq: 8,
            position_pm: Axes::new([0, 0]).unwrap(),
            contact: Axes::new([Contact::Held; 2]).unwrap(),
        }),
    );
    send(&mut b, 5, update(9, i64::MAX));
    let out = b.tick(&frame(1, 0));
    let t = telemetry(&replies(&mut b));
    assert_eq!(t.len(), 1);
    assert_eq!((t[0].ve_seq, t[0].axes[0].ve_position_pm), (7, 500_000_000));
    // The spring's 25.5 N toward the point (a positive f_a resists
    // positive motion, so pulling toward +x is negative), past the ramp's
    // damper as it moved.
    let f = out.commanded_force_n[0];
    assert!(f < -25.0, "{f} N");
    for tick in 2..=3 {
        let out = b.tick(&frame(tick, 0));
        assert_eq!(b.mode(), BoardMode::Armed, "tick {tick}");
        assert!((out.commanded_force_n[0] + 25.5).abs() < 0.01, "{out:?}");
    }
    // The fourth tick on one update, with a deadline of three.
    let out = b.tick(&frame(4, 0));
    assert_eq!(out.actuator_force_n, [0.0]);
    assert!(out.faults.contains(Faults::VE_STALE), "{:?}", out.faults);
    assert_eq!(b.mode(), BoardMode::Disarmed);
    let r = replies(&mut b);
    assert!(
        r.iter()
            .any(|m| matches!(m, Message::FaultReport { faults, .. }
            if *faults & Faults::VE_STALE.0 != 0)),
        "{r:?}"
    );
    // Re-armed, the point starts at the handle again.
    send(&mut b, 6, Message::ClearFaults);
    send(&mut b, 7, Message::Arm);
    replies(&mut b);
    let out = b.tick(&frame(5, 0));
    assert_eq!(b.mode(), BoardMode::Armed);
    assert_eq!(out.commanded_force_n, [0.0]);
}

/// A host's call waits for an answer, so a board answers `Disarm` with
/// its status even when it is disarmed already (a fault, or a lost host,
/// may have disarmed it first).
#[test]
fn disarm_is_answered_even_when_the_board_is_disarmed_already() {
    let mut b = board();
    send(&mut b, 0, Message::Disarm);
    let r = replies(&mut b);
    assert!(
        matches!(r.as_slice(), [Message::Status(s)] if s.mode == BoardMode::Disarmed),
        "{r:?}"
    );
    let mut b = armed(b, 0);
    send(&mut b, 1, Message::Disarm);
    let r = replies(&mut b);
    assert!(
        matches!(r.as_slice(), [Message::Status(s)] if s.mode == BoardMode::Disarmed),
        "{r:?}"
    );
}
