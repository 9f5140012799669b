//! The device object on the shipped Excalibur image, run in-process on a
//! simulated device, one tick per read: the same run on every machine.

use std::time::Duration;
use twoport_board::excalibur;
use twoport_control::Faults;
use twoport_host::{HostBoard, LinkError, Pace, SimulatedBoard};
use twoport_link::{BoardMode, Contact, Gains, ProvenRegion, Refusal, VeSource};

/// The wall the host's VE renders (m): solid above.
const WALL_M: f64 = 0.005;

/// The image's coupling stiffness (N/m).
fn k_c() -> f64 {
    f64::from(excalibur::COUPLING.k_npm)
}

fn open(hand_n: f32) -> HostBoard<SimulatedBoard> {
    HostBoard::open(
        SimulatedBoard::excalibur(hand_n, Pace::PerRead(1)).unwrap(),
        1,
    )
    .unwrap()
}

/// An application opens the board, reads what it can prove, calibrates,
/// hands the VE to the host, arms, and sends a wall at 5 mm (solid above)
/// at 1 kHz against a hand pushing 2 N: the handle stops at the wall,
/// pressed in by the coupling's spring (2 N / 43,500 N/m = 46 um), and
/// the board holds every update it was sent.
#[test]
fn an_application_renders_a_wall_from_the_host_and_lets_go() {
    let mut b = open(2.0);
    let spec = *b.spec();
    assert_eq!(
        (b.axes(), spec.period_ns, spec.ve),
        (1, 1_000_000, VeSource::Board)
    );
    let ProvenRegion::MaxStiffness { k_max_npm, .. } = spec.axes[0].region else {
        panic!("{spec:?}")
    };
    assert!(f64::from(k_max_npm) > k_c());
    assert_eq!(spec.latency_budget_s, excalibur::region::LATENCY_S);
    b.calibrate(&[0.0]).unwrap();
    b.stream(1).unwrap();
    b.host_ve(1, 20).unwrap();
    assert_eq!(b.arm().unwrap().mode, BoardMode::Armed);
    b.take_states();
    let mut sent = 0;
    for _ in 0..3000 {
        b.poll().unwrap();
        sent = b.send_ve(&[WALL_M], &[Contact::Above]).unwrap();
    }
    let states = b.take_states();
    let deepest = states
        .iter()
        .map(|s| s.axes[0].position_m)
        .fold(f64::MIN, f64::max);
    // It meets the wall at some speed; the wall stops it within the
    // spring's share of that energy, ½ m v² = ½ k d², past the press.
    let hit = states
        .iter()
        .find(|s| s.axes[0].position_m > WALL_M)
        .unwrap();
    let reach = hit.axes[0].velocity_mps * (0.93 / k_c()).sqrt();
    let last = states.last().unwrap();
    assert_eq!((last.mode, last.faults), (BoardMode::Armed, 0));
    let x = last.axes[0].position_m;
    let press = 2.0 / k_c();
    assert!((x - WALL_M - press).abs() < 10e-6, "at {x} m");
    assert!(
        deepest < WALL_M + press + reach,
        "{deepest} m deep, {reach} m of reach"
    );
    // The board holds the update sent one or two reads before.
    assert!(sent - last.ve_seq <= 2, "{sent} sent, {} held", last.ve_seq);
    assert!((last.axes[0].ve_position_m - WALL_M).abs() < 1e-9);
    b.close().unwrap();
}

/// A host that stops sending its VE: the board holds the last update for
/// its deadline, then gives zero force and disarms, and the object's next
/// call that waits on the board says which fault latched.
#[test]
fn a_host_that_falls_silent_gets_zero_force_not_a_stale_wall() {
    let mut b = open(0.0);
    b.calibrate(&[0.0]).unwrap();
    b.stream(1).unwrap();
    b.host_ve(1, 20).unwrap();
    b.arm().unwrap();
    b.send_ve(&[0.001], &[Contact::Held]).unwrap();
    for _ in 0..60 {
        b.poll().unwrap();
    }
    let states = b.take_states();
    let faulted = states
        .iter()
        .position(|s| s.faults & Faults::VE_STALE.0 != 0)
        .unwrap();
    // Pulled toward the point until the deadline, then nothing.
    assert!(states[..faulted]
        .iter()
        .any(|s| s.axes[0].actuator_n.abs() > 1.0));
    assert!(states[faulted..]
        .iter()
        .all(|s| s.axes[0].actuator_n == 0.0));
    assert_eq!(states.last().unwrap().mode, BoardMode::Disarmed);
    let e = b.home(Duration::from_secs(1)).unwrap_err();
    assert!(e.to_string().contains("host VE late"), "{e}");
}

