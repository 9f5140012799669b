//! The portable firmware loop driven over the wire, as a host drives it.

use twoport_board::{Board, BoardSupport, Bound, RawSensors, Region, GUARD_TICKS};
use twoport_control::passivity::{PassivityLimits, SeriesDamper};
use twoport_control::servo::{ImpedanceGains, OnDemand, PortLayer, ServoOutput};
use twoport_control::ve::BilateralConstraint;
use twoport_control::{AdmittanceGains, Encoder, Faults, Position, SafetyConfig, Servo};
use twoport_link::{
    encode, Axes, AxisRefusal, BoardMode, Decoder, Gains, GainsReply, Message, Refusal, Role,
    MAX_FRAME, PROTOCOL_VERSION,
};

mod common;
mod wire;
use wire::{frame, replies, send};

fn safety() -> SafetyConfig {
    SafetyConfig {
        heartbeat_timeout_ticks: 50,
        require_dead_man: true,
        ..SafetyConfig::excalibur()
    }
}

fn board() -> Board<BilateralConstraint, 3> {
    common::board(51_000.0, safety(), 10)
}

/// Tick 0 (the board then knows the dead-man is closed), calibrate where
/// it stands and arm; the next tick is 1.
fn arm(b: &mut Board<BilateralConstraint, 3>, raw: u32) {
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
            Message::Gains(Axes::one(Gains::Impedance {
                k_npm: 51_000.0,
                b_nspm: 90.0
            })),
            ack(false),
        ]
    );
    // Gains for three axes are refused whole, by count.
    let g = Gains::Impedance {
        k_npm: 1e4,
        b_nspm: 10.0,
    };
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
        (
            Gains::Impedance {
                k_npm: 50_000.0,
                b_nspm: 90.0,
            },
            None,
        ),
        (
            Gains::Impedance {
                k_npm: 51_001.0,
                b_nspm: 90.0,
            },
            Some(Refusal::NotProvenStable { limit: 51_000.0 }),
        ),
        (
            Gains::Impedance {
                k_npm: 50_600.0,
                b_nspm: 75.0,
            },
            Some(Refusal::NotProvenStable {
                limit: 51_000.0 * 0.99,
            }),
        ),
        (
            Gains::Impedance {
                k_npm: 1_000.0,
                b_nspm: 10.0,
            },
            Some(Refusal::NotProvenStable { limit: 0.0 }),
        ),
        (
            Gains::Impedance {
                k_npm: f32::NAN,
                b_nspm: 90.0,
            },
            Some(Refusal::NotFinite),
        ),
        (
            Gains::Impedance {
                k_npm: -1.0,
                b_nspm: 90.0,
            },
            Some(Refusal::OutOfRange),
        ),
        (
            Gains::Admittance {
                kp_npm: 1.0,
                bp_nspm: 1.0,
                m_kg: 5.0,
                b_nspm: 500.0,
            },
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
        vec![Message::Gains(Axes::one(Gains::Impedance {
            k_npm: 50_000.0,
            b_nspm: 90.0
        }))]
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
        &Message::SetGains(Axes::one(Gains::Impedance {
            k_npm: 40_000.0,
            b_nspm: 60.0,
        })),
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
    assert!(msgs.contains(&accepted(Gains::Impedance {
        k_npm: 40_000.0,
        b_nspm: 60.0
    })));
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
    let ok = Gains::Admittance {
        kp_npm: 51_000.0,
        bp_nspm: 90.0,
        m_kg: 5.2,
        b_nspm: 500.0,
    };
    let stiffer = Gains::Admittance {
        kp_npm: 60_000.0,
        bp_nspm: 90.0,
        m_kg: 5.2,
        b_nspm: 500.0,
    };
    let lighter = Gains::Admittance {
        kp_npm: 51_000.0,
        bp_nspm: 90.0,
        m_kg: 4.9,
        b_nspm: 500.0,
    };
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

fn sensors(tick: u32, raw: u32) -> Message {
    Message::Sensors(twoport_link::PilSensors {
        tick,
        encoder_raw: Axes::one(raw),
        load_cell_raw: Axes::one(0),
        dead_man_closed: true,
        index_raw: Axes::one(None),
    })
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

/// A board's peripherals in a test: link bytes in and out, the duties
/// commanded, sensors that never change.
#[derive(Default)]
struct Io {
    rx: std::collections::VecDeque<u8>,
    tx: Vec<u8>,
    duties: Vec<i16>,
    sensors: RawSensors,
    samples: u32,
    clock: u32,
    feeds: u32,
    /// The control period in the clock's count (0: unchecked).
    period: u32,
    /// How far the clock moves per look (7 by default).
    step: u32,
}

impl BoardSupport for Io {
    fn sample(&mut self) -> RawSensors {
        self.samples += 1;
        self.sensors
    }
    fn set_duty(&mut self, [duty]: [i16; 1]) {
        self.duties.push(duty);
    }
    fn set_outputs(&mut self, _: bool) {}
    fn feed_watchdog(&mut self) {
        self.feeds += 1;
    }
    fn cycles_per_tick(&self) -> u32 {
        self.period
    }
    fn read_byte(&mut self) -> Option<u8> {
        self.rx.pop_front()
    }
    fn write(&mut self, bytes: &[u8]) {
        self.tx.extend_from_slice(bytes);
    }
    fn cycles(&mut self) -> u32 {
        // A clock that advances a fixed step per look (7 unless set), so
        // that each stage of a tick measures one step.
        self.clock = self
            .clock
            .wrapping_add(if self.step == 0 { 7 } else { self.step });
        self.clock
    }
}

impl Io {
    /// At rest with the dead-man closed and `load_cell` counts on the load
    /// cell, a calibration at 0 queued.
    fn calibrating(load_cell: i32) -> Self {
        let mut io = Io {
            sensors: RawSensors {
                encoder_raw: [0],
                load_cell_counts: [load_cell],
                dead_man_closed: true,
                index_raw: [None],
            },
            ..Io::default()
        };
        io.queue(
            0,
            Message::Calibrate {
                position_pm: Axes::one(0),
            },
        );
        io
    }

    fn queue(&mut self, seq: u16, m: Message) {
        let mut buf = [0u8; MAX_FRAME];
        let n = encode(seq, &m, &mut buf).unwrap();
        self.rx.extend(&buf[..n]);
    }
    fn messages(&mut self) -> Vec<Message> {
        let mut out = Vec::new();
        Decoder::new().feed(&std::mem::take(&mut self.tx), |e| out.push(e.msg));
        out
    }
}

/// What [`late_run`] saw: each tick's output, the last duty, the spec,
/// the board's count of guarded late ticks, and whether it guards still.
type LateRun = (Vec<ServoOutput<f32, 1>>, i16, twoport_link::Spec, u32, bool);

/// Calibrate and tick `b` disarmed once with a slow tick, arm it, move the
/// handle off the constraint for 199 ticks, then one tick whose force
/// comes 24 counts after its sample and `after` on time.
fn late_run<L: PortLayer>(b: Board<BilateralConstraint, 3, 1, L>, after: u16) -> LateRun {
    let mut b = b;
    assert_eq!(b.spec().latency_budget_s, 3e-6);
    let mut io = Io::calibrating(0);
    let tick = |b: &mut Board<BilateralConstraint, 3, 1, L>, io: &mut Io, k: u16| {
        io.queue(1 + k, Message::Heartbeat);
        b.poll_link(io);
        let out = b.control_tick(io);
        b.flush(io);
        out
    };
    // Disarmed and slow: no force, nothing latched.
    io.step = 8;
    assert!(tick(&mut b, &mut io, 0).faults.is_empty());
    io.step = 7;
    io.queue(100, Message::Arm);
    let mut outs = vec![tick(&mut b, &mut io, 1)];
    // Armed at rest, then the handle moves 30 µm off the constraint.
    io.sensors.encoder_raw = [30];
    outs.extend((2..200).map(|k| tick(&mut b, &mut io, k)));
    assert!(outs.iter().all(|o| o.faults.is_empty()), "on time");
    assert!(outs.last().unwrap().actuator_force_n[0].abs() > 1.0);
    io.step = 8;
    outs.push(tick(&mut b, &mut io, 200));
    io.step = 7;
    outs.extend((0..after).map(|k| tick(&mut b, &mut io, 201 + k)));
    let duty = *io.duties.last().unwrap();
    (outs, duty, b.spec(), b.late_guarded(), b.guarding())
}

fn late_region() -> Region<3> {
    common::region().with_latency(3e-6).unwrap()
}

/// A board that knows its count's rate holds its latency to its region's:
/// at 7 MHz a region proven for 3 µs allows 21 counts, what a tick of
/// three 7-count looks takes. Disarmed, a slower tick latches nothing (no
/// force goes out); armed, the first tick whose force comes 24 counts
/// after its sample latches "force late", and the next tick's force is
/// zero. A board that does not know its count's rate checks nothing.
#[test]
fn a_force_later_than_the_region_allows_faults_to_zero() {
    let board = || common::board_in(late_region(), 51_000.0, safety(), 0);
    let (outs, duty, spec, guarded, _) = late_run(board().with_count_rate(7_000_000), 1);
    let [late, after] = [&outs[outs.len() - 2], &outs[outs.len() - 1]];
    // The late tick's force is out when it is measured; the next is zero.
    assert!(late.actuator_force_n[0].abs() > 1.0);
    assert!(after.faults.contains(Faults::LATE_FORCE), "{after:?}");
    assert_eq!((after.actuator_force_n[0], duty, guarded), (0.0, 0, 0));
    assert_eq!(spec.worst_latency_cycles, 24);
    let (outs, duty, _, _, _) = late_run(board(), 1);
    assert!(outs.iter().all(|o| o.faults.is_empty()));
    assert_ne!(duty, 0);
}

/// With a passivity layer on demand at the port, the same late tick
/// faults nothing: the board engages the layer and runs on, counting the
/// tick, and lets it go idle [`GUARD_TICKS`] ticks on time later. Until
/// the late tick the forces are the unlayered board's, bit for bit.
#[test]
fn a_late_force_engages_the_passivity_layer() {
    let layered = || {
        let enc = Encoder::new(16, 1_000_000, 0, Position::ZERO).unwrap();
        let servo = Servo::new(
            [ImpedanceGains::new(51_000.0, 90.0).into()],
            [enc],
            [safety()],
            BilateralConstraint::new(Position::ZERO),
        )
        .unwrap();
        let limits = PassivityLimits::for_device(0.93, 1e-3, safety().peak_force_n).unwrap();
        let damper = OnDemand::new(SeriesDamper::new(limits).unwrap());
        Board::new(servo.with_layers([damper]).unwrap(), [late_region()], 0)
    };
    let rate = 7_000_000;
    let (outs, duty, spec, guarded, guarding) = late_run(layered().with_count_rate(rate), 1);
    assert!(outs.iter().all(|o| o.faults.is_empty()));
    assert_eq!(
        (guarded, spec.worst_latency_cycles, guarding),
        (1, 24, true)
    );
    assert_ne!(duty, 0);
    let plain = common::board_in(late_region(), 51_000.0, safety(), 0);
    let (direct, ..) = late_run(plain, 1);
    let force =
        |o: &[ServoOutput<f32, 1>]| o.iter().map(|o| o.actuator_force_n[0]).collect::<Vec<_>>();
    assert_eq!(
        force(&outs[..outs.len() - 1]),
        force(&direct[..direct.len() - 1])
    );
    // Idle again a second of ticks on time later, not before.
    let ticks = GUARD_TICKS as u16;
    let (.., guarding) = late_run(layered().with_count_rate(rate), ticks - 1);
    assert!(guarding);
    let (outs, .., guarding) = late_run(layered().with_count_rate(rate), ticks);
    assert!(!guarding && outs.iter().all(|o| o.faults.is_empty()));
}

#[test]
fn a_pil_board_ticks_once_per_sensor_frame_and_answers_with_the_duty() {
    let mut b = board().with_pil(true);
    let mut io = Io::default();
    io.queue(0, Message::hello(Role::Host, 1, 0xBEEF));
    io.queue(
        1,
        Message::Calibrate {
            position_pm: Axes::one(0),
        },
    );
    // Armed once the first tick has seen the dead-man closed.
    for k in 0..30u16 {
        io.queue(2 + 2 * k, sensors(u32::from(k), u32::from(k) * 10));
        if k == 0 {
            io.queue(3, Message::Arm);
        }
    }
    // Sensor frames from the link only wait; the control tick runs them.
    b.on_bytes(&[]);
    assert!(!b.sensors_pending());
    // As an image's main loop does, send what each tick queued.
    for _ in 0..30 {
        b.control_tick(&mut io);
        b.flush(&mut io);
    }
    assert!(io.rx.is_empty());
    let msgs = io.messages();
    assert!(matches!(msgs[0], Message::HelloAck { accepted: true, .. }));
    let acts: Vec<_> = msgs
        .iter()
        .filter_map(|m| match m {
            Message::Actuator(a) => Some(*a),
            _ => None,
        })
        .collect();
    // Each tick answers its own frame with the duty it commanded, and the
    // board never read its own sensors.
    assert_eq!(acts.len(), 30);
    for (k, a) in acts.iter().enumerate() {
        assert_eq!(a.tick, k as u32);
        assert_eq!(a.duty, Axes::one(io.duties[k]));
        assert_eq!(a.session, 0xBEEF, "every answer carries the host's session");
    }
    assert!(io.duties.iter().any(|d| *d != 0));
    assert_eq!(io.samples, 0);
    assert_eq!(b.pil_refused(), 0);
}

#[test]
fn a_board_with_real_sensors_ticks_from_its_support_and_counts_its_ticks() {
    let mut b = board();
    let mut io = Io::calibrating(1_500);
    // Not a PIL board: nothing the link says makes a tick wait.
    assert!(!b.poll_link(&mut io));
    let mut outs = Vec::new();
    // Past the enable's force ramp.
    let mut tx = Vec::new();
    for k in 0..120 {
        // The host's heartbeats, which the main loop takes off the link.
        io.queue(1 + k, Message::Heartbeat);
        // Armed at rest, then the handle moves 30 um.
        if k == 1 {
            io.queue(500, Message::Arm);
        }
        if k == 2 {
            io.sensors.encoder_raw = [30];
        }
        b.poll_link(&mut io);
        outs.push(b.control_tick(&mut io));
        b.flush(&mut io);
        tx.extend(io.messages());
    }
    assert_eq!(io.samples, 120);
    // The watchdog is fed once a tick.
    assert_eq!(io.feeds, 120);
    // 30 um off the constraint at 51 kN/m is about 1.5 N of pull back;
    // the load cell reads 1.5 N through the scale.
    assert!(
        outs.last().unwrap().actuator_force_n[0].abs() > 1.0,
        "{:?}",
        outs.last()
    );
    assert_eq!(*io.duties.last().unwrap(), b.duty()[0]);
    let telemetry: Vec<_> = tx
        .into_iter()
        .filter_map(|m| match m {
            Message::Telemetry(t) => Some(t),
            _ => None,
        })
        .collect();
    // Telemetry every 10 ticks, numbered by the board's own count, with
    // the time one tick took in the support's cycles.
    assert_eq!(
        telemetry.iter().map(|t| t.tick).collect::<Vec<_>>(),
        (9..120).step_by(10).collect::<Vec<u32>>()
    );
    assert!(telemetry
        .iter()
        .all(|t| (t.axes[0].load_cell_n - 1.5).abs() < 1e-6));
    // Three stages (sensors, law, drive), one step of the clock each and
    // the drive two (it looks once more when the command is written): the
    // latency from the sample to the command is three.
    assert!(telemetry.iter().all(|t| t.loop_cycles == 28
        && t.stage_cycles == [7, 7, 14]
        && t.worst_latency_cycles == 21));
    // Without a period, nothing is checked.
    assert!(telemetry
        .iter()
        .all(|t| t.deadline_misses == 0 && t.worst_jitter_cycles == 0));
    // The dead-man opens: zero force in that very tick.
    io.sensors.dead_man_closed = false;
    let out = b.control_tick(&mut io);
    assert_eq!(*io.duties.last().unwrap(), 0, "{out:?}");
}

/// Loop timing against a period of 37 counts: ticks of 28 that start 35
/// apart are on time with 2 of jitter; a tick of 44 overruns its period,
/// and a tick that starts 85 after the last (a late interrupt) is a miss
/// too. The longest from a sample to its command (three looks of the
/// clock) is kept since boot. Each telemetry frame, sent from inside a
/// tick, carries the timing of the ticks before it.
#[test]
fn deadline_misses_the_worst_jitter_and_latency_are_counted_and_reported() {
    let mut b = common::board(51_000.0, safety(), 1);
    let mut io = Io {
        period: 37,
        ..Io::default()
    };
    // One tick, and the telemetry it sent.
    let tick = |b: &mut Board<BilateralConstraint, 3>, io: &mut Io| {
        b.control_tick(io);
        b.flush(io);
        io.messages()
            .into_iter()
            .find_map(|m| match m {
                Message::Telemetry(t) => Some(t),
                _ => None,
            })
            .unwrap()
    };
    let mut t = tick(&mut b, &mut io);
    for _ in 0..10 {
        t = tick(&mut b, &mut io);
    }
    assert_eq!((t.deadline_misses, t.worst_jitter_cycles), (0, 2));
    assert_eq!(t.worst_latency_cycles, 21);
    // One slow tick: 11 a look, 44 in all, 33 from sample to command.
    io.step = 11;
    tick(&mut b, &mut io);
    io.step = 7;
    let t = tick(&mut b, &mut io);
    assert_eq!((t.deadline_misses, t.stage_cycles), (1, [11, 11, 22]));
    assert_eq!(t.worst_latency_cycles, 33);
    // The tick after it started 44 + 7 = 51 after it: 14 of jitter, but
    // less than half a period late.
    let t = tick(&mut b, &mut io);
    assert_eq!((t.deadline_misses, t.worst_jitter_cycles), (1, 14));
    // An interrupt 50 counts late: 85 from start to start. The latency
    // stays the worst since boot.
    io.clock = io.clock.wrapping_add(50);
    tick(&mut b, &mut io);
    let t = tick(&mut b, &mut io);
    assert_eq!((t.deadline_misses, t.worst_jitter_cycles), (2, 48));
    assert_eq!(t.worst_latency_cycles, 33);
    // The spec gives it in seconds where the board knows its count's rate.
    let mut b = common::board(51_000.0, safety(), 1).with_count_rate(7_000_000);
    b.control_tick(&mut io);
    let spec = b.spec();
    assert_eq!(spec.worst_latency_cycles, 21);
    assert!((spec.worst_latency_s().unwrap() - 3e-6).abs() < 1e-15);
    assert_eq!(
        common::board(51_000.0, safety(), 1)
            .spec()
            .worst_latency_s(),
        None
    );
}
