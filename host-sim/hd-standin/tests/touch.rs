//! The Touch's driver against the stand-in HD library (this crate, loaded
//! at run time as OpenHaptics' would be): the PC's loop, in the library's
//! scheduler, holds the image's wall for 10 s at the certified coupling;
//! and every fault a lab meets ends with the motors off and a message
//! that says what to do.

// (The serial drivers' helpers too, which this test has no use for.)
#[allow(dead_code)]
#[path = "../../tests/emulated/mod.rs"]
mod emulated;

use emulated::{armed_at, turn, wait, wall_holds, Pacing};
use host_sim::emulate::Trace;
use std::path::PathBuf;
use std::time::Duration;
use twoport_board::linkage::touch::{self as image, TOUCH};
use twoport_host::touch::TouchConfig;
use twoport_host::{BoardPort, Gains, HostBoard, LinkError, PcBoard, SteppedPc};

/// The stand-in library, built beside this test.
fn standin() -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    let deps = exe.parent().unwrap();
    let name = format!(
        "{}twoport_hd_standin{}",
        std::env::consts::DLL_PREFIX,
        std::env::consts::DLL_SUFFIX
    );
    [deps.join(&name), deps.parent().unwrap().join(&name)]
        .into_iter()
        .find(|p| p.exists())
        .unwrap_or_else(|| panic!("{name} not built beside {}", deps.display()))
}

/// The Touch the stand-in opens for `scenario`, its stylus button the
/// grip switch.
fn config(scenario: &str) -> TouchConfig {
    TouchConfig {
        library: Some(standin()),
        device: Some(scenario.to_string()),
        ..TouchConfig::stylus_button()
    }
}

/// A file for the stand-in's trace, unique to `what`.
fn trace_file(what: &str) -> PathBuf {
    std::env::temp_dir().join(format!("twoport-touch-{}-{what}.json", std::process::id()))
}

fn read_trace(path: &PathBuf) -> Trace<3> {
    let t = Trace::from_json(&std::fs::read_to_string(path).unwrap()).unwrap();
    let _ = std::fs::remove_file(path);
    t
}

/// A count of `q2` and one of `q3` at the rest pose, at the handle along
/// `z` (m): `l (cos q2 + sin q3) 2π / 15,000`.
const QUANTUM_M: f64 = 0.11e-3;

/// Run the armed board until 10 s after the hand began to press (it
/// presses once the motors are on), unless it faults.
fn press_for_ten_seconds<P: BoardPort>(b: &mut HostBoard<P>) -> u16 {
    let armed = b.latest().map_or(0, |s| s.tick);
    let mut faults = 0;
    wait(b, Duration::from_secs(600), |b| {
        let s = b.latest();
        faults = s.map_or(0, |s| s.faults);
        faults != 0 || s.is_some_and(|s| s.tick >= armed + 10_100)
    })
    .unwrap();
    faults
}

/// The hand rests on the image's wall for 10 s: 1 mm in, where its
/// 0.5 N meet the coupling's 400 N/m, to within the quantum the driver
/// reads HD's angles at: 0.06 mm at each 133 mm link, 0.11 mm at the
/// handle when `q2` and `q3` each turn a count ([`QUANTUM_M`]).
#[test]
fn the_driver_holds_the_wall_for_ten_seconds() {
    let _turn = turn();
    let path = trace_file("wall");
    let pc = PcBoard::touch(&config(&format!("trace={}", path.display()))).unwrap();
    let mut b = armed_at(pc, 3, &TOUCH.rest_rad);
    assert_eq!(press_for_ten_seconds(&mut b), 0);
    drop(b);
    let t = read_trace(&path);
    wall_holds(&t, image::IMAGE.coupling, QUANTUM_M, Pacing::Threaded);
    assert_eq!(t.events[..2], ["open".to_string(), "force on".into()]);
    assert!(t.events.ends_with(&["force off".into(), "disabled".into()]));
}

/// The same wall with the loop stepped frame by frame from the test's
/// thread (no scheduler, no clock, no latency gate).
#[test]
fn the_wall_holds_frame_by_frame() {
    let _turn = turn();
    let path = trace_file("stepped");
    let (io, _scheduler) =
        twoport_host::touch::open(&config(&format!("trace={}", path.display()))).unwrap();
    let stepped = SteppedPc::new(image::board().unwrap(), io);
    let mut b = armed_at(stepped, 3, &TOUCH.rest_rad);
    assert_eq!(press_for_ten_seconds(&mut b), 0);
    drop(b);
    drop(_scheduler);
    wall_holds(
        &read_trace(&path),
        image::IMAGE.coupling,
        QUANTUM_M,
        Pacing::Stepped,
    );
}

