//! The board's state machine over the wire: it boots disarmed with its
//! outputs off, arms only when it is safe to, disarms on any fault, and
//! homes onto a hard stop with a small force to find the encoder offset.

use twoport_board::{BoardSupport, IoScale, RawSensors};
use twoport_control::homing::HomingConfig;
use twoport_control::{Faults, Position, SafetyConfig};
use twoport_link::{
    encode, Axes, BoardMode, Decoder, Message, ModeRefusal, ModeRequest, Status, MAX_FRAME,
};

const T: f32 = 1e-3;

mod common;
use common::TestBoard;

fn board_with(k_npm: f32) -> TestBoard {
    let safety = SafetyConfig {
        require_dead_man: true,
        ..SafetyConfig::excalibur()
    };
    common::board(k_npm, safety, 0)
        .with_homing([HomingConfig::gentle(Position::from_nm(-20_000_000), T)])
}

fn board() -> TestBoard {
    board_with(51_000.0)
}

/// One axis on a bench: a 0.93 kg actuator with 4 N s/m of damping, a hard
/// stop (2e5 N/m) `stop_m` metres from where it powered on, a 16-bit
/// 1 µm encoder that read 0 at power-on, an amplifier whose outputs the
/// board switches, and the link.
struct Bench {
    x_m: f64,
    v_mps: f64,
    stop_m: Option<f64>,
    duty: i16,
    outputs: bool,
    outputs_calls: Vec<bool>,
    dead_man_closed: bool,
    peak_force_n: f64,
    rx: std::collections::VecDeque<u8>,
    tx: Vec<u8>,
    seq: u16,
    /// The encoder's index mark (m from power-on), if it has one.
    index_m: Option<f64>,
    last_x_m: f64,
}

impl Bench {
    fn new(stop_m: Option<f64>) -> Self {
        Bench {
            x_m: 0.0,
            v_mps: 0.0,
            stop_m,
            duty: 0,
            outputs: false,
            outputs_calls: Vec::new(),
            dead_man_closed: true,
            peak_force_n: 0.0,
            rx: Default::default(),
            tx: Vec::new(),
            seq: 0,
            index_m: None,
            last_x_m: 0.0,
        }
    }

    fn say(&mut self, m: Message) {
        let mut buf = [0u8; MAX_FRAME];
        let n = encode(self.seq, &m, &mut buf).unwrap();
        self.seq += 1;
        self.rx.extend(&buf[..n]);
    }

    fn heard(&mut self) -> Vec<Message> {
        let mut out = Vec::new();
        Decoder::new().feed(&std::mem::take(&mut self.tx), |e| out.push(e.msg));
        out
    }

    /// The force the amplifier applies (N, resisting positive motion).
    fn force_n(&self) -> f64 {
        if self.outputs {
            IoScale::EXCALIBUR.force_n(self.duty) as f64
        } else {
            0.0
        }
    }
}

impl BoardSupport for Bench {
    fn sample(&mut self) -> RawSensors {
        // The plant moves for one period under the force held last tick.
        let f_a = self.force_n();
        self.peak_force_n = self.peak_force_n.max(f_a.abs());
        let h = T as f64 / 50.0;
        for _ in 0..50 {
            let mut f = -f_a - 4.0 * self.v_mps;
            if let Some(s) = self.stop_m {
                if self.x_m < s {
                    f += 2.0e5 * (s - self.x_m) - 50.0 * self.v_mps;
                }
            }
            self.v_mps += f / 0.93 * h;
            self.x_m += self.v_mps * h;
        }
        let counts = (self.x_m * 1e6).round() as i64;
        // The index pulse latches the count at its mark when the axis
        // passes it.
        let index_raw = self.index_m.and_then(|m| {
            let crossed = (self.last_x_m - m) * (self.x_m - m) <= 0.0 && self.last_x_m != self.x_m;
            crossed.then(|| ((m * 1e6).round() as i64 as u32) & 0xFFFF)
        });
        self.last_x_m = self.x_m;
        RawSensors {
            encoder_raw: [(counts as u32) & 0xFFFF],
            load_cell_counts: [0],
            dead_man_closed: self.dead_man_closed,
            index_raw: [index_raw],
        }
    }
    fn set_duty(&mut self, [duty]: [i16; 1]) {
        self.duty = duty;
    }
    fn set_outputs(&mut self, on: bool) {
        self.outputs = on;
        self.outputs_calls.push(on);
    }
    fn feed_watchdog(&mut self) {}
    fn cycles_per_tick(&self) -> u32 {
        0
    }
    fn read_byte(&mut self) -> Option<u8> {
        self.rx.pop_front()
    }
    fn write(&mut self, bytes: &[u8]) {
        self.tx.extend_from_slice(bytes);
    }
    fn cycles(&mut self) -> u32 {
        0
    }
}

