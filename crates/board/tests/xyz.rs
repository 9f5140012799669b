//! The three-axis Excalibur image's loop on a bench of three axes: it
//! declares three axes, homes every axis onto its own stop, refuses gains
//! and calibrations per axis with the axis named, zeroes every axis when
//! one faults, and stores every axis's configuration in one record.

use twoport_board::excalibur::xyz::{self, XyzBoard};
use twoport_board::{BoardSupport, IoScale, RawSensors};
use twoport_config::{RamFlash, Store};
use twoport_control::Faults;
use twoport_link::{
    encode, Axes, AxisRefusal, BoardMode, ConfigFallback, ConfigSource, Decoder, Gains, GainsReply,
    Message, ModeRefusal, ModeRequest, Refusal, Role, MAX_FRAME,
};

const T: f64 = 1e-3;

/// Three independent axes, as the one-axis arming bench's: 0.93 kg, 4 N s/m,
/// a hard stop (2e5 N/m) `stop_m` below where each powered on, 16-bit 1 µm
/// encoders that read 0 at power-on, one dead-man switch, and the link.
struct Bench {
    x_m: [f64; 3],
    v_mps: [f64; 3],
    stop_m: [f64; 3],
    duty: [i16; 3],
    outputs: bool,
    peak_force_n: f64,
    /// Makes axis 1's encoder read a count its counter cannot hold.
    broken_encoder: bool,
    rx: std::collections::VecDeque<u8>,
    tx: Vec<u8>,
}

impl Bench {
    fn new(stop_m: [f64; 3]) -> Self {
        Bench {
            x_m: [0.0; 3],
            v_mps: [0.0; 3],
            stop_m,
            duty: [0; 3],
            outputs: false,
            peak_force_n: 0.0,
            broken_encoder: false,
            rx: Default::default(),
            tx: Vec::new(),
        }
    }

    fn say(&mut self, m: Message) {
        let mut buf = [0u8; MAX_FRAME];
        let n = encode(0, &m, &mut buf).unwrap();
        self.rx.extend(&buf[..n]);
    }

    fn heard(&mut self) -> Vec<Message> {
        let mut out = Vec::new();
        Decoder::new().feed(&std::mem::take(&mut self.tx), |e| out.push(e.msg));
        out
    }

    fn force_n(&self, axis: usize) -> f64 {
        match self.outputs {
            true => IoScale::EXCALIBUR.force_n(self.duty[axis]) as f64,
            false => 0.0,
        }
    }
}

impl BoardSupport<3> for Bench {
    fn sample(&mut self) -> RawSensors<3> {
        let mut raw = [0u32; 3];
        for (a, r) in raw.iter_mut().enumerate() {
            let f_a = self.force_n(a);
            self.peak_force_n = self.peak_force_n.max(f_a.abs());
            let h = T / 50.0;
            for _ in 0..50 {
                let mut f = -f_a - 4.0 * self.v_mps[a];
                if self.x_m[a] < self.stop_m[a] {
                    f += 2.0e5 * (self.stop_m[a] - self.x_m[a]) - 50.0 * self.v_mps[a];
                }
                self.v_mps[a] += f / 0.93 * h;
                self.x_m[a] += self.v_mps[a] * h;
            }
            *r = ((self.x_m[a] * 1e6).round() as i64 as u32) & 0xFFFF;
        }
        if self.broken_encoder {
            raw[1] = 0x1_0000;
        }
        RawSensors {
            encoder_raw: raw,
            load_cell_counts: [0; 3],
            dead_man_closed: true,
            index_raw: [None; 3],
        }
    }
    fn set_duty(&mut self, duty: [i16; 3]) {
        self.duty = duty;
    }
    fn set_outputs(&mut self, on: bool) {
        self.outputs = on;
    }
    fn feed_watchdog(&mut self) {}
    fn read_byte(&mut self) -> Option<u8> {
        self.rx.pop_front()
    }
    fn write(&mut self, bytes: &[u8]) {
        self.tx.extend_from_slice(bytes);
    }
    fn cycles(&mut self) -> u32 {
        0
    }
    fn cycles_per_tick(&self) -> u32 {
        0
    }
}

