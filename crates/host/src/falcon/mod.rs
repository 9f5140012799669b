//! The Novint Falcon, driven from the PC: its firmware uploaded at every
//! power-up, then its encoders read and motors driven over the FTDI
//! chip's serial port; the delta's image
//! ([`twoport_board::linkage::falcon_pc`]) runs in the PC's loop.
//!
//! The transport is the kernel's `ftdi_sio` serial driver, not libusb:
//! the port is an ordinary serial device (`/dev/ttyUSB0`), which the
//! `serialport` crate opens with no C library, and its rates, modem lines
//! and exclusive open are the kernel's. The kernel does not know the
//! Falcon's USB id on its own: twoport's udev rule
//! (`udev/60-twoport.rules`) adds it, and sets the chip's latency timer.

pub mod protocol;

use crate::device_port::{DevicePort, Grip};
use crate::{DeviceIo, LinkError, LoopThread, PcBoard};
use protocol::{Command, FalconStatus, CHUNK, PACKET};
use std::path::{Path, PathBuf};
use std::time::Duration;
use twoport_board::linkage::{falcon_pc, io as io_scale, FALCON, PERIOD_S};
use twoport_board::{IoScale, RawSensors};

/// The device's name in messages.
const NAME: &str = "Falcon";

/// How a Falcon is opened and held.
#[derive(Clone, Debug, PartialEq)]
pub struct FalconConfig {
    /// Novint's firmware file (`test_firmware.bin` or `nvent_firmware.bin`
    /// of Novint's driver or libnifalcon's sources): not twoport's to ship.
    pub firmware: PathBuf,
    /// Its dead-man switch: a grip button, or none.
    pub grip: Grip,
    /// The LEDs while it runs.
    pub leds: u8,
    /// Gains outside the image's proven region accepted, and why: the
    /// user's explicit choice, logged when the loop starts and at every
    /// such set ([`accept_unproven_gains`](crate::accept_unproven_gains)).
    /// `None`: refused.
    pub unproven_gains: Option<String>,
    /// How long a reply may take in the loop before the Falcon counts as
    /// silent ([`REPLY_TIMEOUT`](crate::device_port::REPLY_TIMEOUT)
    /// unless a slow hub, or an emulator on a loaded machine, needs
    /// longer).
    pub reply_timeout: Duration,
}

impl FalconConfig {
    /// `firmware`, force on while the grip's center button (bit 0) is held,
    /// the blue LED on.
    pub fn new(firmware: impl Into<PathBuf>) -> Self {
        FalconConfig {
            firmware: firmware.into(),
            grip: Grip::Button { mask: 0b0001 },
            leds: protocol::LED_BLUE,
            unproven_gains: None,
            reply_timeout: crate::device_port::REPLY_TIMEOUT,
        }
    }
}

/// A Falcon running its firmware, on its port.
pub struct FalconIo {
    port: DevicePort,
    io: [IoScale; 3],
    grip: Grip,
    leds: u8,
}

impl FalconIo {
    /// One packet out, its answer in.
    fn send(&mut self, command: &Command) -> Result<FalconStatus, String> {
        self.port.send(&command.encode())?;
        let mut p = [0; PACKET];
        self.port.receive(&mut p)?;
        FalconStatus::decode(&p).map_err(|e| format!("the Falcon's answer: {e}"))
    }
}

impl DeviceIo<3> for FalconIo {
    fn exchange(&mut self, duty: [i16; 3], on: bool) -> Result<RawSensors<3>, String> {
        let s = self.send(&command(duty, on, &self.io, self.leds))?;
        Ok(sensors(&s, self.grip))
    }
}

/// The packet that commands the board image's `duty` (outputs `on`, or
/// zero), each joint's scaled by `io`: the image's torque resists the
/// joint's motion, as libnifalcon's motor value does (the negative of
/// `J^T f`).
pub fn command(duty: [i16; 3], on: bool, io: &[IoScale; 3], leds: u8) -> Command {
    let motor = core::array::from_fn(|i| {
        let tau = if on { io[i].force_n(duty[i]) } else { 0.0 };
        (tau * protocol::MOTOR_PER_NM)
            .round()
            .clamp(-32_767.0, 32_767.0) as i16
    });
    Command {
        motor,
        leds,
        homing: false,
    }
}

