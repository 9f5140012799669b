//! The device object against the firmware in QEMU, running free on its
//! own clock against a device simulated on the chip (the an386 image's
//! `sim-device` build): `cargo xtask device --check` starts it and runs
//! this with its pty in `TWOPORT_PTY`. QEMU's clock is not the host's, so
//! nothing here counts on how many ticks a second of the host's brings.

use std::time::{Duration, Instant};
use twoport_board::excalibur;
use twoport_host::HostBoard;
use twoport_link::{BoardMode, Contact, ProvenRegion, VeSource};

/// The wall the host's VE renders (m): solid above. The image's hand
/// pushes 2 N along +x.
const WALL_M: f64 = 0.005;

/// An application opens the board, reads what it can prove, calibrates,
/// hands the VE to the host, arms, sends a wall at 5 mm (solid above) with
/// every state it reads for two seconds against the simulated hand, and
/// disarms: the handle rests on the wall, pressed in by the coupling's
/// spring, no fault latched, and the latency the board measured is inside
/// the budget its region is proven for.
#[test]
#[ignore = "needs the sim-device image in QEMU (cargo xtask device --check)"]
fn an_application_drives_the_free_running_board_in_qemu() {
    let pty = std::env::var("TWOPORT_PTY").expect("TWOPORT_PTY: the board's pty");
    let mut b = HostBoard::open_serial(&pty, 1).unwrap();
    let spec = *b.spec();
    assert_eq!(
        (spec.period_ns, spec.linkage, spec.ve),
        (1_000_000, false, VeSource::Board)
    );
    assert!(matches!(
        spec.axes[0].region,
        ProvenRegion::MaxStiffness { k_max_npm, .. } if k_max_npm > excalibur::COUPLING.k_npm
    ));
    assert_eq!(spec.latency_budget_s, excalibur::region::LATENCY_S);
    b.calibrate(&[0.0]).unwrap();
    b.stream(1).unwrap();
    // A ramp of one tick, and up to half a second on one update, as the
    // board waits for heartbeats: QEMU and this test share the machine's
    // cores, and a busy machine stalls either.
    b.host_ve(1, 500).unwrap();
    assert_eq!(b.arm().unwrap().mode, BoardMode::Armed);
    let start = Instant::now();
    let mut last_seq = 0;
    while start.elapsed() < Duration::from_secs(2) {
        if b.poll().unwrap() > 0 {
            last_seq = b.send_ve(&[WALL_M], &[Contact::Above]).unwrap();
        }
    }
    let states = b.take_states();
    let last = states.last().copied().unwrap();
    assert_eq!((last.mode, last.faults), (BoardMode::Armed, 0), "{last:?}");
    let x = last.axes[0].position_m;
    let press = 2.0 / f64::from(excalibur::COUPLING.k_npm);
    assert!(
        (x - WALL_M - press).abs() < 20e-6,
        "at {x} m after {} states",
        states.len()
    );
    assert!(last.ve_seq > 0 && last.ve_seq <= last_seq);
    assert_eq!(b.disarm().unwrap().mode, BoardMode::Disarmed);
    let spec = b.session().spec().unwrap();
    let worst = spec
        .worst_latency_s()
        .expect("the image states its count's rate");
    assert!(
        worst > 0.0 && worst <= f64::from(spec.latency_budget_s),
        "{worst} s late, {} s allowed",
        spec.latency_budget_s
    );
    b.close().unwrap();
}