/// One tick, with the host's heartbeat.
fn tick(b: &mut XyzBoard, io: &mut Bench) {
    io.say(Message::Heartbeat);
    b.poll_link(io);
    b.control_tick(io);
    b.flush(io);
}

fn board() -> XyzBoard {
    xyz::board().unwrap()
}

/// The image on a bench whose axes reach no stop, after its first tick.
fn booted() -> (XyzBoard, Bench) {
    let mut b = board();
    let mut io = Bench::new([-1.0; 3]);
    tick(&mut b, &mut io);
    (b, io)
}

fn refusals(io: &mut Bench) -> Vec<(ModeRequest, ModeRefusal)> {
    io.heard()
        .into_iter()
        .filter_map(|m| match m {
            Message::ModeRefused { asked, why } => Some((asked, why)),
            _ => None,
        })
        .collect()
}

/// The world's start, where a host calibrates a board that powered on
/// there.
fn start_pm() -> Axes<i64> {
    let x = xyz::world().unwrap().cursor();
    Axes::new(x.map(|p| p.nm() as i64 * 1000)).unwrap()
}

#[test]
fn the_board_declares_three_axes_and_a_one_axis_host_is_refused() {
    let mut b = board();
    let mut io = Bench::new([-1.0; 3]);
    let mut ack = |host| {
        io.say(Message::hello(Role::Host, host, 9));
        tick(&mut b, &mut io);
        io.heard()
            .into_iter()
            .find(|m| matches!(m, Message::HelloAck { .. }))
            .expect("the board answers a hello")
    };
    assert!(ack(3).accept_ack(3, 9).is_ok());
    let one = ack(1);
    assert!(matches!(
        one,
        Message::HelloAck {
            accepted: false,
            axes: 3,
            ..
        }
    ));
    let e = one.accept_ack(1, 9).unwrap_err().to_string();
    assert!(e.contains('3') && e.contains('1'), "{e}");
}

/// Every axis homes at once onto its own stop, each ending where its stop
/// is in the world's frame, and the board is calibrated only when all
/// three have: with at most the homing force on any axis throughout.
#[test]
fn every_axis_homes_onto_its_own_stop() {
    let mut b = board();
    let stops = [-0.004, -0.009, -0.002];
    let mut io = Bench::new(stops);
    tick(&mut b, &mut io);
    io.say(Message::Home);
    let mut homed_at = None;
    for k in 0..3000 {
        tick(&mut b, &mut io);
        if b.calibrated() {
            homed_at = Some(k);
            break;
        }
        assert_eq!(b.mode(), BoardMode::Homing, "tick {k}: {:?}", io.heard());
    }
    let k = homed_at.expect("homed within 3 s");
    // The slowest axis creeps 9 mm at 20 mm/s, then waits out its stall.
    assert!(k > 400, "homed after {k} ticks");
    assert_eq!(b.mode(), BoardMode::Disarmed);
    assert!(io.peak_force_n <= 5.0 + 0.01, "{} N", io.peak_force_n);
    // One more tick to read the calibrated positions.
    tick(&mut b, &mut io);
    let x = b.last_output().position;
    for a in 0..3 {
        let want_nm = xyz::HOMING[a].stop_position.nm() as f64 + (io.x_m[a] - stops[a]) * 1e9;
        let err_um = (x[a].nm() as f64 - want_nm) / 1e3;
        assert!(err_um.abs() < 50.0, "axis {a}: {err_um} um off");
    }
}

