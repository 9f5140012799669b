//! The Haply 2DIY's driver against its emulator, byte for byte over a
//! pseudo-terminal: the PC's loop holds the image's wall for 10 s at the
//! certified coupling; and every fault a lab meets ends in zero force and
//! a message that says what to do.

mod emulated;

use emulated::{armed_at, each_fault_stops_at_zero, rests_on_the_wall, turn, HAND, PATIENCE};
use host_sim::emulate::{haply, Emulator, Fault};
use twoport_board::linkage::haply::{self as image, HAPLY};
use twoport_host::device_port::open_error;
use twoport_host::haply::{Grip, HaplyConfig};
use twoport_host::{HostBoard, PcBoard, SteppedPc};

/// A switch on analog pin 2, as the emulator's hand closes it.
fn config() -> HaplyConfig {
    HaplyConfig {
        reply_timeout: PATIENCE,
        ..HaplyConfig::v3(Grip::Pin {
            pin: 2,
            closed_above: 0.5,
        })
    }
}

/// Open, calibrate at the rest pose, stream and arm: the setup the board
/// read is the one the driver meant.
fn armed(emu: &Emulator<2>) -> HostBoard<PcBoard> {
    let b = armed_at(
        PcBoard::haply(emu.path(), &config()).unwrap(),
        2,
        &HAPLY.rest_rad,
    );
    let mut sent = config().setup();
    sent.joints.sort_by_key(|j| j.port);
    assert_eq!(
        emu.trace().events,
        ["reset".to_string(), format!("setup {sent:?}")]
    );
    b
}

/// The hand rests on the image's wall for 10 s: 1 mm in, where its
/// 0.4 N meet the coupling's 400 N/m (the encoders' quantum at the links'
/// 70 mm is 0.03 mm).
#[test]
fn the_driver_holds_the_wall_for_ten_seconds() {
    let _turn = turn();
    let emu = haply::start(Some(HAND), None).unwrap();
    let mut b = armed(&emu);
    rests_on_the_wall(&emu, &mut b, image::IMAGE.coupling, 0.05e-3);
    b.disarm().unwrap();
}

/// The same wall with the loop stepped tick by tick (no thread, no
/// clock, no latency gate): what the image, the driver's bytes and the
/// plant do at the certified coupling, whatever the machine's load.
#[test]
fn the_wall_holds_tick_by_tick() {
    let _turn = turn();
    let emu = haply::start(Some(HAND), None).unwrap();
    let io = twoport_host::haply::open(emu.path(), &config()).unwrap();
    let stepped = SteppedPc::new(image::board().unwrap(), io);
    let mut b = armed_at(stepped, 2, &HAPLY.rest_rad);
    rests_on_the_wall(&emu, &mut b, image::IMAGE.coupling, 0.05e-3);
}

#[test]
fn a_failing_device_gets_zero_force_and_a_named_error() {
    let _turn = turn();
    each_fault_stops_at_zero(
        [
            (Fault::Silent, "stopped answering"),
            (Fault::ShortReply, "cut short"),
            (Fault::Garbled, "device id 2 where device 1"),
            (Fault::Unplug, "unplugged"),
        ],
        |f| haply::start(Some(HAND), Some((300, f))).unwrap(),
        armed,
    );
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
    let emu = haply::start(Some(HAND), None).unwrap();
    {
        let _other = serialport::new(emu.path(), 115_200).open().unwrap();
        let e = PcBoard::haply(emu.path(), &config()).err().unwrap();
        assert!(e.to_string().contains("held by another program"), "{e}");
    }
    // (Root opens any port, so the refusal is the message's alone here.)
    let e = open_error("/dev/ttyACM0", std::io::ErrorKind::PermissionDenied, "2DIY");
    assert!(e.to_string().contains("dialout"), "{e}");
    let silent = haply::start(Some(HAND), Some((1, Fault::Silent))).unwrap();
    let e = PcBoard::haply(silent.path(), &config()).err().unwrap();
    assert!(e.to_string().contains("is this a Haply board"), "{e}");
}