/// What an image's interrupt and main loop do for one tick.
fn tick(b: &mut TestBoard, io: &mut Bench) {
    b.poll_link(io);
    b.control_tick(io);
    b.flush(io);
}

/// A board whose homing ends on an index mark at -12 mm, 8 mm above its
/// stop at -20 mm.
fn board_homing_to_an_index() -> TestBoard {
    let mut cfg = HomingConfig::gentle(Position::from_nm(-20_000_000), T);
    cfg.index_position = Some(Position::from_nm(-12_000_000));
    board().with_homing([cfg])
}

/// One tick at power-on, then the host asks the board to home.
fn start_homing(b: &mut TestBoard, io: &mut Bench) {
    tick(b, io);
    io.say(Message::Home);
}

/// Tell the board it stands at 0, and tick once (so it has read its
/// dead-man switch).
fn calibrate_at_rest(b: &mut TestBoard, io: &mut Bench) {
    io.say(Message::Calibrate {
        position_pm: Axes::one(0),
    });
    tick(b, io);
}

/// Ask the board to arm and tick once; what it answered.
fn ask_to_arm(b: &mut TestBoard, io: &mut Bench) -> Vec<Message> {
    io.say(Message::Arm);
    tick(b, io);
    io.heard()
}

fn refused(msgs: &[Message]) -> Vec<(ModeRequest, ModeRefusal)> {
    msgs.iter()
        .filter_map(|m| match m {
            Message::ModeRefused { asked, why } => Some((*asked, *why)),
            _ => None,
        })
        .collect()
}

fn statuses(msgs: &[Message]) -> Vec<Status> {
    msgs.iter()
        .filter_map(|m| match m {
            Message::Status(s) => Some(*s),
            _ => None,
        })
        .collect()
}

#[test]
fn boots_disarmed_with_outputs_off_and_names_why_it_will_not_arm() {
    let mut b = board();
    let mut io = Bench::new(None);
    assert_eq!(b.mode(), BoardMode::Disarmed);
    assert!(!b.outputs_on() && !b.calibrated());
    // Before any tick the dead-man is unknown; before calibration it may
    // not arm at all. The first reason that holds is the one named.
    assert_eq!(
        refused(&ask_to_arm(&mut b, &mut io)),
        [(ModeRequest::Arm, ModeRefusal::NotCalibrated)]
    );
    io.say(Message::Calibrate {
        position_pm: Axes::one(0),
    });
    io.dead_man_closed = false;
    tick(&mut b, &mut io);
    assert_eq!(
        refused(&ask_to_arm(&mut b, &mut io)),
        [(ModeRequest::Arm, ModeRefusal::DeadManOpen)]
    );
    // Displaced 1 mm from the constraint it was calibrated at, the
    // disarmed board still commands nothing and its outputs stay off.
    io.x_m = 0.001;
    for _ in 0..20 {
        tick(&mut b, &mut io);
    }
    assert_eq!(io.duty, 0);
    assert!(io.outputs_calls.is_empty());
    io.dead_man_closed = true;
    tick(&mut b, &mut io);
    let msgs = ask_to_arm(&mut b, &mut io);
    assert_eq!(refused(&msgs), []);
    assert_eq!(
        statuses(&msgs),
        [Status {
            mode: BoardMode::Armed,
            calibrated: true,
            faults: 0,
            first_fault: 0,
            session: twoport_link::NO_SESSION,
        }]
    );
    assert_eq!(io.outputs_calls, [true]);
}

