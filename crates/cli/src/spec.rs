//! `twoport devices` and `twoport spec DEVICE`: the devices whose servo
//! loop runs on the PC, each with the coupling proven over its workspace at
//! its loop's rate and with the latency its protocol gives, beside the
//! stiffness CHAI3D sets for it by hand.

use serde::Serialize;
use std::fmt;
use twoport_design::linkage::{certified_design_from, least_damping, LinkageFile};

/// A device a lab drives from the PC.
struct Known {
    /// The name `twoport spec` takes.
    name: &'static str,
    /// What it is.
    title: &'static str,
    /// Its linkage file, where one is published: (path, text).
    file: Option<(&'static str, &'static str)>,
    /// The PC's servo rate (Hz).
    rate_hz: f64,
    /// From a sample to its force, in ticks, and why.
    latency_ticks: f64,
    latency_why: &'static str,
    /// CHAI3D's hand-set (force N, stiffness N/m, damping N s/m).
    chai3d: Option<(f64, f64, f64)>,
    /// The coupling twoport's driver runs, where it drives the device.
    driven: Option<twoport_control::ImpedanceGains>,
}

const KNOWN: [Known; 3] = [
    Known {
        name: "falcon",
        title: "Novint Falcon (rotary delta, USB through an FTDI chip)",
        file: Some((
            "models/linkages/falcon_like.toml",
            include_str!("../../../models/linkages/falcon_like.toml"),
        )),
        rate_hz: 1000.0,
        latency_ticks: 2.0,
        latency_why: "the PC hands a tick's torques to the next exchange (one tick), and the \
                      FTDI chip's 1 ms latency timer can hold the encoders' packet a tick more",
        chai3d: Some((8.0, 3000.0, 20.0)),
        driven: Some(twoport_board::linkage::falcon_pc::IMAGE.coupling),
    },
    Known {
        name: "haply-2diy",
        title: "Haply 2DIY (five-bar pantograph, USB serial)",
        file: Some((
            "models/linkages/haply_2diy.toml",
            include_str!("../../../models/linkages/haply_2diy.toml"),
        )),
        rate_hz: 1000.0,
        latency_ticks: 2.0,
        latency_why: "the PC hands a tick's torques to the next exchange (one tick), and the \
                      board answers a torque packet with its encoders within the next 1 ms USB \
                      frame",
        chai3d: None,
        driven: Some(twoport_board::linkage::haply::IMAGE.coupling),
    },
    Known {
        name: "touch",
        title: "3D Systems Touch (serial arm, USB through OpenHaptics)",
        file: Some((
            "models/linkages/touch.toml",
            include_str!("../../../models/linkages/touch.toml"),
        )),
        rate_hz: 1000.0,
        latency_ticks: 2.0,
        latency_why: "the PC hands a tick's torques to the next servo frame of OpenHaptics' \
                      scheduler (one tick), and the frame that applies them reads the joints \
                      again (the device's own transfer, up to a tick more)",
        chai3d: Some((3.3, 400.0, 4.0)),
        driven: Some(twoport_board::linkage::touch::IMAGE.coupling),
    },
];

/// `twoport devices`: what `twoport spec` knows, and what is plugged in.
#[derive(Serialize)]
pub(crate) struct Devices {
    devices: Vec<DeviceLine>,
    /// This computer's serial ports.
    ports: Vec<PortLine>,
    /// Falcons plugged in that the kernel has given no port.
    falcons_without_a_port: usize,
    /// OpenHaptics' HD library, where installed.
    hd_library: Option<String>,
}

#[derive(Serialize)]
struct PortLine {
    path: String,
    usb_id: Option<String>,
    product: Option<String>,
    device: Option<&'static str>,
    /// Why this program cannot open it, where it cannot.
    cannot_open: Option<String>,
}

#[derive(Serialize)]
struct DeviceLine {
    name: &'static str,
    title: &'static str,
    rate_hz: f64,
    latency_s: f64,
    model: Option<&'static str>,
}

