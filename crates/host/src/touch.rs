//! The 3D Systems Touch (and the USB PHANToM Omni), driven from the PC:
//! OpenHaptics' HD library, loaded at run time ([`twoport_hd`]), reads the
//! joints' angles and takes their torques; the serial arm's image
//! ([`twoport_board::linkage::touch`]) runs in the PC's loop, each tick
//! one servo frame inside the library's own scheduler.

use crate::device_port::Grip;
use crate::pc_loop::{Priority, Ticker};
use crate::{DeviceIo, LinkError, PcBoard};
use std::path::PathBuf;
use std::sync::Arc;
use twoport_board::linkage::touch::{self as image, TOUCH};
use twoport_board::linkage::{io as io_scale, PERIOD_S};
use twoport_board::{IoScale, RawSensors};
use twoport_hd::{HdDevice, HdError, HdFrame, HdLibrary, Scheduled, HD_DEVICE_BUTTON_1};

/// The device's name in messages.
const NAME: &str = "Touch";

/// Which Touch, through which library, held how.
#[derive(Clone, Debug, PartialEq)]
pub struct TouchConfig {
    /// OpenHaptics' HD library (`None`: `libHD.so` where the system's
    /// loader finds it).
    pub library: Option<PathBuf>,
    /// The device's name as Touch Setup configured it (`None`: the
    /// default device).
    pub device: Option<String>,
    /// Each joint's direction: `1.0` where HD's angle grows as the image's
    /// `q` does, `-1.0` where it shrinks.
    pub directions: [f32; 3],
    /// The dead-man switch: the stylus's buttons, or assumed.
    pub grip: Grip,
    /// Gains outside the image's proven region accepted, and why: the
    /// user's explicit choice, logged when the loop starts and at every
    /// such set ([`accept_unproven_gains`](crate::accept_unproven_gains)).
    /// `None`: refused.
    pub unproven_gains: Option<String>,
}

impl TouchConfig {
    /// The default device through the system's library, HD's joint angles
    /// taken as the image's (`q3` absolute, as HD gives it), the hand
    /// held by `grip`.
    pub fn new(grip: Grip) -> Self {
        TouchConfig {
            library: None,
            device: None,
            directions: [1.0; 3],
            grip,
            unproven_gains: None,
        }
    }

    /// Its first stylus button as the grip switch: force only while it is
    /// held.
    pub fn stylus_button() -> Self {
        Self::new(Grip::Button {
            mask: HD_DEVICE_BUTTON_1 as u8,
        })
    }
}

/// What messages call the device: its configured name, or the default.
fn shown(config: &TouchConfig) -> String {
    config
        .device
        .clone()
        .unwrap_or_else(|| "the default HD device".into())
}

/// A Touch, open, one servo frame an exchange.
pub struct TouchIo {
    device: Arc<HdDevice>,
    io: [IoScale; 3],
    directions: [f32; 3],
    grip: Grip,
    /// Whether the motors' output is enabled.
    on: bool,
}

/// The joints' torques HD takes (mN m, toward larger angles) for the
/// image's `duty`, its outputs `on`, each joint scaled by `io` and turned
/// by `directions`.
pub fn torques_mnm(duty: [i16; 3], on: bool, io: &[IoScale; 3], directions: [f32; 3]) -> [f64; 3] {
    // The board image's torque resists the joint's motion.
    core::array::from_fn(|i| {
        if on {
            f64::from(-io[i].force_n(duty[i]) * directions[i]) * 1e3
        } else {
            0.0
        }
    })
}

/// The image's sensors for a frame HD gave: each joint's angle counted
/// from the image's rest pose (as the image's joints read until the host
/// calibrates them) at its quantum, turned by `directions`; the grip from
/// the buttons.
pub fn sensors(frame: &HdFrame, directions: [f32; 3], grip: Grip) -> RawSensors<3> {
    let counts = core::array::from_fn(|i| {
        let rad = frame.joint_rad[i] * f64::from(directions[i]) - f64::from(TOUCH.rest_rad[i]);
        let c = (rad * f64::from(TOUCH.hardware.counts_per_rev) / core::f64::consts::TAU).round();
        // (Two's complement: the counter wraps as an encoder's does.)
        (c as i64) as u32
    });
    let buttons = u8::try_from(frame.buttons & 0xff).unwrap_or(0);
    RawSensors {
        encoder_raw: counts,
        dead_man_closed: grip.closed(|_| None, buttons),
        ..RawSensors::default()
    }
}

impl DeviceIo<3> for TouchIo {
    fn exchange(&mut self, duty: [i16; 3], on: bool) -> Result<RawSensors<3>, String> {
        let said = |e: HdError| format!("the {NAME}: {e}");
        if on != self.on {
            self.device.force_output(on).map_err(said)?;
            self.on = on;
        }
        let torque = torques_mnm(duty, on, &self.io, self.directions);
        let frame = self.device.frame(torque).map_err(said)?;
        Ok(sensors(&frame, self.directions, self.grip))
    }
}

/// OpenHaptics' scheduler running the loop's ticks.
pub struct HdScheduler {
    device: Arc<HdDevice>,
    scheduled: Option<Scheduled>,
}

impl Ticker for HdScheduler {
    fn start(
        &mut self,
        period_s: f64,
        tick: Box<dyn FnMut() -> bool + Send>,
    ) -> Result<Priority, String> {
        let rate_hz = (1.0 / period_s).round() as u32;
        let scheduled = self
            .device
            .schedule(rate_hz, tick)
            .map_err(|e| format!("the {NAME}'s scheduler: {e}"))?;
        self.scheduled = Some(scheduled);
        Ok(Priority::Library(
            "OpenHaptics' servo scheduler runs the loop in its thread, at the priority it sets"
                .into(),
        ))
    }
}

impl Drop for HdScheduler {
    fn drop(&mut self) {
        // (The scheduler stops before the device it drives is disabled.)
        self.scheduled.take();
    }
}

/// Load the HD library and open the Touch `config` names, its motors off:
/// the [`TouchIo`] the PC's loop runs against, and the scheduler that
/// runs it.
pub fn open(config: &TouchConfig) -> Result<(TouchIo, HdScheduler), LinkError> {
    let path = shown(config);
    config.grip.check(&path, NAME, false, true)?;
    let refuse = |e: HdError| LinkError::Open {
        path: path.clone(),
        why: e.to_string(),
    };
    let library = HdLibrary::load(config.library.as_deref()).map_err(refuse)?;
    let device = Arc::new(
        library
            .init_device(config.device.as_deref())
            .map_err(refuse)?,
    );
    device.force_output(false).map_err(refuse)?;
    let io = TouchIo {
        device: Arc::clone(&device),
        io: io_scale(&TOUCH),
        directions: config.directions,
        grip: config.grip,
        on: false,
    };
    Ok((
        io,
        HdScheduler {
            device,
            scheduled: None,
        },
    ))
}

impl PcBoard {
    /// The Touch `config` names: its image ([`image::board`], its region
    /// proven for [`LATENCY_S`](twoport_board::linkage::pc::LATENCY_S))
    /// ticking at 1 kHz in OpenHaptics' scheduler.
    pub fn touch(config: &TouchConfig) -> Result<Self, LinkError> {
        let (io, scheduler) = open(config)?;
        let board =
            image::board().map_err(|e| LinkError::Image(format!("the {NAME}'s image: {e:?}")))?;
        let board =
            crate::accept_unproven_gains(board, config.unproven_gains.as_deref(), &shown(config));
        PcBoard::start(board, io, f64::from(PERIOD_S), scheduler)
    }
}
