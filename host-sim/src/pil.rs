//! Processor-in-the-loop: host-sim's plant, hand and effects at one end, the
//! board's loop at the other, exchanging one sensor frame and one actuator
//! frame per tick over the link protocol (lockstep).
//!
//! The board end is a [`BoardPort`]: a serial port (the firmware in QEMU
//! through a pty, or a real board), or the same `twoport-board` loop
//! in-process. A run sends both ends the same bytes: heartbeats, sensor
//! frames and, if asked, corrupted frames and a link loss, so the in-process
//! run is the reference the firmware must match.

use crate::{Sample, Scene, Simulation};
use std::time::{Duration, Instant};
use twoport_board::excalibur::{self, REGION_POINTS};
use twoport_board::Board;
use twoport_control::servo::{SensorFrame, ServoOutput};
use twoport_control::ve::UnilateralWall;
use twoport_control::Position;
use twoport_link::{
    encode, Decoder, LinkStats, Message, Role, SensorFrame as LinkSensors, Telemetry, MAX_FRAME,
};

/// How long the host waits for the board's answer to one frame.
pub const ANSWER_TIMEOUT: Duration = Duration::from_secs(5);
/// Heartbeats go out every this many ticks (the board's watchdog allows
/// [`excalibur::HEARTBEAT_TIMEOUT_TICKS`]).
pub const HEARTBEAT_EVERY: u64 = 10;

/// The board end of the link.
pub trait BoardPort {
    /// Send bytes to the board.
    fn send(&mut self, bytes: &[u8]) -> Result<(), String>;
    /// Bytes from the board: waits up to `timeout` for at least one.
    fn recv(&mut self, buf: &mut [u8], timeout: Duration) -> Result<usize, String>;
}

/// A serial port: the firmware in QEMU (`-serial pty`) or a real board.
pub struct SerialBoard(Box<dyn serialport::SerialPort>);

impl SerialBoard {
    /// Open `path` (115200 8N1; a pty ignores the rate).
    pub fn open(path: &str) -> Result<Self, String> {
        serialport::new(path, 115_200)
            .timeout(Duration::from_millis(20))
            .open()
            .map(SerialBoard)
            .map_err(|e| format!("serial port {path}: {e}"))
    }
}

impl BoardPort for SerialBoard {
    fn send(&mut self, bytes: &[u8]) -> Result<(), String> {
        std::io::Write::write_all(&mut self.0, bytes).map_err(|e| format!("serial write: {e}"))
    }
    fn recv(&mut self, buf: &mut [u8], timeout: Duration) -> Result<usize, String> {
        let _ = self.0.set_timeout(timeout);
        match std::io::Read::read(&mut self.0, buf) {
            Ok(n) => Ok(n),
            Err(e) if e.kind() == std::io::ErrorKind::TimedOut => Ok(0),
            Err(e) => Err(format!("serial read: {e}")),
        }
    }
}

/// The Excalibur board image's loop, in this process.
pub struct LocalBoard {
    board: Board<UnilateralWall, REGION_POINTS>,
    out: Vec<u8>,
}

impl LocalBoard {
    /// The image the firmware ships ([`excalibur::stiff_wall_board`]).
    pub fn excalibur() -> Result<Self, String> {
        Ok(LocalBoard {
            board: excalibur::stiff_wall_board()
                .map_err(|e| format!("the Excalibur board image: {e:?}"))?,
            out: Vec::new(),
        })
    }
}

impl BoardPort for LocalBoard {
    fn send(&mut self, bytes: &[u8]) -> Result<(), String> {
        // Byte by byte, as a UART delivers them.
        for &b in bytes {
            self.board.on_bytes(&[b]);
            while let Some(f) = self.board.pop_tx() {
                self.out.extend_from_slice(&f);
            }
        }
        Ok(())
    }
    fn recv(&mut self, buf: &mut [u8], _: Duration) -> Result<usize, String> {
        let n = buf.len().min(self.out.len());
        buf[..n].copy_from_slice(&self.out[..n]);
        self.out.drain(..n);
        Ok(n)
    }
}

/// What to do to the link during a run.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Faults {
    /// Every this many ticks, send a corrupted copy of the tick's sensor
    /// frame (one byte flipped) and a burst of garbage first (0: never).
    pub corrupt_every: u64,
    /// Stop the heartbeats from this tick on (a lost host).
    pub link_loss_at: Option<u64>,
}

