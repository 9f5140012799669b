//! The portable firmware loop driven over the wire, as a host drives it.

use twoport_board::{Board, Bound, Region};
use twoport_control::ve::BilateralConstraint;
use twoport_control::{AdmittanceGains, Encoder, Faults, Position, SafetyConfig, Servo};
use twoport_link::{
    encode, Axes, AxisRefusal, BoardMode, Decoder, Gains, GainsReply, Message, Refusal, Role,
    MAX_FRAME, PROTOCOL_VERSION,
};

mod common;
mod wire;
use common::sensors;
use wire::{frame, replies, send};

fn safety() -> SafetyConfig {
    common::safety()
}

fn board() -> Board<Servo<BilateralConstraint>, 3> {
    common::board(51_000.0, safety(), 10)
}

/// Tick 0 (the board then knows the dead-man is closed), calibrate where
/// it stands and arm; the next tick is 1.
fn arm(b: &mut Board<Servo<BilateralConstraint>, 3>, raw: u32) {
    b.tick(&frame(0, raw));
    send(
        b,
        100,
        Message::Calibrate {
            position_pm: Axes::one(0),
        },
    );
    send(b, 101, Message::Arm);
    assert_eq!(b.mode(), BoardMode::Armed, "{:?}", replies(b));
    replies(b);
}

/// A one-axis board's acceptance of `g`.
fn accepted(g: Gains) -> Message {
    Message::GainsReply(GainsReply::Accepted(Axes::one(g)))
}

/// A one-axis board's refusal of its axis's gains.
fn refused(why: Refusal) -> Message {
    Message::GainsReply(GainsReply::Refused(AxisRefusal { axis: 0, why }))
}

#[test]
fn handshake_and_gain_queries() {
    let mut b = board();
    send(&mut b, 0, Message::hello(Role::Host, 1, 7));
    send(&mut b, 1, Message::GetGains);
    // A host that drives three axes hears that this board has one, and the
    // board stays in the session it was in.
    send(&mut b, 2, Message::hello(Role::Host, 3, 8));
    let ack = |accepted| Message::HelloAck {
        version: PROTOCOL_VERSION,
        accepted,
        axes: 1,
        session: 7,
    };
    assert_eq!(
        replies(&mut b),
        vec![
            ack(true),
            Message::Gains(Axes::one(Gains::impedance(51_000.0, 90.0))),
            ack(false),
        ]
    );
    // Gains for three axes are refused whole, by count.
    let g = Gains::impedance(1e4, 10.0);
    send(&mut b, 3, Message::SetGains(Axes::new([g; 3]).unwrap()));
    assert_eq!(
        replies(&mut b),
        vec![Message::GainsReply(GainsReply::Refused(AxisRefusal {
            axis: 0,
            why: Refusal::WrongAxisCount { axes: 1 }
        }))]
    );
}

/// Only gains inside the proven region are accepted; everything else is
/// refused with the reason, and the gains in force do not change.
#[test]
fn gains_outside_the_proven_region_are_refused() {
    let mut b = board();
    let cases = [
        (Gains::impedance(50_000.0, 90.0), None),
        (
            Gains::impedance(51_001.0, 90.0),
            Some(Refusal::NotProvenStable { limit: 51_000.0 }),
        ),
        (
            Gains::impedance(50_600.0, 75.0),
            Some(Refusal::NotProvenStable {
                limit: 51_000.0 * 0.99,
            }),
        ),
        (
            Gains::impedance(1_000.0, 10.0),
            Some(Refusal::NotProvenStable { limit: 0.0 }),
        ),
        (Gains::impedance(f32::NAN, 90.0), Some(Refusal::NotFinite)),
        (Gains::impedance(-1.0, 90.0), Some(Refusal::OutOfRange)),
        (
            Gains::admittance(1.0, 1.0, 5.0, 500.0),
            Some(Refusal::WrongDisplay),
        ),
    ];
    for (i, (g, refusal)) in cases.iter().enumerate() {
        send(&mut b, i as u16, Message::SetGains(Axes::one(*g)));
        let r = replies(&mut b);
        match refusal {
            None => assert_eq!(r, vec![accepted(*g)]),
            Some(why) => assert_eq!(r, vec![refused(*why)], "{g:?}"),
        }
    }
    // The one accepted change is in force; the refusals changed nothing.
    send(&mut b, 99, Message::GetGains);
    assert_eq!(
        replies(&mut b),
        vec![Message::Gains(Axes::one(Gains::impedance(50_000.0, 90.0)))]
    );
}

