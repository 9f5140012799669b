//! The Haply 2DIY's driver against its emulator, byte for byte over a
//! pseudo-terminal: the image is the shipped file's and the designer's;
//! the PC's loop holds the image's wall for 10 s at the certified
//! coupling; and every fault a lab meets ends in zero force and a message
//! that says what to do. The emulator's plant advances one period per
//! torque packet, so what is asserted does not depend on the machine's
//! speed (a tick later than the region allows is its own, named, fault).

use host_sim::emulate::haply::{file, Emulator, Fault, Hand};
use std::sync::{Mutex, MutexGuard};
use std::time::{Duration, Instant};
use twoport_board::linkage::haply::{self as image, HAPLY, HAPLY_LINKS};
use twoport_board::linkage::GRASP_NSPM;
use twoport_control::Faults;
use twoport_design::linkage::{certified_design_from, least_damping, Geometry, LinkageFile};
use twoport_host::haply::{open_error, Grip, HaplyConfig};
use twoport_host::{BoardMode, HostBoard, LinkError, PcBoard};

/// The hand of the wall run: a 2 N s/m grasp (the region's least) and a
/// 100 N/m spring pressing 10 mm past the rest pose, 5 mm past the wall.
const HAND: Hand = Hand {
    grasp_nspm: 2.0,
    stiffness_npm: 100.0,
    push_m: 0.010,
};

/// The tests take turns: a loop's thread and the emulator's are the
/// machine's to schedule, and another test at once on two cores would
/// hold their ticks back.
static LOOP: Mutex<()> = Mutex::new(());

fn turn() -> MutexGuard<'static, ()> {
    LOOP.lock().unwrap_or_else(|p| p.into_inner())
}

/// A switch on analog pin 2, as the emulator's hand closes it.
fn config() -> HaplyConfig {
    HaplyConfig::v3(Grip::Pin {
        pin: 2,
        closed_above: 0.5,
    })
}

/// Wait up to `limit` for `done`, polling the board.
fn wait(
    b: &mut HostBoard<PcBoard>,
    limit: Duration,
    mut done: impl FnMut(&mut HostBoard<PcBoard>) -> bool,
) {
    let until = Instant::now() + limit;
    while !done(b) && Instant::now() < until {
        let _ = b.poll();
        std::thread::sleep(Duration::from_millis(2));
    }
}

#[test]
fn the_image_is_the_files_and_the_designers() {
    let _turn = turn();
    let file = file().unwrap();
    let hw = file.hardware::<2>().unwrap();
    assert_eq!(hw, HAPLY.hardware);
    match file.geometry {
        Geometry::Pantograph { l_m, big_l_m, d_m } => {
            let close = |a: f32, b: f64| (f64::from(a) - b).abs() < 1e-6 * b;
            assert!(close(HAPLY_LINKS.l_m, l_m) && close(HAPLY_LINKS.big_l_m, big_l_m));
            assert!(close(HAPLY_LINKS.d_m, d_m));
        }
        ref g => panic!("the 2DIY's file is {g:?}"),
    }
    let least = least_damping(&file).unwrap();
    let claimed = f64::from(HAPLY.least_damping_nspm);
    assert!(claimed <= least.bound && claimed >= 0.999 * least.bound);
    // The region: the designer's proof at 1 kHz and the image's latency,
    // rounded down by less than 0.01 %.
    let at = LinkageFile {
        period_s: 1e-3,
        latency_s: f64::from(image::LATENCY_S),
        ..file
    };
    let r = image::region().unwrap();
    assert_eq!(r.latency_s(), image::LATENCY_S);
    for (b, k) in image::DAMPING_NSPM.iter().zip(image::LIMIT_NPM) {
        let proof = certified_design_from(&at, &least, f64::from(*b), f64::from(GRASP_NSPM), None)
            .unwrap()
            .k_c_npm;
        let k = f64::from(k);
        assert!(
            k <= proof && k >= proof * (1.0 - 1e-4),
            "b {b}: {k} vs {proof}"
        );
    }
    assert!(image::COUPLING.k_npm <= r.limit_at(image::COUPLING.b_nspm).unwrap());
}

/// Open, calibrate at the rest pose, stream and arm: the setup the board
/// read is the one the driver meant.
fn armed(emu: &Emulator) -> HostBoard<PcBoard> {
    let pc = PcBoard::haply(emu.path(), &config()).unwrap();
    let mut b = HostBoard::open(pc, 2).unwrap();
    assert_eq!(b.spec().latency_budget_s, image::LATENCY_S);
    b.calibrate(&HAPLY.rest_rad.map(f64::from)).unwrap();
    b.stream(10).unwrap();
    assert_eq!(b.arm().unwrap().mode, BoardMode::Armed);
    let t = emu.trace();
    let mut sent = config().setup();
    sent.joints.sort_by_key(|j| j.port);
    assert_eq!(t.setup, Some(sent));
    assert_eq!(t.resets, 1);
    b
}

