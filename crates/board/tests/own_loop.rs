//! A board ticking from its own support: real sensors or the host's
//! sensor frames (PIL), its loop's timing (deadline misses, jitter,
//! latency), and the latency gate, faulting a late force or engaging
//! the passivity layer.

use common::sensors;
use twoport_board::{Board, BoardSupport, RawSensors, Region, GUARD_TICKS};
use twoport_control::passivity::{PassivityLimits, SeriesDamper};
use twoport_control::servo::{ImpedanceGains, OnDemand, PortLayer, ServoOutput};
use twoport_control::ve::BilateralConstraint;
use twoport_control::{Encoder, Faults, Position, SafetyConfig, Servo};
use twoport_link::*;

mod common;

fn safety() -> SafetyConfig {
    common::safety()
}

fn board() -> Board<Servo<BilateralConstraint>, 3> {
    common::board(51_000.0, safety(), 10)
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
fn late_run<L: PortLayer>(
    b: Board<Servo<BilateralConstraint, f32, 1, L>, 3>,
    after: u16,
) -> LateRun {
    let mut b = b;
    assert_eq!(b.spec().latency_budget_s, 3e-6);
    let mut io = Io::calibrating(0);
    let tick = |b: &mut Board<Servo<BilateralConstraint, f32, 1, L>, 3>, io: &mut Io, k: u16| {
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
    let tick = |b: &mut Board<Servo<BilateralConstraint>, 3>, io: &mut Io| {
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