/// With heartbeats the loop runs; when they stop, force is zero within the
/// watchdog's 50 ticks, a fault report goes out, and it stays latched until
/// the host clears it.
#[test]
fn link_loss_gives_zero_force_within_the_watchdog_deadline() {
    let mut b = board();
    arm(&mut b, 0);
    let mut seq = 1;
    for k in 1..500u32 {
        if k % 10 == 0 {
            send(&mut b, seq, Message::Heartbeat);
            seq += 1;
        }
        let out = b.tick(&frame(k, 100));
        assert!(out.faults.is_empty(), "tick {k}: {}", out.faults);
    }
    assert!(
        b.tick(&frame(500, 100)).actuator_force_n[0].abs() > 1.0,
        "the coupling pulls"
    );
    let mut zero_at = None;
    for k in 501..600u32 {
        let out = b.tick(&frame(k, 100));
        if out.actuator_force_n[0] == 0.0 && zero_at.is_none() {
            zero_at = Some(k);
            assert!(out.faults.contains(Faults::HEARTBEAT_LOST));
        }
    }
    let zero_at = zero_at.expect("zero force after link loss");
    assert!(
        zero_at - 491 <= 51,
        "zero at tick {zero_at}, last heartbeat at 490"
    );
    assert!(replies(&mut b).iter().any(|m| matches!(m, Message::FaultReport { faults, .. } if faults & Faults::HEARTBEAT_LOST.0 != 0)));
    send(&mut b, seq, Message::ClearFaults);
    send(&mut b, seq + 1, Message::Heartbeat);
    assert!(b.tick(&frame(600, 100)).faults.is_empty());
}

/// Garbage and corrupted frames between good ones: the loop keeps ticking,
/// the good commands still act, the bad ones are counted.
#[test]
fn corrupted_frames_do_not_stop_the_loop() {
    let mut b = board();
    let mut good = [0u8; MAX_FRAME];
    let n = encode(
        7,
        &Message::SetGains(Axes::one(Gains::impedance(40_000.0, 60.0))),
        &mut good,
    )
    .unwrap();
    let mut bad = good;
    bad[3] ^= 0x40;
    for k in 0..1000u32 {
        match k % 100 {
            10 => b.on_bytes(&[0xde, 0xad, 0xbe, 0xef, 0x00, 0x13]),
            20 => b.on_bytes(&bad[..n]),
            _ => {}
        }
        if k == 555 {
            b.on_bytes(&good[..n]);
        }
        b.tick(&frame(k, k % 300));
    }
    let s = b.link_stats();
    assert!(s.dropped() >= 20, "{s:?}");
    assert_eq!(s.frames, 1);
    let msgs = replies(&mut b);
    assert!(msgs.contains(&accepted(Gains::impedance(40_000.0, 60.0))));
}

/// A host that never reads cannot grow the board's memory: telemetry keeps
/// the newest frames and counts the dropped ones, and an answer queued
/// behind the flood is still delivered first.
#[test]
fn the_outgoing_queue_is_bounded() {
    let mut b = board();
    for k in 0..10_000u32 {
        b.tick(&frame(k, 0));
        if k == 5_000 {
            send(&mut b, 0, Message::GetGains);
        }
    }
    assert!(b.tx_dropped() > 900);
    let msgs = replies(&mut b);
    assert_eq!(msgs.len(), 1 + twoport_board::TX_FRAMES);
    assert!(
        matches!(msgs[0], Message::Gains(_)),
        "the answer first: {:?}",
        msgs[0]
    );
    assert!(matches!(msgs.last(), Some(Message::Telemetry(t)) if t.tick == 9_999));
}

#[test]
fn admittance_gains_need_the_proven_regulator() {
    let region = Region::new(
        Bound::MinMass,
        [300.0, 500.0],
        [5.5, 5.0],
        Some((51_000.0, 90.0)),
    )
    .unwrap();
    let enc = Encoder::new(16, 1_000_000, 0, Position::ZERO).unwrap();
    let s = Servo::new(
        [AdmittanceGains::new(51_000.0, 90.0, 5.0, 500.0).into()],
        [enc],
        [safety()],
        BilateralConstraint::new(Position::ZERO),
    )
    .unwrap();
    let mut b = Board::new(s, [region], 0);
    let ok = Gains::admittance(51_000.0, 90.0, 5.2, 500.0);
    let stiffer = Gains::admittance(60_000.0, 90.0, 5.2, 500.0);
    let lighter = Gains::admittance(51_000.0, 90.0, 4.9, 500.0);
    for (g, want) in [
        (ok, accepted(ok)),
        (
            stiffer,
            refused(Refusal::NotProvenStable { limit: 51_000.0 }),
        ),
        (lighter, refused(Refusal::NotProvenStable { limit: 5.0 })),
    ] {
        let mut buf = [0u8; MAX_FRAME];
        let n = encode(0, &Message::SetGains(Axes::one(g)), &mut buf).unwrap();
        b.on_bytes(&buf[..n]);
        let f = b.pop_tx().unwrap();
        let mut got = None;
        Decoder::new().feed(&f, |e| got = Some(e.msg));
        assert_eq!(got, Some(want));
    }
}

#[test]
fn a_board_with_real_sensors_ignores_sensor_frames_from_the_link() {
    let mut b = board();
    arm(&mut b, 0);
    for k in 1..20u32 {
        b.tick(&frame(k, k));
    }
    let before = b.last_output().position[0];
    for k in 0..5u16 {
        send(&mut b, 1 + k, sensors(20 + u32::from(k), 5000));
    }
    assert_eq!(b.pil_refused(), 5);
    // No tick ran from the link, and nothing answered.
    assert_eq!(b.last_output().position[0], before);
    assert!(replies(&mut b)
        .iter()
        .all(|m| !matches!(m, Message::Actuator(_))));
}
