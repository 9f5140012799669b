//! The Haply 2DIY, driven from the PC: its hAPI board on a USB serial
//! port reads the encoders and drives the motors; the pantograph's image
//! ([`twoport_board::linkage::haply`]) runs in the PC's loop.

mod io;
pub mod protocol;

pub use crate::device_port::Grip;
pub use io::{sensors, torques_nm, HaplyIo};

use crate::device_port::DevicePort;
use crate::{DeviceIo, LinkError, LoopThread, PcBoard};
use protocol::{Direction, Joint, Setup};
use twoport_board::linkage::haply::{self as image, HAPLY};
use twoport_board::linkage::{io as io_scale, PERIOD_S};

/// The device's name in messages.
const NAME: &str = "2DIY";

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
    /// Gains outside the image's proven region accepted, and why: the
    /// user's explicit choice, logged when the loop starts and at every
    /// such set ([`accept_unproven_gains`](crate::accept_unproven_gains)).
    /// `None`: refused.
    pub unproven_gains: Option<String>,
    /// How long a reply may take before the board counts as silent
    /// ([`REPLY_TIMEOUT`](crate::device_port::REPLY_TIMEOUT) unless a
    /// slow hub, or an emulator on a loaded machine, needs longer).
    pub reply_timeout: std::time::Duration,
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
            unproven_gains: None,
            reply_timeout: crate::device_port::REPLY_TIMEOUT,
        }
    }

    /// The setup packet's content.
    pub fn setup(&self) -> Setup<2> {
        Setup {
            device_id: self.device_id,
            joints: self.joints,
            sensor_pins: match self.grip {
                Grip::Pin { pin, .. } => vec![pin],
                Grip::Assumed | Grip::Button { .. } => vec![],
            },
        }
    }
}

/// Open the 2DIY's board on `path`, reset and set it up as `config` says,
/// and hear it answer: the [`HaplyIo`] the PC's loop runs against.
pub fn open(path: &str, config: &HaplyConfig) -> Result<impl DeviceIo<2> + 'static, LinkError> {
    config.grip.check(path, NAME, true, false)?;
    let mut port = DevicePort::open(path, 115_200, NAME)?;
    port.set_timeout(config.reply_timeout)
        .map_err(|why| LinkError::Open {
            path: path.to_string(),
            why,
        })?;
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
    /// for [`LATENCY_S`](twoport_board::linkage::pc::LATENCY_S)) ticking at
    /// 1 kHz in the PC's loop.
    pub fn haply(path: &str, config: &HaplyConfig) -> Result<Self, LinkError> {
        let io = open(path, config)?;
        let board =
            image::board().map_err(|e| LinkError::Image(format!("the 2DIY's image: {e:?}")))?;
        let board = crate::accept_unproven_gains(board, config.unproven_gains.as_deref(), path);
        PcBoard::start(board, io, f64::from(PERIOD_S), LoopThread::default())
    }
}