/// The hand presses through the wall 5 mm under the rest pose and rests
/// on it for 10 s (10,000 periods of the device): 1 mm in, where the
/// hand's 0.4 N meet the coupling's 400 N/m, and still. Unless the
/// machine held a tick past the 5 ms the region is proven for: then the
/// board faulted "force late", the loop measured the latency past it, and
/// the motors were sent zero.
#[test]
fn the_driver_holds_the_wall_for_ten_seconds() {
    let _turn = turn();
    let emu = Emulator::start(Some(HAND), None).unwrap();
    let mut b = armed(&emu);
    emu.press();
    let from = emu.ticks();
    let mut faults = 0;
    wait(&mut b, Duration::from_secs(120), |b| {
        faults = b.latest().map_or(0, |s| s.faults);
        faults != 0 || emu.ticks() >= from + 10_000
    });
    let t = emu.trace();
    let worst = b.port().timing().latency_s.max;
    if faults == Faults::LATE_FORCE.0 {
        assert!(
            worst > f64::from(image::LATENCY_S),
            "faulted late at {worst} s"
        );
        std::thread::sleep(Duration::from_millis(50));
        assert_eq!(emu.trace().torque_nm.last(), Some(&[0.0, 0.0]));
        return;
    }
    assert_eq!(faults, 0);
    assert!(t.ticks >= from + 10_000, "{} periods", t.ticks - from);
    let y0 = t.handle_m[0][1];
    let wall = y0 - 0.005;
    let last = &t.handle_m[t.handle_m.len() - 1000..];
    let (lo, hi) = last.iter().fold((f64::MAX, f64::MIN), |(lo, hi), x| {
        (lo.min(x[1]), hi.max(x[1]))
    });
    // 0.43 N on 600 N/m in series with the wall's 100 kN/m, to within
    // the encoders' quantum (0.03 mm at the links' 70 mm).
    let k = f64::from(image::COUPLING.k_npm);
    let press = 0.005 * HAND.stiffness_npm / (HAND.stiffness_npm + k * 100e3 / (100e3 + k));
    let mid = 0.5 * (lo + hi);
    assert!(
        (wall - press - mid).abs() < 0.1e-3,
        "at {} mm",
        (mid - y0) * 1e3
    );
    assert!(
        hi - lo < 0.05e-3,
        "moved {} mm in the last second",
        (hi - lo) * 1e3
    );
    // Force on it: the motors hold the wall.
    let tau = t.torque_nm.last().unwrap();
    assert!(tau.iter().any(|t| t.abs() > 5e-3), "{tau:?}");
    b.disarm().unwrap();
}

/// Each fault of the device mid-run stops the loop with a message saying
/// what happened and what to do, and the motors' last command is zero.
#[test]
fn a_failing_device_gets_zero_force_and_a_named_error() {
    let _turn = turn();
    for (fault, says) in [
        (Fault::Silent, "stopped answering"),
        (Fault::ShortReply, "cut short"),
        (Fault::WrongId, "device id 2 where device 1"),
        (Fault::Unplug, "unplugged"),
    ] {
        let emu = Emulator::start(Some(HAND), Some((300, fault))).unwrap();
        let mut b = armed(&emu);
        emu.press();
        let mut err = None;
        wait(&mut b, Duration::from_secs(60), |b| {
            if let Err(e) = b.poll() {
                err = Some(e);
            }
            err.is_some()
        });
        match err {
            Some(LinkError::Device(why)) => assert!(why.contains(says), "{fault:?}: {why}"),
            e => panic!("{fault:?}: {e:?}"),
        }
        if fault != Fault::Unplug {
            std::thread::sleep(Duration::from_millis(50));
            let t = emu.trace();
            assert_eq!(t.torque_nm.last(), Some(&[0.0, 0.0]), "{fault:?}");
        }
    }
}

/// A port that is not there, held by another program, or not the user's,
/// and a board that never answers its setup, each named at open.
#[test]
fn a_port_that_will_not_open_says_why() {
    let _turn = turn();
    let e = PcBoard::haply("/dev/twoport-no-such-port", &config())
        .err()
        .unwrap();
    assert!(e.to_string().contains("no such port"), "{e}");
    let emu = Emulator::start(Some(HAND), None).unwrap();
    {
        let _other = serialport::new(emu.path(), 115_200).open().unwrap();
        let e = PcBoard::haply(emu.path(), &config()).err().unwrap();
        assert!(e.to_string().contains("held by another program"), "{e}");
    }
    // (Root opens any port, so the refusal is the message's alone here.)
    let e = open_error("/dev/ttyACM0", std::io::ErrorKind::PermissionDenied, "open");
    assert!(e.to_string().contains("dialout"), "{e}");
    let silent = Emulator::start(Some(HAND), Some((1, Fault::Silent))).unwrap();
    let e = PcBoard::haply(silent.path(), &config()).err().unwrap();
    assert!(e.to_string().contains("is this a Haply board"), "{e}");
}