/// What the board image reads from the Falcon's `status`, its dead-man
/// switch from `grip`.
pub fn sensors(status: &FalconStatus, grip: Grip) -> RawSensors<3> {
    RawSensors {
        encoder_raw: status.encoder.map(|c| i32::from(c) as u32),
        dead_man_closed: grip.closed(|_| None, status.buttons),
        ..RawSensors::default()
    }
}

/// The firmware file's bytes, or what is wrong with it.
fn firmware(path: &Path) -> Result<Vec<u8>, String> {
    let bytes = std::fs::read(path).map_err(|e| {
        format!(
            "the Falcon's firmware file {}: {e}. The firmware is Novint's, and twoport \
             does not ship it: name the file from Novint's driver or libnifalcon's \
             sources (test_firmware.bin)",
            path.display()
        )
    })?;
    if bytes.is_empty() {
        return Err(format!(
            "the Falcon's firmware file {} is empty",
            path.display()
        ));
    }
    Ok(bytes)
}

/// Set the FTDI chip's latency timer (ms) where the kernel shows it; a
/// port with none (not an FTDI chip: the emulator's) has nothing to set.
fn latency_timer(path: &str, ms: u8) -> Result<(), String> {
    let Some(tty) = Path::new(path)
        .canonicalize()
        .ok()
        .and_then(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
    else {
        return Ok(());
    };
    let knob = Path::new("/sys/bus/usb-serial/devices")
        .join(tty)
        .join("latency_timer");
    if !knob.exists() {
        return Ok(());
    }
    std::fs::write(&knob, format!("{ms}")).map_err(|e| {
        format!(
            "{}: {e}; install twoport's udev rule (udev/60-twoport.rules), which lets \
             the Falcon's latency timer be set",
            knob.display()
        )
    })
}

/// Set the port's rate, naming it if refused.
fn rate(port: &mut DevicePort, baud: u32) -> Result<(), String> {
    port.port_mut()
        .set_baud_rate(baud)
        .map_err(|e| format!("the Falcon's port would not run at {baud} baud: {e}"))
}

/// Is the firmware already running (the Falcon not power-cycled since
/// it was loaded)? One zero packet at the run rate tells.
fn running(port: &mut DevicePort, path: &str) -> Result<bool, String> {
    latency_timer(path, 1)?;
    rate(port, protocol::RUN_BAUD)?;
    port.send(&Command::default().encode())?;
    let mut p = [0; PACKET];
    let answered = port.receive(&mut p).is_ok() && FalconStatus::decode(&p).is_ok();
    let _ = port.port_mut().clear(serialport::ClearBuffer::All);
    Ok(answered)
}

/// How long the loader may take to answer: its FTDI latency timer holds
/// a short answer up to 16 ms.
const LOADER_TIMEOUT: Duration = Duration::from_millis(100);

/// The loader's handshake and the upload, as libnifalcon does them.
fn load(port: &mut DevicePort, path: &str, image: &[u8]) -> Result<(), String> {
    latency_timer(path, 16)?;
    port.set_timeout(LOADER_TIMEOUT)?;
    rate(port, protocol::CHECK_BAUD)?;
    let _ = port.port_mut().clear(serialport::ClearBuffer::All);
    // (A port with no modem lines, the emulator's pty, refuses these; a
    // Falcon's FTDI chip takes them, and its loader needs the DTR pulse.)
    let lines = port
        .port_mut()
        .write_request_to_send(false)
        .and_then(|()| port.port_mut().write_data_terminal_ready(false))
        .and_then(|()| port.port_mut().write_data_terminal_ready(true))
        .err()
        .map(|e| format!(" (the port refused its modem lines: {e})"))
        .unwrap_or_default();
    let not_loader = |what: &str| {
        format!(
            "the Falcon's loader did not answer {what}{lines}: unplug the Falcon's power \
             and USB, plug them back, and open it again (its FTDI chip must be this \
             program's: see docs/devices.md)"
        )
    };
    // Each handshake: what the host sends, and what the loader answers.
    let shake = |port: &mut DevicePort, send: &[u8], answer: &[u8], which: &str| {
        port.send(send)?;
        let mut got = vec![0; answer.len()];
        port.receive(&mut got)
            .map_err(|_| not_loader(&format!("its {which} handshake")))?;
        if got != answer {
            return Err(not_loader(&format!(
                "its {which} handshake as expected ({got:02x?})"
            )));
        }
        Ok(())
    };
    shake(port, &protocol::CHECK_1, &protocol::CHECK_1_ANSWER, "first")?;
    let _ = port.port_mut().write_data_terminal_ready(false);
    rate(port, protocol::LOAD_BAUD)?;
    shake(
        port,
        &protocol::CHECK_2,
        &protocol::CHECK_2_ANSWER,
        "second",
    )?;
    let mut echo = [0; CHUNK];
    for (k, chunk) in image.chunks(CHUNK).enumerate() {
        port.send(chunk)?;
        let back = &mut echo[..chunk.len()];
        port.receive(back)
            .map_err(|e| format!("the firmware's upload stopped at byte {}: {e}", k * CHUNK))?;
        if let Some(i) = chunk.iter().zip(back.iter()).position(|(a, b)| a != b) {
            return Err(format!(
                "the firmware's upload came back garbled at byte {} (libnifalcon's \
                 \"could not load firmware\"): unplug the Falcon's power and USB, plug them \
                 back, and open it again",
                k * CHUNK + i
            ));
        }
    }
    Ok(())
}

/// Open the Falcon on `path`: load its firmware unless it runs already,
/// switch to the run rate, and hear it answer.
pub fn open(path: &str, config: &FalconConfig) -> Result<impl DeviceIo<3> + 'static, LinkError> {
    let open_err = |why: String| LinkError::Open {
        path: path.to_string(),
        why,
    };
    config.grip.check(path, NAME, false, true)?;
    let image = firmware(&config.firmware).map_err(open_err)?;
    let mut port = DevicePort::open(path, protocol::CHECK_BAUD, NAME)?;
    if !running(&mut port, path).map_err(open_err)? {
        load(&mut port, path, &image).map_err(open_err)?;
        port.set_timeout(config.reply_timeout).map_err(open_err)?;
        latency_timer(path, 1).map_err(open_err)?;
        rate(&mut port, protocol::RUN_BAUD).map_err(open_err)?;
        // (The firmware takes a moment to start.)
        std::thread::sleep(Duration::from_millis(20));
        let _ = port.port_mut().clear(serialport::ClearBuffer::All);
    }
    port.set_timeout(config.reply_timeout).map_err(open_err)?;
    let mut io = FalconIo {
        port,
        io: io_scale(&FALCON),
        grip: config.grip,
        leds: config.leds,
    };
    io.exchange([0; 3], false).map_err(|why| {
        open_err(format!(
            "{why} (after loading the firmware: is {} Novint's Falcon firmware?)",
            config.firmware.display()
        ))
    })?;
    Ok(io)
}

impl PcBoard {
    /// The Falcon on `path`: its image ([`falcon_pc::board`], its region
    /// proven for [`LATENCY_S`](twoport_board::linkage::pc::LATENCY_S))
    /// ticking at 1 kHz in the PC's loop.
    pub fn falcon(path: &str, config: &FalconConfig) -> Result<Self, LinkError> {
        let io = open(path, config)?;
        let board = falcon_pc::board()
            .map_err(|e| LinkError::Image(format!("the Falcon's image: {e:?}")))?;
        let board = crate::accept_unproven_gains(board, config.unproven_gains.as_deref(), path);
        PcBoard::start(board, io, f64::from(PERIOD_S), LoopThread::default())
    }
}