/// One PIL run's record.
#[derive(Clone, Debug, Default)]
pub struct Run {
    /// One sample per tick.
    pub samples: Vec<Sample>,
    /// The duty the board answered each tick.
    pub duties: Vec<i16>,
    /// Telemetry received.
    pub telemetry: Vec<Telemetry>,
    /// Frames the host injected corrupted.
    pub corrupted_sent: u64,
    /// The board's link counters at the end.
    pub board_stats: LinkStats,
    /// Host-side frames dropped from the board.
    pub host_dropped: u32,
    /// Ticks from the link loss to the first zero duty that stayed zero.
    pub zero_after_loss_ticks: Option<u64>,
}

/// The host side of the link.
struct Host<'a, P: BoardPort> {
    port: &'a mut P,
    seq: u16,
    decoder: Decoder,
    inbox: Vec<Message>,
}

impl<P: BoardPort> Host<'_, P> {
    fn frame(&mut self, msg: &Message) -> Result<Vec<u8>, String> {
        let mut buf = [0u8; MAX_FRAME];
        let n = encode(self.seq, msg, &mut buf).map_err(|e| format!("encode: {e:?}"))?;
        self.seq = self.seq.wrapping_add(1);
        Ok(buf[..n].to_vec())
    }

    fn send(&mut self, msg: &Message) -> Result<(), String> {
        let f = self.frame(msg)?;
        self.port.send(&f)
    }

    /// Read until `want` picks a message out, or time out.
    fn wait<T>(
        &mut self,
        what: &str,
        mut want: impl FnMut(&Message) -> Option<T>,
    ) -> Result<T, String> {
        let deadline = Instant::now() + ANSWER_TIMEOUT;
        loop {
            if let Some(i) = self.inbox.iter().position(|m| want(m).is_some()) {
                let m = self.inbox.remove(i);
                return want(&m).ok_or_else(|| "unreachable".to_string());
            }
            let now = Instant::now();
            if now > deadline {
                return Err(format!(
                    "the board did not answer {what} within {} s",
                    ANSWER_TIMEOUT.as_secs()
                ));
            }
            let mut buf = [0u8; 256];
            let n = self
                .port
                .recv(&mut buf, (deadline - now).min(Duration::from_millis(50)))?;
            let inbox = &mut self.inbox;
            self.decoder.feed(&buf[..n], |env| inbox.push(env.msg));
        }
    }

    /// Hello until the board answers (a pty drops what is sent before the
    /// other end opens it).
    fn handshake(&mut self) -> Result<(), String> {
        let deadline = Instant::now() + ANSWER_TIMEOUT;
        loop {
            self.send(&Message::hello(Role::Host))?;
            let mut buf = [0u8; 256];
            let n = self.port.recv(&mut buf, Duration::from_millis(100))?;
            let inbox = &mut self.inbox;
            self.decoder.feed(&buf[..n], |env| inbox.push(env.msg));
            if let Some(i) = self
                .inbox
                .iter()
                .position(|m| matches!(m, Message::HelloAck { .. }))
            {
                return match self.inbox.remove(i) {
                    Message::HelloAck { accepted: true, .. } => Ok(()),
                    Message::HelloAck { version, .. } => Err(format!(
                        "the board speaks protocol {version}, this host {}",
                        twoport_link::PROTOCOL_VERSION
                    )),
                    _ => Err("unreachable".into()),
                };
            }
            if Instant::now() > deadline {
                return Err("no handshake answer from the board".into());
            }
        }
    }
}

/// The scene's sensors must be the board's: the same encoder.
pub fn check_scene(scene: &Scene) -> Result<(), String> {
    let (bits, pm) = excalibur::ENCODER;
    match scene.effects.encoder {
        Some(e) if e.bits == bits && (e.resolution_m * 1e12).round() as i64 == pm => Ok(()),
        _ => Err(format!(
            "the scene's encoder must be the board's ({bits} bits, {} um per count): \
             set effects.encoder = {{ resolution_m = {:e}, bits = {bits} }}",
            pm as f64 * 1e-6,
            pm as f64 * 1e-12
        )),
    }
}