pub(crate) fn devices() -> Devices {
    Devices {
        devices: KNOWN
            .iter()
            .map(|k| DeviceLine {
                name: k.name,
                title: k.title,
                rate_hz: k.rate_hz,
                latency_s: k.latency_ticks / k.rate_hz,
                model: k.file.map(|f| f.0),
            })
            .collect(),
        ports: twoport_host::attached::ports()
            .into_iter()
            .map(|p| PortLine {
                path: p.path,
                usb_id: p.usb.map(|(v, d)| format!("{v:04x}:{d:04x}")),
                product: p.product,
                device: p.device,
                cannot_open: p.open.err(),
            })
            .collect(),
        falcons_without_a_port: twoport_host::attached::falcons_without_a_port(),
        hd_library: twoport_host::attached::hd_library().map(|p| p.display().to_string()),
    }
}

impl fmt::Display for Devices {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "Devices whose servo loop runs on the PC (twoport spec NAME):"
        )?;
        for d in &self.devices {
            write!(
                f,
                "  {:<11} {} at {} Hz, {:.1} ms from sample to force",
                d.name,
                d.title,
                d.rate_hz,
                d.latency_s * 1e3
            )?;
            match d.model {
                Some(m) => writeln!(f, " ({m})")?,
                None => writeln!(f, " (no published model)")?,
            }
        }
        writeln!(f, "Serial ports on this computer:")?;
        if self.ports.is_empty() {
            writeln!(f, "  none")?;
        }
        for p in &self.ports {
            write!(f, "  {}", p.path)?;
            if let Some(id) = &p.usb_id {
                write!(
                    f,
                    " (USB {id}{})",
                    p.product
                        .as_deref()
                        .map(|s| format!(", {s}"))
                        .unwrap_or_default()
                )?;
            }
            match (p.device, &p.cannot_open) {
                (Some(d), None) => writeln!(f, ": a {d}? twoport can open it")?,
                (Some(d), Some(why)) => writeln!(f, ": a {d}? {why}")?,
                (None, _) => writeln!(f)?,
            }
        }
        if self.falcons_without_a_port > 0 {
            writeln!(
                f,
                "  {} Falcon(s) plugged in with no serial port: install twoport's udev rule \
                 (udev/60-twoport.rules), then unplug and plug it",
                self.falcons_without_a_port
            )?;
        }
        match &self.hd_library {
            Some(p) => writeln!(
                f,
                "OpenHaptics' HD library (for a Touch): {p}; open the Touch by its Touch Setup \
                 name (twoport_host::attached::open(\"touch\", NAME, None))"
            )?,
            None => writeln!(
                f,
                "OpenHaptics' HD library (for a Touch): not found (install 3D Systems' Touch \
                 drivers and OpenHaptics, or name the library's path when opening)"
            )?,
        }
        Ok(())
    }
}

/// `twoport spec DEVICE`: the proven coupling at the device's rate and
/// latency, hands off and for a least grasp, beside CHAI3D's hand-set one.
#[derive(Serialize)]
pub(crate) struct DeviceSpec {
    device: &'static str,
    title: &'static str,
    model: &'static str,
    rate_hz: f64,
    latency_s: f64,
    latency_why: &'static str,
    /// The stiffest coupling proven with no coupling damping (N/m), hands
    /// off (any passive hand).
    hands_off_k_npm: f64,
    /// The same for every grasp of at least `min_grasp_nspm`.
    min_grasp_nspm: f64,
    grasp_k_npm: f64,
    /// The coupling damping below which a stiffness is proven at that
    /// grasp (N s/m): the handle's least damping and the grasp's.
    grasp_b_max_nspm: f64,
    /// CHAI3D's hand-set stiffness and damping, where it has one.
    chai3d_k_npm: Option<f64>,
    chai3d_b_nspm: Option<f64>,
    /// The coupling twoport's driver runs (N/m, N s/m), and the latency
    /// (s) its region is proven for, where twoport drives the device.
    driven_k_npm: Option<f64>,
    driven_b_nspm: Option<f64>,
    driven_latency_s: Option<f64>,
}