#[test]
fn gains_outside_the_proven_region_never_arm() {
    // An image built with gains its region does not hold.
    let mut b = board_with(60_000.0);
    let mut io = Bench::new(None);
    calibrate_at_rest(&mut b, &mut io);
    assert_eq!(
        refused(&ask_to_arm(&mut b, &mut io)),
        [(ModeRequest::Arm, ModeRefusal::GainsNotProven)]
    );
    assert_eq!(b.mode(), BoardMode::Disarmed);
}

/// Armed and pushing, the dead-man opens: the fault latches, the board
/// disarms and its outputs go off in that same tick, the status names the
/// fault, and neither arming nor clearing brings the force back alone.
#[test]
fn any_fault_disarms_and_latches_until_cleared_and_re_armed() {
    let mut b = board();
    let mut io = Bench::new(None);
    calibrate_at_rest(&mut b, &mut io);
    io.say(Message::Arm);
    for k in 0..400 {
        tick(&mut b, &mut io);
        // Pull the handle 2 mm out at 10 mm/s and hold it there, against
        // the coupling.
        io.x_m = (k as f64 * 1e-5).min(0.002);
        io.v_mps = 0.0;
    }
    assert_eq!(b.mode(), BoardMode::Armed);
    assert!(io.force_n().abs() > 50.0, "{} N", io.force_n());
    io.heard();
    io.dead_man_closed = false;
    tick(&mut b, &mut io);
    assert_eq!(b.mode(), BoardMode::Disarmed);
    assert_eq!(io.force_n(), 0.0);
    assert_eq!(
        (io.duty, io.outputs_calls.as_slice()),
        (0, &[true, false][..])
    );
    let msgs = io.heard();
    let s = statuses(&msgs);
    assert_eq!(s.len(), 1);
    assert_eq!(s[0].mode, BoardMode::Disarmed);
    assert_eq!(Faults(s[0].faults), Faults::DEAD_MAN);
    assert_eq!(Faults(s[0].faults).to_string(), "dead-man switch released");
    io.dead_man_closed = true;
    assert_eq!(
        refused(&ask_to_arm(&mut b, &mut io)),
        [(
            ModeRequest::Arm,
            ModeRefusal::Faulted {
                faults: Faults::DEAD_MAN.0
            }
        )]
    );
    io.say(Message::ClearFaults);
    tick(&mut b, &mut io);
    assert_eq!(b.mode(), BoardMode::Disarmed);
    io.say(Message::Arm);
    tick(&mut b, &mut io);
    assert_eq!(b.mode(), BoardMode::Armed, "{:?}", io.heard());
}