/// Run `scene` for `ticks` against the board at `port`.
pub fn run<P: BoardPort>(
    scene: Scene,
    ticks: u64,
    port: &mut P,
    faults: Faults,
) -> Result<Run, String> {
    check_scene(&scene)?;
    let mut sim = Simulation::new(scene)?;
    let mut host = Host {
        port,
        seq: 0,
        decoder: Decoder::new(),
        inbox: Vec::new(),
    };
    host.handshake()?;
    host.send(&Message::Enable)?;
    let mut r = Run::default();
    let io = twoport_board::IoScale::EXCALIBUR;
    let mut error = None;
    for tick in 0..ticks {
        let lost = faults.link_loss_at.is_some_and(|t| tick >= t);
        if tick % HEARTBEAT_EVERY == 0 && !lost {
            host.send(&Message::Heartbeat)?;
        }
        let mut duty_seen = 0i16;
        let mut ctl = |f: &SensorFrame| -> ServoOutput {
            let sensors = Message::Sensors(LinkSensors {
                tick: f.tick,
                encoder_raw: f.encoder_raw,
                load_cell_raw: (f.load_cell_n / io.load_cell_n_per_count).round() as i32,
                dead_man_closed: f.dead_man_closed,
            });
            let answer = (|| {
                let good = host.frame(&sensors)?;
                if faults.corrupt_every > 0
                    && tick % faults.corrupt_every == faults.corrupt_every / 2
                {
                    let mut bad = good.clone();
                    let i = bad.len() / 2;
                    bad[i] ^= 0x5A;
                    if bad[i] == 0 {
                        bad[i] = 0x33;
                    }
                    host.port.send(&[0x17, 0xFF, 0x42, 0x00])?;
                    host.port.send(&bad)?;
                    r.corrupted_sent += 2;
                }
                host.port.send(&good)?;
                let want = f.tick;
                host.wait(&format!("tick {want}"), |m| match m {
                    Message::Actuator(a) if a.tick == want => Some(a.duty),
                    _ => None,
                })
            })();
            let duty = match answer {
                Ok(d) => d,
                Err(e) => {
                    error = Some(e);
                    0
                }
            };
            duty_seen = duty;
            ServoOutput {
                actuator_force_n: io.force_n(duty),
                commanded_force_n: io.force_n(duty),
                position: Position::ZERO,
                ..ServoOutput::default()
            }
        };
        let s = sim.step_external(&mut ctl);
        if let Some(e) = error.take() {
            return Err(e);
        }
        r.samples.push(s);
        r.duties.push(duty_seen);
        for m in host.inbox.drain(..) {
            if let Message::Telemetry(t) = m {
                r.telemetry.push(t);
            }
        }
    }
    host.send(&Message::GetStats)?;
    r.board_stats = host.wait("GetStats", |m| match m {
        Message::Stats(s) => Some(*s),
        _ => None,
    })?;
    r.host_dropped = host.decoder.stats().dropped();
    if let Some(t0) = faults.link_loss_at {
        // The last tick with a non-zero duty after the loss, plus one.
        let after = r.duties.iter().skip(t0 as usize);
        let last_nonzero = after.clone().rposition(|d| *d != 0);
        r.zero_after_loss_ticks = Some(last_nonzero.map_or(0, |i| i as u64 + 1));
    }
    Ok(r)
}

/// How far two runs of the same scene drift apart.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct Comparison {
    /// Ticks compared.
    pub ticks: u64,
    /// Largest handle-position difference (m).
    pub max_position_error_m: f64,
    /// Largest actuator-force difference (N).
    pub max_force_error_n: f64,
    /// Ticks whose duty differs.
    pub duty_mismatches: u64,
}

/// Compare a run with its reference, tick by tick.
pub fn compare(a: &Run, b: &Run) -> Comparison {
    let mut c = Comparison {
        ticks: a.samples.len().min(b.samples.len()) as u64,
        ..Comparison::default()
    };
    for (x, y) in a.samples.iter().zip(&b.samples) {
        c.max_position_error_m = c.max_position_error_m.max((x.handle_m - y.handle_m).abs());
        c.max_force_error_n = c.max_force_error_n.max((x.actuator_n - y.actuator_n).abs());
    }
    c.duty_mismatches = a
        .duties
        .iter()
        .zip(&b.duties)
        .filter(|(x, y)| x != y)
        .count() as u64;
    c
}
