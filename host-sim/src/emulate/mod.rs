//! Devices emulated on a pseudo-terminal, byte for byte as their protocols
//! speak, with the simulator's linkage plant behind them: a driver opens
//! the emulator's port as it opens the device's.
//!
//! The plant advances one period for each command packet, whenever it
//! comes: what a run shows does not depend on how fast the machine is.
//! Each device's firmware ([`Firmware`]) reads the host's bytes and
//! answers; this module holds what every emulated device shares: the
//! terminal, the thread, the plant under a hand, the faults and the trace.

pub mod falcon;
pub mod haply;

use crate::engine::linkage::{CartesianHand, LinkageArm};
use crate::Error;
use nalgebra::DMatrix;
use serialport::{SerialPort, TTYPort};
use std::io::{ErrorKind, Read, Write};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};
use std::thread::JoinHandle;
use std::time::Duration;
use twoport_board::linkage::ImageSpec;
use twoport_design::linkage::LinkageFile;

/// Runge-Kutta steps a period.
const SUBSTEPS: u32 = 4;

/// What the emulated device does wrong, from a given command on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fault {
    /// It reads the commands and answers none.
    Silent,
    /// It answers with the reply's first half only.
    ShortReply,
    /// It answers with a reply garbled as its protocol can be (another
    /// device's id, a broken frame).
    Garbled,
    /// Its USB goes away: the port closes.
    Unplug,
}

/// The hand on the handle: a grasp of `grasp_nspm` in every direction;
/// until told to press ([`Emulator::press`]), a firm hold at the rest
/// pose ([`HOLD_NPM`]: the user holding the handle where the driver
/// calibrates it), then a spring of `stiffness_npm` pulling toward an
/// anchor `push_m` past the rest pose along the last axis, downward (into
/// the images' wall); its grip switch closed (open with no hand).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EmulatedHand {
    /// The grasp's damping (N s/m).
    pub grasp_nspm: f64,
    /// The spring's stiffness (N/m).
    pub stiffness_npm: f64,
    /// How far past the rest pose its anchor is, along the last axis,
    /// downward (m).
    pub push_m: f64,
}

/// The hand of the drivers' wall runs: a 2 N s/m grasp (the PC images'
/// least) and a 100 N/m spring pressing 10 mm past the rest pose, 5 mm
/// past the images' wall.
pub const PRESSING: EmulatedHand = EmulatedHand {
    grasp_nspm: 2.0,
    stiffness_npm: 100.0,
    push_m: 0.010,
};

/// The hand's hold at the rest pose before it presses (N/m): a 60 g
/// handle sags 0.3 mm on it under gravity.
pub const HOLD_NPM: f64 = 2_000.0;

/// What the emulator has seen and done.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Trace<const N: usize> {
    /// Commands answered (periods run).
    pub ticks: u64,
    /// The handle's position after each period (m).
    pub handle_m: Vec<[f64; N]>,
    /// The torque each joint's motor held each period (N m, toward larger
    /// angles), after the device's saturation.
    pub torque_nm: Vec<[f32; N]>,
    /// What the firmware noted, in order (a setup read, a reset, a
    /// loader's step).
    pub events: Vec<String>,
    /// Why the emulator stopped reading, if it has.
    pub stopped: Option<String>,
    /// The period after which the hand began to press, once it has.
    pub pressed_at: Option<u64>,
}

/// A trace as a file holds it (JSON): the joints' arrays as lists.
#[derive(serde::Serialize, serde::Deserialize)]
struct TraceFile {
    ticks: u64,
    handle_m: Vec<Vec<f64>>,
    torque_nm: Vec<Vec<f32>>,
    events: Vec<String>,
    stopped: Option<String>,
    pressed_at: Option<u64>,
}

impl<const N: usize> Trace<N> {
    /// The trace as JSON, for an emulator in another library (the HD
    /// stand-in's) to hand to its test.
    pub fn to_json(&self) -> String {
        let file = TraceFile {
            ticks: self.ticks,
            handle_m: self.handle_m.iter().map(|x| x.to_vec()).collect(),
            torque_nm: self.torque_nm.iter().map(|t| t.to_vec()).collect(),
            events: self.events.clone(),
            stopped: self.stopped.clone(),
            pressed_at: self.pressed_at,
        };
        serde_json::to_string(&file).unwrap_or_default()
    }

    /// The trace [`Trace::to_json`] wrote.
    pub fn from_json(text: &str) -> Result<Self, Error> {
        let bad = |what: &str| Error::Sim(format!("a trace file: {what}"));
        let f: TraceFile = serde_json::from_str(text).map_err(|e| bad(&e.to_string()))?;
        let fixed =
            |v: &Vec<f64>| <[f64; N]>::try_from(v.as_slice()).map_err(|_| bad("a pose's length"));
        let fixed32 =
            |v: &Vec<f32>| <[f32; N]>::try_from(v.as_slice()).map_err(|_| bad("a torque's length"));
        Ok(Trace {
            ticks: f.ticks,
            handle_m: f.handle_m.iter().map(fixed).collect::<Result<_, _>>()?,
            torque_nm: f.torque_nm.iter().map(fixed32).collect::<Result<_, _>>()?,
            events: f.events,
            stopped: f.stopped,
            pressed_at: f.pressed_at,
        })
    }
}