/// The stop is 15 mm below where the axis powered on, and the board's
/// frame puts it at -20 mm. Homing finds it without ever pushing harder
/// than its 5 N, calibrates the encoder and leaves the board disarmed;
/// from then on the board's positions are the truth less 5 mm, to within
/// the stop's give under 5 N and a count.
#[test]
fn homing_finds_the_stop_gently_and_calibrates_the_encoder() {
    let mut b = board();
    let mut io = Bench::new(Some(-0.015));
    start_homing(&mut b, &mut io);
    let mut ticks = 0;
    loop {
        tick(&mut b, &mut io);
        ticks += 1;
        if b.mode() != BoardMode::Homing || ticks > 5000 {
            break;
        }
    }
    assert!(b.calibrated(), "after {ticks} ticks: {:?}", io.heard());
    assert_eq!(b.mode(), BoardMode::Disarmed);
    assert!(b.servo().safety().faults().is_empty());
    // 15 mm at 20 mm/s, the stall time and the ramp-in.
    assert!((800..1100).contains(&ticks), "{ticks} ticks");
    assert!(io.peak_force_n <= 5.0 + 0.01, "{} N", io.peak_force_n);
    assert_eq!(io.outputs_calls, [true, false]);
    let s = statuses(&io.heard());
    assert_eq!(
        s.iter().map(|s| (s.mode, s.calibrated)).collect::<Vec<_>>(),
        [(BoardMode::Homing, false), (BoardMode::Disarmed, true)]
    );
    // Walk the axis back to where it powered on, at 15 mm/s: the board
    // reads -5 mm.
    let from = io.x_m;
    for k in 1..=1000 {
        io.x_m = from * (1.0 - k as f64 / 1000.0);
        io.v_mps = 0.0;
        tick(&mut b, &mut io);
    }
    let err_nm = b.last_output().position[0].nm() - -5_000_000;
    assert!(err_nm.abs() <= 30_000, "{err_nm} nm");
    // Homed, it arms.
    io.say(Message::Arm);
    tick(&mut b, &mut io);
    assert_eq!(b.mode(), BoardMode::Armed);
}

#[test]
fn homing_without_a_stop_times_out_as_a_named_fault() {
    let mut cfg = HomingConfig::gentle(Position::ZERO, T);
    cfg.timeout_s = 0.5;
    let mut b = board().with_homing([cfg]);
    let mut io = Bench::new(None);
    start_homing(&mut b, &mut io);
    for _ in 0..600 {
        tick(&mut b, &mut io);
    }
    assert_eq!(b.mode(), BoardMode::Disarmed);
    assert!(!b.calibrated());
    assert_eq!(b.servo().safety().faults(), Faults::HOMING_FAILED);
    assert_eq!(io.force_n(), 0.0);
    let msgs = io.heard();
    assert!(msgs.iter().any(|m| matches!(m, Message::FaultReport { faults, .. } if Faults(*faults) == Faults::HOMING_FAILED)));
    assert_eq!(
        Faults::HOMING_FAILED.to_string(),
        "homing found no hard stop"
    );
}

/// Requests that would move an armed or homing board are refused, and a
/// `Disarm` ends a homing run where it is.
#[test]
fn calibrate_and_home_need_a_disarmed_board_and_disarm_stops_homing() {
    let mut b = board();
    let mut io = Bench::new(Some(-0.015));
    start_homing(&mut b, &mut io);
    tick(&mut b, &mut io);
    assert_eq!(b.mode(), BoardMode::Homing);
    io.say(Message::Calibrate {
        position_pm: Axes::one(0),
    });
    io.say(Message::Home);
    io.say(Message::Arm);
    tick(&mut b, &mut io);
    let busy = ModeRefusal::NotDisarmed {
        mode: BoardMode::Homing,
    };
    assert_eq!(
        refused(&io.heard()),
        [
            (ModeRequest::Calibrate, busy),
            (ModeRequest::Home, busy),
            (ModeRequest::Arm, busy),
        ]
    );
    for _ in 0..100 {
        tick(&mut b, &mut io);
    }
    io.say(Message::Disarm);
    tick(&mut b, &mut io);
    assert_eq!((b.mode(), b.calibrated()), (BoardMode::Disarmed, false));
    assert_eq!(io.force_n(), 0.0);
    // A position beyond the board's range is refused by name.
    io.say(Message::Calibrate {
        position_pm: Axes::one(3_000_000_000_000_000),
    });
    tick(&mut b, &mut io);
    assert_eq!(
        refused(&io.heard()),
        [(ModeRequest::Calibrate, ModeRefusal::OutOfRange)]
    );
}