/// Each fault mid-run stops the loop with a message saying what happened
/// and what to do, and the motors end off.
#[test]
fn a_failing_device_gets_zero_force_and_a_named_error() {
    let _turn = turn();
    for (fault, says) in [
        ("unplug", "HD_COMM_ERROR"),
        ("short", "HD_DEVICE_FAULT"),
        ("garbled", "not a device's"),
        ("silent", "has run no tick"),
    ] {
        let path = trace_file(fault);
        let scenario = format!("trace={} fault={fault}@300", path.display());
        let mut b = armed_at(
            PcBoard::touch(&config(&scenario)).unwrap(),
            3,
            &TOUCH.rest_rad,
        );
        match wait(&mut b, Duration::from_secs(60), |_| false) {
            Err(LinkError::Device(why)) => assert!(why.contains(says), "{fault}: {why}"),
            e => panic!("{fault}: {e:?}"),
        }
        drop(b);
        let t = read_trace(&path);
        assert_eq!(
            t.events.last().map(String::as_str),
            Some("disabled"),
            "{fault}"
        );
        if fault != "silent" {
            // The loop turned the motors off itself.
            let n = t.events.len();
            assert_eq!(t.events[n - 2], "force off", "{fault}: {:?}", t.events);
        }
        if fault == "garbled" {
            assert_eq!(t.torque_nm.last(), Some(&[0.0; 3]));
        }
    }
}

/// The scope watches a device as it watches a board: opened by name on a
/// scene of its axes, calibrated at its image's rest pose, armed; its
/// telemetry streams in, armed, with the hand's press on the last axis.
#[test]
fn the_scope_runs_the_touch_live() {
    use host_sim::scope::board::WithBoard;
    use host_sim::scope::world::WorldState;
    let _turn = turn();
    // (A scene names its files from the workspace's root; this test alone
    // reads any by a relative path.)
    std::env::set_current_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/../..")).unwrap();
    let scene = std::path::Path::new("scenes/linkages/phantom_wall.toml");
    let mut s = WorldState::<3>::open(scene).unwrap();
    let lib = standin();
    s.connect_device("touch", "", Some(&lib));
    assert_eq!(s.message, None);
    assert_eq!(
        s.board.as_ref().and_then(|b| b.device.as_deref()),
        Some("touch")
    );
    let run = |s: &mut WorldState<3>, seconds: f64| {
        let until = std::time::Instant::now() + Duration::from_secs_f64(seconds);
        while std::time::Instant::now() < until {
            s.advance(0.002);
            std::thread::sleep(Duration::from_millis(2));
        }
    };
    run(&mut s, 0.1);
    s.calibrate_device();
    run(&mut s, 0.1);
    s.tell_board(twoport_link::Message::Arm);
    run(&mut s, 1.0);
    assert_eq!(s.message, None);
    let b = s.board.as_ref().unwrap();
    let t = b.telemetry.expect("telemetry streamed");
    assert_eq!((t.mode, t.faults), (twoport_link::BoardMode::Armed, 0));
    assert!(b.status.is_some_and(|st| st.calibrated));
    let pressed = s.board_forces[2].iter().last().map_or(0.0, |(_, f)| *f);
    assert!(pressed.abs() > 0.1, "{pressed} N on z");
}

/// Gains past the proven region are refused, naming the limit, unless the
/// user chose to accept them (an explicit, logged choice).
#[test]
fn gains_past_the_region_need_the_users_choice() {
    let _turn = turn();
    let stiff: [Gains; 3] = [twoport_control::Gains::impedance(800.0, 1.0); 3];
    let mut b = HostBoard::open(PcBoard::touch(&config("")).unwrap(), 3).unwrap();
    match b.set_gains(&stiff) {
        Err(LinkError::GainsRefused(why)) => assert_eq!(why.axis, 0, "{why:?}"),
        e => panic!("{e:?}"),
    }
    drop(b);
    let chosen = TouchConfig {
        unproven_gains: Some("a stiffness study on a clamped handle".into()),
        ..config("")
    };
    let mut b = HostBoard::open(PcBoard::touch(&chosen).unwrap(), 3).unwrap();
    let g = b.set_gains(&stiff).unwrap();
    assert_eq!(g.as_slice(), &stiff);
}

/// A library that is not there, a port the user may not open, a device
/// another program holds, and a grip the Touch has no way to read: each
/// refused at open, saying what to do.
#[test]
fn opening_fails_with_what_to_do() {
    let _turn = turn();
    let refused = |c: TouchConfig| match PcBoard::touch(&c) {
        Err(LinkError::Open { why, .. }) => why,
        Err(e) => panic!("{e:?}"),
        Ok(_) => panic!("opened {c:?}"),
    };
    let missing = TouchConfig {
        library: Some("/nonexistent/libHD.so".into()),
        ..TouchConfig::stylus_button()
    };
    assert!(refused(missing).contains("Install OpenHaptics"));
    assert!(refused(config("open=denied")).contains("dialout"));
    assert!(refused(config("open=busy")).contains("another program"));
    // Held by this program: a second open of the one device.
    let first = PcBoard::touch(&config("")).unwrap();
    assert!(refused(config("")).contains("HD_DEVICE_ALREADY_INITIATED"));
    drop(first);
    let pin = TouchConfig {
        grip: twoport_host::device_port::Grip::Pin {
            pin: 2,
            closed_above: 0.5,
        },
        ..config("")
    };
    assert!(refused(pin).contains("no analog pins"));
}