/// A device's firmware: what it does with the bytes the host sends.
pub trait Firmware<const N: usize>: Send + 'static {
    /// Take the whole packets at the front of `rx` (draining what it
    /// used), the host's port at `baud`; step `device` for each command,
    /// and put the answers in `tx`.
    fn serve(
        &mut self,
        rx: &mut Vec<u8>,
        baud: u32,
        device: &mut EmulatedDevice<N>,
        tx: &mut Vec<u8>,
    ) -> Result<(), String>;
}

/// The plant behind the firmware, the hand on it, and what it is told to
/// do wrong.
pub struct EmulatedDevice<const N: usize> {
    arm: LinkageArm<N>,
    spec: ImageSpec<N>,
    hand: Option<EmulatedHand>,
    rest_m: [f64; N],
    fault: Option<(u64, Fault)>,
    shared: Arc<Shared<N>>,
    unplugged: bool,
}

/// What the emulator's thread and its owner share.
struct Shared<const N: usize> {
    trace: Mutex<Trace<N>>,
    stop: AtomicBool,
    press: AtomicBool,
}

impl<const N: usize> Shared<N> {
    fn trace(&self) -> MutexGuard<'_, Trace<N>> {
        self.trace.lock().unwrap_or_else(|p| p.into_inner())
    }

    fn press(&self) {
        let mut t = self.trace();
        if !self.press.swap(true, Ordering::Relaxed) {
            t.pressed_at = Some(t.ticks);
        }
    }
}

/// What a period leaves the firmware to answer with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Period<const N: usize> {
    /// Each joint's encoder counts from the rest pose.
    pub counts: [i32; N],
    /// Whether the hand's grip switch is closed.
    pub grip: bool,
}

impl<const N: usize> EmulatedDevice<N> {
    /// The linkage `file` (its image `spec`) at rest at the image's rest
    /// pose under `hand`, with gravity along `-z` where `gravity`, going
    /// wrong as `fault` says from that command on.
    pub fn new(
        file: &LinkageFile,
        spec: ImageSpec<N>,
        gravity: bool,
        hand: Option<EmulatedHand>,
        fault: Option<(u64, Fault)>,
    ) -> Result<Self, Error> {
        let plant = |e| Error::Sim(format!("the emulated device's plant: {e}"));
        let mut arm =
            LinkageArm::<N>::at_rest(file, spec.rest_rad.map(f64::from)).map_err(plant)?;
        if gravity {
            arm.plant.gravity_mps2 = crate::pil::linkage::GRAVITY_MPS2;
        }
        let (rest_m, _) = arm.handle().map_err(plant)?;
        Ok(EmulatedDevice {
            arm,
            spec,
            hand,
            rest_m,
            fault,
            shared: Arc::new(Shared {
                trace: Mutex::new(Trace::default()),
                stop: AtomicBool::new(false),
                press: AtomicBool::new(false),
            }),
            unplugged: false,
        })
    }

    /// The hand presses from now on.
    pub fn press(&self) {
        self.shared.press();
    }

    /// What it has seen and done so far.
    pub fn trace(&self) -> Trace<N> {
        self.shared.trace().clone()
    }

    /// Periods run so far, and the one after which the hand began to
    /// press, once it has.
    pub fn ticks(&self) -> (u64, Option<u64>) {
        let t = self.shared.trace();
        (t.ticks, t.pressed_at)
    }

    /// One period with the motors holding `torque_nm` (N m, toward larger
    /// angles; clamped at the device's peak, a non-finite one held at
    /// zero).
    pub fn tick(&mut self, torque_nm: [f32; N]) -> Result<Period<N>, String> {
        let peak = self.spec.hardware.peak_torque_nm;
        let held = torque_nm.map(|t| {
            if t.is_finite() {
                t.clamp(-peak, peak)
            } else {
                0.0
            }
        });
        let joint: [f64; N] =
            core::array::from_fn(|i| f64::from(held[i] * self.spec.hardware.ratios[i]));
        // The plant's torque resists the joint's motion.
        let tau = joint.map(|t| -t);
        let mut anchor = self.rest_m.to_vec();
        let pressing = self.shared.press.load(Ordering::Relaxed);
        if pressing {
            if let (Some(h), Some(last)) = (self.hand, anchor.last_mut()) {
                *last -= h.push_m;
            }
        }
        let hand = match self.hand {
            Some(h) => CartesianHand {
                anchor_m: anchor,
                k_npm: DMatrix::identity(N, N) * if pressing { h.stiffness_npm } else { HOLD_NPM },
                b_nspm: DMatrix::identity(N, N) * h.grasp_nspm,
            },
            None => CartesianHand::off(N),
        };
        let period_s = f64::from(twoport_board::linkage::PERIOD_S);
        self.arm
            .step(&tau, &|x, v| hand.force(x, v), period_s, SUBSTEPS)
            .map_err(|e| format!("the plant: {e:?}"))?;
        let (x, _) = self.arm.handle().map_err(|e| format!("the plant: {e:?}"))?;
        let mut t = self.shared.trace();
        t.ticks += 1;
        t.handle_m.push(x);
        t.torque_nm.push(held);
        Ok(Period {
            counts: self.arm.counts().map(|c| c as i32),
            grip: self.hand.is_some(),
        })
    }