/// An encoder with an index mark 6 mm below where the axis powered on,
/// and the board's frame putting the mark at -12 mm: homing creeps toward
/// the stop, stops at the first index pulse and calibrates from the count
/// the pulse latched, to the count, long before the stop (15 mm down).
#[test]
fn homing_on_an_index_pulse_calibrates_to_the_count_before_the_stop() {
    let mut b = board_homing_to_an_index();
    let mut io = Bench::new(Some(-0.015));
    io.index_m = Some(-0.006);
    start_homing(&mut b, &mut io);
    let mut ticks = 0;
    while ticks < 5000 {
        tick(&mut b, &mut io);
        ticks += 1;
        if b.mode() != BoardMode::Homing {
            break;
        }
    }
    assert!(b.calibrated(), "{:?}", io.heard());
    assert!(b.servo().safety().faults().is_empty());
    // 6 mm at 20 mm/s and the ramp-in: well before the stop.
    assert!((250..600).contains(&ticks), "{ticks} ticks");
    assert!(io.x_m > -0.0075, "stopped at {} m", io.x_m);
    // The board's frame is the truth less 6 mm, to the count, from the
    // next tick on.
    tick(&mut b, &mut io);
    let err_nm = b.last_output().position[0].nm() - ((io.x_m * 1e9).round() as i32 - 6_000_000);
    assert!(err_nm.abs() <= 1_000, "{err_nm} nm");
}

/// Homing on an index that never comes: the stall on the stop is a
/// failure, not a calibration.
#[test]
fn homing_on_an_index_that_never_pulses_fails_at_the_stop() {
    let mut b = board_homing_to_an_index();
    let mut io = Bench::new(Some(-0.015));
    start_homing(&mut b, &mut io);
    for _ in 0..3000 {
        tick(&mut b, &mut io);
    }
    assert!(!b.calibrated());
    assert_eq!(b.servo().safety().faults(), Faults::HOMING_FAILED);
    assert_eq!(b.mode(), BoardMode::Disarmed);
}

/// An experiment the test boards can play: 5 N of harmonics 1 to 20 of
/// 200 ticks, three periods, held by 2,000 N/m and 30 N s/m.
fn experiment() -> twoport_link::ExperimentRequest {
    twoport_link::ExperimentRequest {
        axis: 0,
        period_ticks: 200,
        first: 1,
        last: 20,
        amplitude_n: twoport_control::multisine::Multisine::new(200, 1, 20, 5.0)
            .unwrap()
            .amplitude(),
        peak_n: 5.0,
        periods: 3,
        hold_k_npm: 2_000.0,
        hold_b_nspm: 30.0,
    }
}

fn telemetry(msgs: &[Message]) -> Vec<twoport_link::Telemetry> {
    msgs.iter()
        .filter_map(|m| match m {
            Message::Telemetry(t) => Some(*t),
            _ => None,
        })
        .collect()
}

