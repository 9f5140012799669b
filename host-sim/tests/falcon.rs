//! The Falcon's driver against its emulator, byte for byte over a
//! pseudo-terminal: the loader's handshake at its rates, the firmware's
//! upload echoed and checked (a stand-in file: Novint's is not twoport's
//! to ship), a Falcon whose firmware runs already, the delta's floor held
//! for 10 s at the certified coupling, and every fault a lab meets (the
//! libnifalcon trackers' "could not load firmware", a Falcon found one
//! day and not the next) ending in zero force and a message that says
//! what to do.

mod emulated;

use emulated::{armed_at, each_fault_stops_at_zero, rests_on_the_wall, turn, HAND, PATIENCE};
use host_sim::emulate::falcon::{self, Loader};
use host_sim::emulate::{Emulator, Fault};
use std::path::PathBuf;
use twoport_board::linkage::{falcon_pc, FALCON};
use twoport_host::falcon::FalconConfig;
use twoport_host::{HostBoard, PcBoard, SteppedPc};

/// A stand-in firmware file of 1,000 bytes, and its bytes.
fn firmware(name: &str) -> (PathBuf, Vec<u8>) {
    let bytes: Vec<u8> = (0..1000u32)
        .map(|i| (i.wrapping_mul(2_654_435_761) >> 24) as u8)
        .collect();
    let dir = std::env::temp_dir().join(format!("twoport-falcon-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, &bytes).unwrap();
    (path, bytes)
}

/// The driver's settings for `firmware`, patient with the emulator.
fn config(firmware: impl Into<PathBuf>) -> FalconConfig {
    FalconConfig {
        reply_timeout: PATIENCE,
        ..FalconConfig::new(firmware)
    }
}

fn loader(image: Vec<u8>) -> Loader {
    Loader {
        image,
        answers: true,
        garble_at: None,
    }
}

/// Open, calibrate at the rest pose, stream and arm.
fn armed(emu: &Emulator<3>, config: &FalconConfig) -> HostBoard<PcBoard> {
    armed_at(
        PcBoard::falcon(emu.path(), config).unwrap(),
        3,
        &FALCON.rest_rad,
    )
}

/// The firmware goes up once: the loader's two handshakes, its 1,000
/// bytes echoed, then it runs; opened again, it runs already and nothing
/// is loaded. The hand rests on the floor for 10 s, 1 mm in (the
/// encoders' quantum at the handle is about 0.04 mm), against gravity the
/// image holds up.
#[test]
fn the_driver_loads_the_firmware_and_holds_the_floor_for_ten_seconds() {
    let _turn = turn();
    let (path, image) = firmware("wall.bin");
    let emu = falcon::start(loader(image), Some(HAND), None).unwrap();
    let config = config(&path);
    let mut b = armed(&emu, &config);
    assert_eq!(
        emu.trace().events,
        [
            "loader: first handshake",
            "loader: second handshake",
            "loader: 1000 bytes uploaded, running"
        ]
    );
    rests_on_the_wall(&emu, &mut b, falcon_pc::IMAGE.coupling, 0.1e-3);
    b.close().unwrap();
    // Not power-cycled: the firmware still runs, and is not loaded again.
    let b = HostBoard::open(PcBoard::falcon(emu.path(), &config).unwrap(), 3).unwrap();
    assert_eq!(emu.trace().events.len(), 3);
    b.close().unwrap();
}

/// The same floor with the loop stepped tick by tick (no thread, no
/// clock, no latency gate): what the image, the driver's bytes and the
/// plant do at the certified coupling, whatever the machine's load.
#[test]
fn the_floor_holds_tick_by_tick() {
    let _turn = turn();
    let (path, image) = firmware("stepped.bin");
    let emu = falcon::start(loader(image), Some(HAND), None).unwrap();
    let io = twoport_host::falcon::open(emu.path(), &config(&path)).unwrap();
    let stepped = SteppedPc::new(falcon_pc::board().unwrap(), io);
    let mut b = armed_at(stepped, 3, &FALCON.rest_rad);
    rests_on_the_wall(&emu, &mut b, falcon_pc::IMAGE.coupling, 0.1e-3);
}

#[test]
fn a_failing_falcon_gets_zero_force_and_a_named_error() {
    let _turn = turn();
    let (path, image) = firmware("faults.bin");
    each_fault_stops_at_zero(
        [
            (Fault::Silent, "stopped answering"),
            (Fault::ShortReply, "cut short"),
            (Fault::Garbled, "not a nibble"),
            (Fault::Unplug, "unplugged"),
        ],
        |f| falcon::start(loader(image.clone()), Some(HAND), Some((300, f))).unwrap(),
        |emu| armed(emu, &config(&path)),
    );
}

/// What goes wrong before the loop runs, each named with what to do: no
/// firmware file, a loader that does not answer, an upload garbled on
/// the way, and a file that is not the Falcon's firmware.
#[test]
fn a_falcon_that_will_not_start_says_why() {
    let _turn = turn();
    let (path, image) = firmware("start.bin");
    // Why the driver would not start on an emulated Falcon with `loader`,
    // the firmware file at `file`.
    let refused = |loader: Loader, file: &std::path::Path| {
        let emu = falcon::start(loader, Some(HAND), None).unwrap();
        let why = PcBoard::falcon(emu.path(), &config(file))
            .err()
            .unwrap()
            .to_string();
        (emu, why)
    };
    let (_, e) = refused(
        loader(image.clone()),
        std::path::Path::new("/nonexistent/test_firmware.bin"),
    );
    assert!(e.contains("does not ship it"), "{e}");
    let silent = Loader {
        answers: false,
        ..loader(image.clone())
    };
    let (_, e) = refused(silent, &path);
    assert!(
        e.contains("did not answer its first handshake") && e.contains("unplug"),
        "{e}"
    );
    let garbled = Loader {
        garble_at: Some(123),
        ..loader(image.clone())
    };
    let (_, e) = refused(garbled, &path);
    assert!(e.contains("garbled at byte 123"), "{e}");
    let mut other = image;
    other[500] ^= 1;
    let (emu, e) = refused(loader(other), &path);
    assert!(e.contains("Novint's Falcon firmware"), "{e}");
    assert!(emu
        .trace()
        .events
        .iter()
        .any(|e| e.contains("not the firmware")));
}