/// Calls that cannot be right are refused by name before anything is
/// sent, and the board's refusals come back with its reason.
#[test]
fn wrong_calls_are_named_and_refusals_carry_the_boards_reason() {
    let mut b = open(0.0);
    let e = b.calibrate(&[0.0, 0.0]).unwrap_err();
    assert!(
        matches!(
            e,
            LinkError::Axes {
                given: 2,
                board: 1,
                ..
            }
        ),
        "{e}"
    );
    let e = b.send_ve(&[f64::NAN], &[Contact::Held]).unwrap_err();
    assert!(e.to_string().contains("outside the board's range"), "{e}");
    let e = b.send_ve(&[0.0], &[]).unwrap_err();
    assert!(e.to_string().contains("contact"), "{e}");
    let e = b.send_ve(&[3.0], &[Contact::Held]).unwrap_err();
    assert!(e.to_string().contains("outside the board's range"), "{e}");
    let e = b
        .set_gains(&[Gains::impedance(80_000.0, 90.0)])
        .unwrap_err();
    assert!(
        matches!(e, LinkError::GainsRefused(r) if matches!(r.why, Refusal::NotProvenStable { .. })),
        "{e}"
    );
    // Arming uncalibrated.
    let e = b.arm().unwrap_err();
    assert!(e.to_string().contains("NotCalibrated"), "{e}");
    // The VE moves only while disarmed.
    b.calibrate(&[0.0]).unwrap();
    b.arm().unwrap();
    let e = b.host_ve(1, 20).unwrap_err();
    assert!(e.to_string().contains("NotDisarmed"), "{e}");
}

/// Homing drives the simulated handle into its stop (30 mm below where it
/// started) and calls the stall the Excalibur image's stop position,
/// -20 mm: the board is calibrated, disarmed, and reads the handle there.
#[test]
fn homing_finds_the_stop_and_calibrates() {
    let mut b = open(2.0);
    let s = b.home(Duration::from_secs(60)).unwrap();
    assert!(s.calibrated && s.mode == BoardMode::Disarmed, "{s:?}");
    b.stream(1).unwrap();
    for _ in 0..20 {
        b.poll().unwrap();
    }
    let x = b.latest().unwrap().axes[0].position_m;
    assert!((x + 0.020).abs() < 1e-5, "at {x} m");
}

/// The board's own wall set from the application: moved to 5 mm, it
/// holds the simulated hand's 2 N there (39 um in, as the host's wall
/// did); a value out of range is named before it is sent, an axis the
/// board has not too, and an armed board refuses.
#[test]
fn the_boards_own_wall_is_set_from_the_host() {
    use twoport_host::VeParam;
    let mut b = open(2.0);
    b.calibrate(&[0.0]).unwrap();
    let e = b.set_ve_param(0, VeParam::Stiffness(-1.0)).unwrap_err();
    assert!(
        e.to_string()
            .contains("VE stiffness (N/m) = -1 must be finite and >= 0"),
        "{e}"
    );
    let e = b.set_ve_param(1, VeParam::Damping(1.0)).unwrap_err();
    assert!(matches!(e, LinkError::Axes { .. }), "{e}");
    let e = VeParam::surface_m(3.0).unwrap_err();
    assert!(e.to_string().contains("VE surface (m) = 3"), "{e}");
    b.set_ve_param(0, VeParam::surface_m(WALL_M).unwrap())
        .unwrap();
    b.stream(1).unwrap();
    b.arm().unwrap();
    for _ in 0..3000 {
        b.poll().unwrap();
    }
    let x = b.latest().unwrap().axes[0].position_m;
    assert!((x - WALL_M - 2.0 / k_c()).abs() < 10e-6, "at {x} m");
    let e = b.set_ve_param(0, VeParam::Damping(1.0)).unwrap_err();
    assert!(e.to_string().contains("NotDisarmed"), "{e}");
}

/// A port whose board answers a `GetGains` only 40 ms after it was asked
/// (a busy link), counting the heartbeats sent meanwhile.
struct Slow {
    inner: SimulatedBoard,
    decoder: twoport_link::Decoder,
    hold_until: Option<std::time::Instant>,
    heartbeats_while_held: usize,
}

impl twoport_host::BoardPort for Slow {
    fn send(&mut self, bytes: &[u8]) -> Result<(), LinkError> {
        let now = std::time::Instant::now();
        let held = self.hold_until.is_some_and(|t| now < t);
        let (mut asked, mut beats) = (false, 0);
        self.decoder.feed(bytes, |e| match e.msg {
            twoport_link::Message::GetGains => asked = true,
            twoport_link::Message::Heartbeat => beats += 1,
            _ => {}
        });
        if held {
            self.heartbeats_while_held += beats;
        }
        if asked {
            self.hold_until = Some(now + Duration::from_millis(40));
        }
        self.inner.send(bytes)
    }

    fn recv(&mut self, buf: &mut [u8], timeout: Duration) -> Result<usize, LinkError> {
        if let Some(t) = self.hold_until {
            let now = std::time::Instant::now();
            if now < t {
                std::thread::sleep(timeout.min(t - now));
                return Ok(0);
            }
        }
        self.inner.recv(buf, timeout)
    }
}

/// While a call waits for a slow answer, the device object keeps the
/// board's watchdog fed: a heartbeat goes out before the answer is taken,
/// whatever the machine's speed (the answer comes 40 ms late, the
/// heartbeats every 10 ms).
#[test]
fn a_call_that_waits_keeps_sending_heartbeats() {
    let port = Slow {
        inner: SimulatedBoard::excalibur(2.0, Pace::PerRead(1)).unwrap(),
        decoder: twoport_link::Decoder::new(),
        hold_until: None,
        heartbeats_while_held: 0,
    };
    let mut b = HostBoard::open(port, 1).unwrap();
    b.gains().unwrap();
    let sent = b.port().heartbeats_while_held;
    assert!(sent >= 1, "{sent} heartbeats while the answer was held");
}
