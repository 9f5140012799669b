//! A Haply 2DIY's hAPI board on a pseudo-terminal: it reads the host's
//! reset, setup and torque packets (`twoport_host::haply::protocol`), turns
//! each torque packet into one period of the pantograph's nonlinear plant
//! (`models/linkages/haply_2diy.toml`) under a simulated hand, and answers
//! with the encoders' angles as the board does.
//!
//! The plant advances one period for each torque packet, whenever it
//! comes: what a run shows does not depend on how fast the machine is.

use crate::engine::linkage::{CartesianHand, LinkageArm};
use crate::Error;
use nalgebra::DMatrix;
use serialport::{SerialPort, TTYPort};
use std::io::{ErrorKind, Read, Write};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::Duration;
use twoport_board::linkage::haply::HAPLY;
use twoport_board::linkage::PERIOD_S;
use twoport_design::linkage::LinkageFile;
use twoport_host::haply::protocol::{self, PacketError, Setup};

/// Runge-Kutta steps a period.
const SUBSTEPS: u32 = 4;

/// The port each of the plant's joints (`q1`, `q2`) is wired to, as Haply
/// wires the hardware v3.
pub const WIRING: [u8; 2] = [2, 1];

/// What the emulated board does wrong, from a given torque packet on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fault {
    /// It reads the packets and answers none.
    Silent,
    /// It answers with the reply's first half only.
    ShortReply,
    /// It answers with another device's id.
    WrongId,
    /// Its USB goes away: the port closes.
    Unplug,
}

/// The hand on the handle: a grasp of `grasp_nspm` in every direction and
/// a spring of `stiffness_npm` holding it at the rest pose until told to
/// press ([`Emulator::press`]), then pulling toward an anchor `push_m` past
/// the rest pose along `-y` (toward the motors, into the image's wall); its
/// grip switch reads 1.0 (0.0 with no hand).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hand {
    /// The grasp's damping (N s/m).
    pub grasp_nspm: f64,
    /// The spring's stiffness (N/m).
    pub stiffness_npm: f64,
    /// How far past the rest pose its anchor is, along `-y` (m).
    pub push_m: f64,
}

/// What the emulator has seen and done.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Trace {
    /// Torque packets answered (periods run).
    pub ticks: u64,
    /// The handle's position after each period (m), `(x, y)`.
    pub handle_m: Vec<[f64; 2]>,
    /// The torque each motor held each period (N m, toward larger
    /// angles), after the board's saturation.
    pub torque_nm: Vec<[f32; 2]>,
    /// The setup the host sent, once it has: its joints in port order, as
    /// the board knows them.
    pub setup: Option<Setup<2>>,
    /// Resets read.
    pub resets: u32,
    /// Why the emulator stopped reading, if it has.
    pub stopped: Option<String>,
}

/// A 2DIY's board on a pseudo-terminal, its plant running in a thread.
pub struct Emulator {
    path: String,
    trace: Arc<Mutex<Trace>>,
    stop: Arc<AtomicBool>,
    press: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
    // (The terminal's other end, held open so that the port stays up
    // between a driver's opens.)
    _slave: TTYPort,
}

/// The shipped 2DIY file.
pub fn file() -> Result<LinkageFile, Error> {
    LinkageFile::from_toml(
        include_str!("../../../models/linkages/haply_2diy.toml"),
        "haply_2diy.toml",
    )
    .map_err(|e| Error::Sim(e.to_string()))
}