    /// Answer the period just run with `reply`, as the device's fault
    /// says: `garble` breaks it as the protocol can be broken.
    pub fn answer(
        &mut self,
        mut reply: Vec<u8>,
        garble: impl FnOnce(&mut Vec<u8>),
        tx: &mut Vec<u8>,
    ) {
        let tick = self.shared.trace().ticks;
        match self.fault {
            Some((from, fault)) if tick >= from => match fault {
                Fault::Silent => return,
                Fault::ShortReply => reply.truncate(reply.len() / 2),
                Fault::Garbled => garble(&mut reply),
                Fault::Unplug => {
                    self.unplugged = true;
                    return;
                }
            },
            _ => {}
        }
        tx.extend(reply);
    }

    /// Note what the firmware did.
    pub fn note(&self, event: impl Into<String>) {
        self.shared.trace().events.push(event.into());
    }
}

/// A device on a pseudo-terminal, its firmware and plant in a thread.
pub struct Emulator<const N: usize> {
    path: String,
    shared: Arc<Shared<N>>,
    thread: Option<JoinHandle<()>>,
    // (The terminal's other end, held open so that the port stays up
    // between a driver's opens.)
    _slave: TTYPort,
}

impl<const N: usize> Emulator<N> {
    /// `firmware` on the linkage `file` (its image `spec`), at rest at the
    /// image's rest pose under `hand`, with gravity along `-z` where
    /// `gravity` (the image holds the moving masses up), going wrong as
    /// `fault` says from that command on.
    pub fn start(
        file: &LinkageFile,
        spec: ImageSpec<N>,
        gravity: bool,
        firmware: impl Firmware<N>,
        hand: Option<EmulatedHand>,
        fault: Option<(u64, Fault)>,
    ) -> Result<Self, Error> {
        let device = EmulatedDevice::new(file, spec, gravity, hand, fault)?;
        let shared = Arc::clone(&device.shared);
        let (master, slave) =
            TTYPort::pair().map_err(|e| Error::Sim(format!("a pseudo-terminal: {e}")))?;
        let path = slave
            .name()
            .ok_or_else(|| Error::Sim("the pseudo-terminal has no name".into()))?;
        let thread = std::thread::Builder::new()
            .name("device-emulator".into())
            .spawn(move || run(master, firmware, device))
            .map_err(|e| Error::Sim(format!("the emulator's thread: {e}")))?;
        Ok(Emulator {
            path,
            shared,
            thread: Some(thread),
            _slave: slave,
        })
    }

    /// The port a driver opens.
    pub fn path(&self) -> &str {
        &self.path
    }

    /// The hand presses from now on.
    pub fn press(&self) {
        self.shared.press();
    }

    /// Commands answered so far.
    pub fn ticks(&self) -> u64 {
        self.shared.trace().ticks
    }

    /// What it has seen and done so far.
    pub fn trace(&self) -> Trace<N> {
        self.shared.trace().clone()
    }
}

impl<const N: usize> Drop for Emulator<N> {
    fn drop(&mut self) {
        self.shared.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// The emulator's thread: read, serve, answer, until stopped or unplugged
/// (the terminal's master closes with it).
fn run<const N: usize>(
    mut port: TTYPort,
    mut firmware: impl Firmware<N>,
    mut device: EmulatedDevice<N>,
) {
    let _ = port.set_timeout(Duration::from_millis(20));
    let mut rx = Vec::new();
    let why = loop {
        if device.shared.stop.load(Ordering::Relaxed) {
            break "stopped".to_string();
        }
        let mut chunk = [0u8; 256];
        match port.read(&mut chunk) {
            Ok(n) => rx.extend_from_slice(&chunk[..n]),
            Err(e) if matches!(e.kind(), ErrorKind::TimedOut | ErrorKind::WouldBlock) => {}
            Err(e) if e.kind() == ErrorKind::Interrupted => {}
            // (EIO: no program has the terminal's other end open.)
            Err(e) if e.raw_os_error() == Some(5) => {
                std::thread::sleep(Duration::from_millis(5));
            }
            Err(e) => break format!("read: {e}"),
        }
        // The rate the host's end set (a pty carries it, not its timing).
        let baud = port.baud_rate().unwrap_or(0);
        let mut tx = Vec::new();
        if let Err(e) = firmware.serve(&mut rx, baud, &mut device, &mut tx) {
            break e;
        }
        if device.unplugged {
            break "unplugged".to_string();
        }
        if !tx.is_empty() {
            if let Err(e) = port.write_all(&tx) {
                break format!("write: {e}");
            }
        }
    };
    device.shared.trace().stopped = Some(why);
}