pub(crate) fn spec(name: &str, min_grasp_nspm: f64) -> Result<DeviceSpec, String> {
    let names = || KNOWN.map(|k| k.name).join(", ");
    let k = KNOWN
        .iter()
        .find(|k| k.name == name)
        .ok_or_else(|| format!("{name}: not a device twoport knows (one of {})", names()))?;
    if !(min_grasp_nspm.is_finite() && min_grasp_nspm >= 0.0) {
        return Err(format!(
            "--min-grasp {min_grasp_nspm}: must be a finite damping >= 0 N s/m"
        ));
    }
    let (path, text) = k.file.ok_or_else(|| {
        format!(
            "{name}: no model of the {} is published; identify one at a pose \
             (twoport identify-pose) and prove it with twoport design impedance --device",
            k.title
        )
    })?;
    let mut file = LinkageFile::from_toml(text, path).map_err(|e| format!("{path}: {e}"))?;
    file.period_s = 1.0 / k.rate_hz;
    file.latency_s = k.latency_ticks * file.period_s;
    let least = least_damping(&file).map_err(|e| format!("{path}: {e}"))?;
    let proven = |grasp: f64| {
        certified_design_from(&file, &least, 0.0, grasp, None)
            .map(|d| d.k_c_npm)
            .map_err(|e| e.to_string())
    };
    Ok(DeviceSpec {
        device: k.name,
        title: k.title,
        model: path,
        rate_hz: k.rate_hz,
        latency_s: file.latency_s,
        latency_why: k.latency_why,
        hands_off_k_npm: proven(0.0)?,
        min_grasp_nspm,
        grasp_k_npm: proven(min_grasp_nspm)?,
        grasp_b_max_nspm: least.bound + min_grasp_nspm,
        chai3d_k_npm: k.chai3d.map(|c| c.1),
        chai3d_b_nspm: k.chai3d.map(|c| c.2),
        driven_k_npm: k.driven.map(|c| f64::from(c.k_npm)),
        driven_b_nspm: k.driven.map(|c| f64::from(c.b_nspm)),
        driven_latency_s: k
            .driven
            .map(|_| f64::from(twoport_board::linkage::pc::LATENCY_S)),
    })
}

impl fmt::Display for DeviceSpec {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "{} ({})", self.title, self.model)?;
        writeln!(
            f,
            "  loop: {} Hz on the PC, {:.1} ms from sample to force: {}",
            self.rate_hz,
            self.latency_s * 1e3,
            self.latency_why
        )?;
        writeln!(
            f,
            "  proven over the workspace (b_c = 0): {:.1} N/m hands off; {:.0} N/m for a grasp \
             of at least {} N s/m (b_c below {:.3} N s/m)",
            (self.hands_off_k_npm * 10.0).floor() / 10.0,
            self.grasp_k_npm.floor(),
            self.min_grasp_nspm,
            self.grasp_b_max_nspm
        )?;
        match (self.driven_k_npm, self.driven_b_nspm, self.driven_latency_s) {
            (Some(k), Some(b), Some(l)) => writeln!(
                f,
                "  twoport's driver runs {k:.0} N/m at {b} N s/m, proven over the workspace for \
                 a grasp of at least 2 N s/m at {:.0} ms (the protocol's and the PC's scheduling): docs/devices.md",
                l * 1e3
            )?,
            _ => writeln!(f, "  twoport does not drive this device yet")?,
        }
        match (self.chai3d_k_npm, self.chai3d_b_nspm) {
            (Some(k), Some(b)) => write!(
                f,
                "  CHAI3D sets {k:.0} N/m and {b} N s/m by hand: {:.1} times the grasp's proof",
                k / self.grasp_k_npm
            ),
            _ => write!(f, "  CHAI3D has no specification of this device"),
        }
    }
}