impl Emulator {
    /// The board, the pantograph at the image's rest pose under `hand`,
    /// going wrong as `fault` says from that torque packet on.
    pub fn start(hand: Option<Hand>, fault: Option<(u64, Fault)>) -> Result<Self, Error> {
        let file = file()?;
        let arm = LinkageArm::<2>::at_rest(&file, HAPLY.rest_rad.map(f64::from))
            .map_err(|e| Error::Sim(format!("the 2DIY's plant: {e:?}")))?;
        let (master, slave) =
            TTYPort::pair().map_err(|e| Error::Sim(format!("a pseudo-terminal: {e}")))?;
        let path = slave
            .name()
            .ok_or_else(|| Error::Sim("the pseudo-terminal has no name".into()))?;
        let (rest_m, _) = arm
            .handle()
            .map_err(|e| Error::Sim(format!("the 2DIY's plant: {e:?}")))?;
        let trace = Arc::new(Mutex::new(Trace::default()));
        let stop = Arc::new(AtomicBool::new(false));
        let press = Arc::new(AtomicBool::new(false));
        let board = Board {
            press: Arc::clone(&press),
            port: master,
            arm,
            hand,
            fault,
            trace: Arc::clone(&trace),
            stop: Arc::clone(&stop),
            setup: None,
            buf: Vec::new(),
            rest_m,
        };
        let thread = std::thread::Builder::new()
            .name("haply-emulator".into())
            .spawn(move || board.run())
            .map_err(|e| Error::Sim(format!("the emulator's thread: {e}")))?;
        Ok(Emulator {
            path,
            trace,
            stop,
            press,
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
        self.press.store(true, Ordering::Relaxed);
    }

    /// Torque packets answered so far.
    pub fn ticks(&self) -> u64 {
        self.trace.lock().unwrap_or_else(|p| p.into_inner()).ticks
    }

    /// What it has seen and done so far.
    pub fn trace(&self) -> Trace {
        self.trace.lock().unwrap_or_else(|p| p.into_inner()).clone()
    }
}

impl Drop for Emulator {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// The board's side: the port, the plant and what it was told.
struct Board {
    port: TTYPort,
    arm: LinkageArm<2>,
    hand: Option<Hand>,
    fault: Option<(u64, Fault)>,
    trace: Arc<Mutex<Trace>>,
    stop: Arc<AtomicBool>,
    press: Arc<AtomicBool>,
    setup: Option<Setup<2>>,
    buf: Vec<u8>,
    /// The handle at the rest pose (m).
    rest_m: [f64; 2],
}

impl Board {
    fn run(mut self) {
        let _ = self.port.set_timeout(Duration::from_millis(20));
        let why = loop {
            if self.stop.load(Ordering::Relaxed) {
                break "stopped".to_string();
            }
            let mut chunk = [0u8; 256];
            match self.port.read(&mut chunk) {
                Ok(n) => self.buf.extend_from_slice(&chunk[..n]),
                Err(e) if matches!(e.kind(), ErrorKind::TimedOut | ErrorKind::WouldBlock) => {}
                Err(e) if e.kind() == ErrorKind::Interrupted => {}
                // (EIO: no program has the terminal's other end open.)
                Err(e) if e.raw_os_error() == Some(5) => {
                    std::thread::sleep(Duration::from_millis(5));
                }
                Err(e) => break format!("read: {e}"),
            }
            match self.serve() {
                Ok(true) => {}
                Ok(false) => break "unplugged".to_string(),
                Err(e) => break e,
            }
        };
        self.trace().stopped = Some(why);
    }

    fn trace(&self) -> std::sync::MutexGuard<'_, Trace> {
        self.trace.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// Answer every whole packet buffered; `false` once unplugged.
    fn serve(&mut self) -> Result<bool, String> {
        loop {
            let Some(&kind) = self.buf.first() else {
                return Ok(true);
            };
            let used = match kind {
                protocol::RESET if self.buf.len() >= 2 => {
                    self.setup = None;
                    self.trace().resets += 1;
                    2
                }
                protocol::SETUP => match Setup::<2>::decode(&self.buf) {
                    Ok((setup, used)) => {
                        self.trace().setup = Some(setup.clone());
                        self.setup = Some(setup);
                        used
                    }
                    Err(PacketError::Short { .. }) => return Ok(true),
                    Err(e) => return Err(format!("setup: {e}")),
                },
                protocol::TORQUES if self.buf.len() >= Setup::<2>::torques_len() => {
                    let n = Setup::<2>::torques_len();
                    // A board not set up answers nothing.
                    if let Some(setup) = self.setup.clone() {
                        let torque = setup
                            .decode_torques(&self.buf[..n])
                            .map_err(|e| format!("torques: {e}"))?;
                        if !self.tick(&setup, torque)? {
                            return Ok(false);
                        }
                    }
                    n
                }
                protocol::RESET | protocol::TORQUES => return Ok(true),
                other => return Err(format!("{}", PacketError::Type(other))),
            };
            self.buf.drain(..used);
        }
    }

    /// One period under `torque` (N m, toward larger angles), and the
    /// reply; `false` once unplugged.
    fn tick(&mut self, setup: &Setup<2>, torque: [f32; 2]) -> Result<bool, String> {
        let peak = HAPLY.hardware.peak_torque_nm;
        // The board knows its joints by port: the wiring says which is the
        // plant's `q1` and which its `q2`.
        let at = WIRING.map(|port| setup.joints.iter().position(|j| j.port == port));
        let [Some(a), Some(b)] = at else {
            return Err(format!("a setup without ports {WIRING:?}: {setup:?}"));
        };
        let held = [torque[a], torque[b]].map(|t| {
            if t.is_finite() {
                t.clamp(-peak, peak)
            } else {
                0.0
            }
        });
        // The plant's torque resists the joint's motion.
        let tau = held.map(|t| -f64::from(t));
        let x0 = self.rest_m;
        let push = self.press.load(Ordering::Relaxed);
        let hand = self.hand.map(|h| CartesianHand {
            anchor_m: vec![x0[0], x0[1] - if push { h.push_m } else { 0.0 }],
            k_npm: DMatrix::identity(2, 2) * h.stiffness_npm,
            b_nspm: DMatrix::identity(2, 2) * h.grasp_nspm,
        });
        let off = CartesianHand::off(2);
        let h = hand.as_ref().unwrap_or(&off);
        self.arm
            .step(&tau, &|x, v| h.force(x, v), f64::from(PERIOD_S), SUBSTEPS)
            .map_err(|e| format!("the plant: {e:?}"))?;
        let (x, _) = self.arm.handle().map_err(|e| format!("the plant: {e:?}"))?;
        let tick = {
            let mut t = self.trace();
            t.ticks += 1;
            t.handle_m.push(x);
            t.torque_nm.push(held);
            t.ticks
        };
        let grip = if self.hand.is_some() { 1.0 } else { 0.0 };
        let plant = self.arm.counts().map(|c| c as i32);
        let mut counts = [0; 2];
        (counts[a], counts[b]) = (plant[0], plant[1]);
        let mut reply = setup.reply(&vec![grip; setup.sensor_pins.len()], counts);
        match self.fault {
            Some((from, fault)) if tick >= from => match fault {
                Fault::Silent => return Ok(true),
                Fault::ShortReply => reply.truncate(reply.len() / 2),
                Fault::WrongId => reply[0] = reply[0].wrapping_add(1),
                Fault::Unplug => return Ok(false),
            },
            _ => {}
        }
        self.port
            .write_all(&reply)
            .map_err(|e| format!("write: {e}"))?;
        Ok(true)
    }
}
