//! The Haply 2DIY, driven from the PC: its hAPI board on a USB serial
//! port reads the encoders and drives the motors; the pantograph's image
//! ([`twoport_board::linkage::haply`]) runs in the PC's loop.

mod io;
pub mod protocol;

pub use io::{Grip, HaplyIo, REPLY_TIMEOUT};

use crate::{DeviceIo, LinkError, PcBoard};
use protocol::{Direction, Joint, Setup};
use twoport_board::linkage::haply::{self as image, HAPLY};
use twoport_board::linkage::{io as io_scale, PERIOD_S};

/// How the 2DIY is wired and held.
#[derive(Clone, Debug, PartialEq)]
pub struct HaplyConfig {
    /// The device id its packets carry.
    pub device_id: u8,
    /// Its two joints (the pantograph's `q1`, `q2`): port, directions,
    /// and the angle each encoder reads when the port is opened.
    pub joints: [Joint; 2],
    /// Its dead-man switch.
    pub grip: Grip,
}

impl HaplyConfig {
    /// The hardware v3 as Haply's examples wire it (`q1`'s motor and
    /// encoder on port 2, `q2`'s on port 1, both counter-clockwise), its
    /// encoders reading the image's rest pose when the port is opened:
    /// open it with the handle held there.
    pub fn v3(grip: Grip) -> Self {
        let joint = |port, rad: f32| Joint {
            port,
            motor: Direction::Ccw,
            encoder: Direction::Ccw,
            offset_deg: rad.to_degrees(),
            counts_per_rev: HAPLY.hardware.counts_per_rev,
        };
        HaplyConfig {
            device_id: 1,
            joints: [joint(2, HAPLY.rest_rad[0]), joint(1, HAPLY.rest_rad[1])],
            grip,
        }
    }

    /// The setup packet's content.
    pub fn setup(&self) -> Setup<2> {
        Setup {
            device_id: self.device_id,
            joints: self.joints,
            sensor_pins: match self.grip {
                Grip::Pin { pin, .. } => vec![pin],
                Grip::Assumed => vec![],
            },
        }
    }
}

/// Why a port would not open, and what to do about it.
pub fn open_error(path: &str, kind: std::io::ErrorKind, what: &str) -> LinkError {
    use std::io::ErrorKind as K;
    let why = match kind {
        K::NotFound => format!(
            "{what}: no such port; is the 2DIY plugged in? `twoport devices` lists the \
             serial ports this computer has"
        ),
        K::PermissionDenied => format!(
            "{what}: permission denied; on Linux add yourself to the port's group \
             (`sudo usermod -aG dialout $USER`, then log in again), or install \
             twoport's udev rule (docs/devices.md)"
        ),
        K::ResourceBusy | K::WouldBlock => format!(
            "{what}: the port is held by another program (a Processing sketch, Haply's \
             own software, another twoport); close it and open the port again"
        ),
        _ => format!("{what}: {kind}"),
    };
    LinkError::Open {
        path: path.to_string(),
        why,
    }
}

/// Open the 2DIY's board on `path`, reset and set it up as `config` says,
/// and hear it answer: the [`HaplyIo`] the PC's loop runs against.
pub fn open(path: &str, config: &HaplyConfig) -> Result<impl DeviceIo<2> + 'static, LinkError> {
    // (The port is opened in its exclusive mode, under an advisory lock:
    // a second driver, twoport's or another, is refused.)
    let port = serialport::new(path, 115_200)
        .timeout(REPLY_TIMEOUT)
        .open()
        .map_err(|e| {
            let there = std::path::Path::new(path).exists();
            let kind = match e.kind {
                serialport::ErrorKind::NoDevice if !there => std::io::ErrorKind::NotFound,
                serialport::ErrorKind::NoDevice if e.description.contains("lock") => {
                    std::io::ErrorKind::ResourceBusy
                }
                serialport::ErrorKind::Io(k) => k,
                _ => std::io::ErrorKind::Other,
            };
            match kind {
                std::io::ErrorKind::Other => LinkError::Open {
                    path: path.to_string(),
                    why: e.to_string(),
                },
                k => open_error(path, k, "open"),
            }
        })?;
    // What the board sent before this program opened the port is stale.
    let _ = port.clear(serialport::ClearBuffer::All);
    if matches!(config.grip, Grip::Assumed) {
        eprintln!(
            "twoport: {path}: the 2DIY's grip is assumed (Grip::Assumed): force is on \
             whenever the loop is armed, hands on the handle or not; its region is \
             proven only for a grasp of at least 2 N s/m"
        );
    }
    let mut io =
        HaplyIo::open(port, config.setup(), io_scale(&HAPLY), config.grip).map_err(|why| {
            LinkError::Open {
                path: path.to_string(),
                why,
            }
        })?;
    // A board that answers its first torque packet is set up.
    io.exchange([0; 2], false).map_err(|why| LinkError::Open {
        path: path.to_string(),
        why: format!(
            "{why} (after its setup: is this a Haply board running Haply's firmware, with \
             the device id {}?)",
            config.device_id
        ),
    })?;
    Ok(io)
}

impl PcBoard {
    /// The 2DIY on `path`: its image ([`image::board`], its region proven
    /// for [`image::LATENCY_S`]) ticking at 1 kHz in the PC's loop.
    pub fn haply(path: &str, config: &HaplyConfig) -> Result<Self, LinkError> {
        let io = open(path, config)?;
        let board =
            image::board().map_err(|e| LinkError::Image(format!("the 2DIY's image: {e:?}")))?;
        PcBoard::start(board, io, f64::from(PERIOD_S))
    }
}