#[test]
fn calibration_and_gains_are_refused_per_axis_by_name() {
    let (mut b, mut io) = booted();
    io.say(Message::Calibrate {
        position_pm: Axes::one(0),
    });
    tick(&mut b, &mut io);
    assert_eq!(
        refusals(&mut io),
        [(
            ModeRequest::Calibrate,
            ModeRefusal::WrongAxisCount { axes: 3 }
        )]
    );
    assert!(!b.calibrated());
    let g = |k_npm| Gains::impedance(k_npm, 90.0);
    let before = b.config();
    io.say(Message::SetGains(
        Axes::new([g(25_000.0), g(90_000.0), g(25_000.0)]).unwrap(),
    ));
    io.say(Message::SetGains(Axes::one(g(25_000.0))));
    tick(&mut b, &mut io);
    let replies: Vec<_> = io
        .heard()
        .into_iter()
        .filter_map(|m| match m {
            Message::GainsReply(GainsReply::Refused(r)) => Some(r),
            _ => None,
        })
        .collect();
    assert_eq!(replies.len(), 2, "{replies:?}");
    assert_eq!(replies[0].axis, 1);
    assert!(matches!(replies[0].why, Refusal::NotProvenStable { .. }));
    assert_eq!(
        replies[1],
        AxisRefusal {
            axis: 0,
            why: Refusal::WrongAxisCount { axes: 3 }
        }
    );
    assert_eq!(b.config(), before, "a refused change changes no axis");
    io.say(Message::SetGains(Axes::new([g(25_000.0); 3]).unwrap()));
    tick(&mut b, &mut io);
    assert!(b.config().iter().all(|c| c.gains == g(25_000.0)));
}

/// Armed, with the hand pressing the cursor into the cube's face along x
/// and into the floor along z, a bad count on the idle y axis alone gives
/// zero force on all three in that tick, and disarms.
#[test]
fn a_fault_on_one_axis_zeroes_every_axis() {
    let (mut b, mut io) = booted();
    io.say(Message::Calibrate {
        position_pm: start_pm(),
    });
    io.say(Message::Arm);
    tick(&mut b, &mut io);
    assert_eq!(b.mode(), BoardMode::Armed, "{:?}", io.heard());
    // The cube's face is 39 mm along x from the cursor's centre, the
    // floor 9 mm below it: the hand goes 1.5 mm and 2 mm past them.
    for k in 0..400 {
        let s = (k as f64 / 300.0).min(1.0);
        io.x_m = [0.0405 * s, 0.0, -0.011 * s];
        io.v_mps = [0.0; 3];
        tick(&mut b, &mut io);
    }
    let d = b.duty();
    assert!(d[0] > 100 && d[2] < -100, "{d:?}");
    io.broken_encoder = true;
    tick(&mut b, &mut io);
    assert_eq!(b.duty(), [0; 3]);
    assert_eq!(b.mode(), BoardMode::Disarmed);
    assert!(b.last_output().faults.contains(Faults::ENCODER_INVALID));
}

#[test]
fn every_axis_is_stored_in_one_record() {
    type Flash = RamFlash<512, 256>;
    let mut b = board();
    let mut st = Store::new(Flash::new(), 0, 256);
    assert_eq!(
        b.boot_config(&mut st),
        ConfigSource::Defaults {
            why: ConfigFallback::Missing
        }
    );
    let mut io = Bench::new([-1.0; 3]);
    let z = Gains::impedance(30_000.0, 60.0);
    let mut g = b.config().map(|c| c.gains);
    g[2] = z;
    io.say(Message::SetGains(Axes::new(g).unwrap()));
    io.say(Message::SaveConfig);
    tick(&mut b, &mut io);
    b.service_config(&mut st);
    let saved = b.config();
    let mut again = board();
    assert_eq!(again.boot_config(&mut st), ConfigSource::Stored { seq: 1 });
    assert_eq!(again.config(), saved);
    assert_eq!(again.config()[2].gains, z);
    // A one-axis board's record is not run here, and the reason says why.
    let mut one = Store::new(Flash::new(), 0, 256);
    one.save(&saved[0]).unwrap();
    assert_eq!(
        board().boot_config(&mut one),
        ConfigSource::Defaults {
            why: ConfigFallback::WrongAxes { found: 1 }
        }
    );
}