/// Armed, the board plays the experiment: telemetry every tick (the
/// board sends none otherwise), the actuator's force the hold minus the
/// multisine, the same multisine each period, and at the end of the last
/// period it disarms, outputs off.
#[test]
fn an_armed_board_plays_an_experiment_and_disarms_at_its_end() {
    let mut b = board();
    let mut io = Bench::new(None);
    calibrate_at_rest(&mut b, &mut io);
    assert_eq!(refused(&ask_to_arm(&mut b, &mut io)), []);
    // Past the arming ramp, so that every tick's force is the law's.
    for _ in 0..SafetyConfig::excalibur().ramp_ticks {
        tick(&mut b, &mut io);
    }
    io.heard();
    io.say(Message::Identify(experiment()));
    let mut heard = Vec::new();
    for _ in 0..700 {
        tick(&mut b, &mut io);
        heard.extend(io.heard());
    }
    let modes: Vec<BoardMode> = statuses(&heard).iter().map(|s| s.mode).collect();
    assert_eq!(modes, [BoardMode::Identifying, BoardMode::Disarmed]);
    let t = telemetry(&heard);
    assert_eq!(t.len(), 600, "one frame per tick of the experiment");
    assert!(t.windows(2).all(|w| w[1].tick == w[0].tick + 1));
    assert!(t.iter().all(|t| t.mode == BoardMode::Identifying));
    let m = twoport_control::multisine::Multisine::new(200, 1, 20, 5.0).unwrap();
    for (n, t) in t.iter().enumerate() {
        let a = t.axes[0];
        let hold = 2_000.0 * (a.position_pm as f32 * 1e-12) + 30.0 * a.velocity_mps;
        let want = hold - m.at(n as u32);
        assert!(
            (a.actuator_n - want).abs() < 1e-3,
            "tick {n}: {} against {want}",
            a.actuator_n
        );
    }
    assert_eq!(
        (b.mode(), io.duty, io.outputs),
        (BoardMode::Disarmed, 0, false)
    );
    assert!(b.experiment().is_none());
}

/// Every condition is named: a disarmed board, a band past Nyquist, a
/// peak past the continuous force, a hold outside the proven region, an
/// axis the board lacks. None of them changes the mode.
#[test]
fn an_experiment_is_refused_with_the_reason() {
    let mut b = board();
    let mut io = Bench::new(None);
    calibrate_at_rest(&mut b, &mut io);
    io.say(Message::Identify(experiment()));
    tick(&mut b, &mut io);
    assert_eq!(
        refused(&io.heard()),
        [(
            ModeRequest::Identify,
            ModeRefusal::NotArmed {
                mode: BoardMode::Disarmed
            }
        )]
    );
    assert_eq!(refused(&ask_to_arm(&mut b, &mut io)), []);
    let bad = [
        twoport_link::ExperimentRequest {
            last: 100,
            ..experiment()
        },
        twoport_link::ExperimentRequest {
            peak_n: 1e4,
            ..experiment()
        },
        // An amplitude whose rms is past the peak the host claims.
        twoport_link::ExperimentRequest {
            amplitude_n: 5.0,
            ..experiment()
        },
        twoport_link::ExperimentRequest {
            hold_k_npm: 60_000.0,
            ..experiment()
        },
        twoport_link::ExperimentRequest {
            hold_b_nspm: f32::NAN,
            ..experiment()
        },
        twoport_link::ExperimentRequest {
            axis: 1,
            ..experiment()
        },
        twoport_link::ExperimentRequest {
            periods: 0,
            ..experiment()
        },
    ];
    for x in bad {
        io.say(Message::Identify(x));
        tick(&mut b, &mut io);
        assert_eq!(
            refused(&io.heard()),
            [(ModeRequest::Identify, ModeRefusal::BadExperiment)],
            "{x:?}"
        );
        assert_eq!(b.mode(), BoardMode::Armed);
    }
}

/// The dead-man opens halfway: zero force at once, disarmed, the fault
/// named, and the experiment over.
#[test]
fn releasing_the_handle_ends_an_experiment_at_zero_force() {
    let mut b = board();
    let mut io = Bench::new(None);
    calibrate_at_rest(&mut b, &mut io);
    assert_eq!(refused(&ask_to_arm(&mut b, &mut io)), []);
    io.say(Message::Identify(experiment()));
    for _ in 0..300 {
        tick(&mut b, &mut io);
    }
    assert_eq!(b.mode(), BoardMode::Identifying);
    assert!(io.force_n().abs() > 0.5, "{} N", io.force_n());
    io.dead_man_closed = false;
    tick(&mut b, &mut io);
    assert_eq!((b.mode(), io.force_n()), (BoardMode::Disarmed, 0.0));
    assert!(b.experiment().is_none());
    let s = statuses(&io.heard());
    assert_eq!(Faults(s.last().unwrap().faults), Faults::DEAD_MAN);
}
