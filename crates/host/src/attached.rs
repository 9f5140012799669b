//! What is plugged into this computer that twoport can drive: its serial
//! ports with their USB ids, a Falcon the kernel has not given a port,
//! and OpenHaptics' library for a Touch.

use crate::falcon::protocol::{USB_PRODUCT_ID, USB_VENDOR_ID};
use std::path::{Path, PathBuf};

/// A serial port, and what twoport makes of it.
#[derive(Clone, Debug, PartialEq)]
pub struct AttachedPort {
    /// Its path (`/dev/ttyUSB0`).
    pub path: String,
    /// Its USB vendor and product ids, where it is a USB device.
    pub usb: Option<(u16, u16)>,
    /// What the device calls itself.
    pub product: Option<String>,
    /// The device twoport takes it for (`twoport spec`'s name), if any.
    pub device: Option<&'static str>,
    /// Whether this program may open it, or why not and what to do.
    pub open: Result<(), String>,
}

/// The device a USB id is: the Falcon's FTDI chip, or an Arduino-class
/// CDC board as Haply's are.
fn device(usb: (u16, u16)) -> Option<&'static str> {
    match usb {
        (USB_VENDOR_ID, USB_PRODUCT_ID) => Some("falcon"),
        // Arduino's and Adafruit's vendor ids: the hAPI boards' Due and
        // SAMD21 kin.
        (0x2341 | 0x2a03 | 0x239a, _) => Some("haply-2diy"),
        _ => None,
    }
}

/// Every serial port this computer has.
pub fn ports() -> Vec<AttachedPort> {
    let mut out = Vec::new();
    for p in serialport::available_ports().unwrap_or_default() {
        let (usb, product) = match &p.port_type {
            serialport::SerialPortType::UsbPort(u) => (Some((u.vid, u.pid)), u.product.clone()),
            _ => (None, None),
        };
        let device = usb.and_then(device);
        // (Opened only where twoport would drive it: opening a port
        // resets some boards.)
        let open = match device {
            Some(name) => std::fs::File::options()
                .read(true)
                .write(true)
                .open(&p.port_name)
                .map(drop)
                .map_err(|e| {
                    crate::device_port::open_error(&p.port_name, e.kind(), name).to_string()
                }),
            None => Ok(()),
        };
        out.push(AttachedPort {
            path: p.port_name,
            usb,
            product,
            device,
            open,
        });
    }
    out
}

/// Falcons plugged in with no serial port: the kernel's `ftdi_sio` does
/// not know their id until twoport's udev rule adds it.
pub fn falcons_without_a_port() -> usize {
    let Ok(dir) = std::fs::read_dir("/sys/bus/usb/devices") else {
        return 0;
    };
    let id = |d: &Path, f: &str| {
        std::fs::read_to_string(d.join(f))
            .ok()
            .and_then(|s| u16::from_str_radix(s.trim(), 16).ok())
    };
    let with_port: Vec<_> = ports()
        .into_iter()
        .filter(|p| p.device == Some("falcon"))
        .collect();
    let plugged = dir
        .flatten()
        .filter(|e| {
            let d = e.path();
            (id(&d, "idVendor"), id(&d, "idProduct")) == (Some(USB_VENDOR_ID), Some(USB_PRODUCT_ID))
        })
        .count();
    plugged.saturating_sub(with_port.len())
}

/// OpenHaptics' HD library, where it is installed (for a Touch).
pub fn hd_library() -> Option<PathBuf> {
    let mut dirs: Vec<PathBuf> = std::env::var_os("LD_LIBRARY_PATH")
        .map(|v| std::env::split_paths(&v).collect())
        .unwrap_or_default();
    dirs.extend(
        [
            "/usr/lib",
            "/usr/lib64",
            "/usr/local/lib",
            "/usr/lib/x86_64-linux-gnu",
        ]
        .map(PathBuf::from),
    );
    dirs.into_iter()
        .map(|d| d.join(twoport_hd::DEFAULT_NAME))
        .find(|p| p.exists())
}

/// Where the device `name`'s image calibrates (rad, a joint each): hold
/// the handle there and calibrate the board there after
/// [`open`]ing it.
pub fn rest_pose(name: &str) -> Result<Vec<f64>, crate::LinkError> {
    let rest: &[f32] = match name {
        "haply-2diy" => &twoport_board::linkage::haply::HAPLY.rest_rad,
        "falcon" => &twoport_board::linkage::FALCON.rest_rad,
        "touch" => &twoport_board::linkage::touch::TOUCH.rest_rad,
        other => {
            return Err(crate::LinkError::Image(format!(
                "{other}: not a device twoport drives (haply-2diy, falcon, touch)"
            )))
        }
    };
    Ok(rest.iter().map(|q| f64::from(*q)).collect())
}

/// The device `name` (`twoport spec`'s: `haply-2diy`, `falcon` or
/// `touch`) at `path`, wired and held as its driver does by default (a
/// Haply v3 with a grip switch on analog pin 2; a Falcon's center button;
/// a Touch's first stylus button), its image running in the PC's loop;
/// with its axes. A Falcon needs Novint's `firmware` file. A Touch's
/// `path` is its name in Touch Setup (empty: the default device), and
/// `firmware`, where given, the HD library's path (by default the
/// system's `libHD.so`).
pub fn open(
    name: &str,
    path: &str,
    firmware: Option<&Path>,
) -> Result<(crate::PcBoard, u8), crate::LinkError> {
    open_with(name, path, firmware, None)
}

/// [`open`], its image accepting gains outside its proven region where
/// `unproven_gains` says why: the user's explicit choice, logged
/// ([`accept_unproven_gains`](crate::accept_unproven_gains)).
pub fn open_with(
    name: &str,
    path: &str,
    firmware: Option<&Path>,
    unproven_gains: Option<&str>,
) -> Result<(crate::PcBoard, u8), crate::LinkError> {
    use crate::device_port::Grip;
    let bad = |why: String| crate::LinkError::Open {
        path: path.to_string(),
        why,
    };
    let why = || unproven_gains.map(str::to_string);
    match name {
        "haply-2diy" => {
            let grip = Grip::Pin {
                pin: 2,
                closed_above: 0.5,
            };
            let config = crate::haply::HaplyConfig {
                unproven_gains: why(),
                ..crate::haply::HaplyConfig::v3(grip)
            };
            Ok((crate::PcBoard::haply(path, &config)?, 2))
        }
        "falcon" => {
            let firmware = firmware.ok_or_else(|| {
                bad(
                    "the Falcon needs Novint's firmware file, which twoport does not ship: \
                     name it"
                        .into(),
                )
            })?;
            let config = crate::falcon::FalconConfig {
                unproven_gains: why(),
                ..crate::falcon::FalconConfig::new(firmware)
            };
            Ok((crate::PcBoard::falcon(path, &config)?, 3))
        }
        "touch" => {
            let config = crate::touch::TouchConfig {
                library: firmware.map(Path::to_path_buf),
                device: (!path.is_empty()).then(|| path.to_string()),
                unproven_gains: why(),
                ..crate::touch::TouchConfig::stylus_button()
            };
            Ok((crate::PcBoard::touch(&config)?, 3))
        }
        other => Err(bad(format!(
            "{other}: not a device twoport drives (haply-2diy, falcon, touch)"
        ))),
    }
}
