//! Processor-in-the-loop: host-sim's plant, hand and effects at one end, the
//! board's loop at the other, exchanging one sensor frame and one actuator
//! frame per tick over the link protocol (lockstep).
//!
//! The board end is a [`BoardPort`]: a serial port (the firmware in QEMU
//! through a pty, or a real board), or the same `twoport-board` loop
//! in-process. A run sends both ends the same bytes: heartbeats, sensor
//! frames and, if asked, corrupted frames and a link loss, so the in-process
//! run is the reference the firmware must match.

use crate::engine::sim::round_counts;
use crate::engine::xyz::{XyzSample, XyzScene, XyzSimulation};
use crate::{Sample, Scene, Simulation};
use std::collections::VecDeque;
use std::time::{Duration, Instant};
use twoport_board::excalibur::{self, xyz, REGION_POINTS};
use twoport_board::{Board, BoardSupport, RawSensors};
use twoport_config::{RamFlash, Store};
use twoport_control::passivity::SeriesDamper;
use twoport_control::servo::{Direct, PortLayer, SensorFrame, ServoOutput};
use twoport_control::ve::UnilateralWall;
use twoport_control::world::World;
use twoport_control::Faults as BoardFaults;
use twoport_link::{
    encode, Axes, ConfigSource, Decoder, LinkStats, Message, Mode, ModeRequest, Role,
    SensorFrame as LinkSensors, Status, Telemetry, MAX_FRAME,
};

/// How far a homed board's position may be from the plant's: the stop's
/// give under the homing force (25 µm on the scenes' 2e5 N/m stop) and a
/// count or two.
pub const HOMING_TOLERANCE_M: f64 = 50e-6;

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

/// The Excalibur board image's loop, in this process: the plain image's,
/// the passivity image's (`S` with the series damper), or the three-axis
/// image's (`N` = 3).
pub struct LocalBoard<W = UnilateralWall, const N: usize = 1, L = Direct> {
    board: Board<W, REGION_POINTS, N, L>,
    link: HostLink,
    /// Its stored configuration, in RAM as on the QEMU images.
    store: Store<RamFlash<512, 256>>,
}

/// The in-process board's only peripheral: its link, as two byte queues.
#[derive(Default)]
struct HostLink {
    rx: VecDeque<u8>,
    out: Vec<u8>,
}

impl<const N: usize> BoardSupport<N> for HostLink {
    // A processor-in-the-loop board reads no sensors of its own.
    fn sample(&mut self) -> RawSensors<N> {
        RawSensors::default()
    }
    // The duties go back in the board's actuator frame.
    fn set_duty(&mut self, _: [i16; N]) {}
    // So do the outputs: a disarmed board answers zero duty.
    fn set_outputs(&mut self, _: bool) {}
    // The host's loop cannot hang unseen: no watchdog.
    fn feed_watchdog(&mut self) {}
    // The host paces the ticks.
    fn cycles_per_tick(&self) -> u32 {
        0
    }
    fn read_byte(&mut self) -> Option<u8> {
        self.rx.pop_front()
    }
    fn write(&mut self, bytes: &[u8]) {
        self.out.extend_from_slice(bytes);
    }
    fn cycles(&mut self) -> u32 {
        0
    }
}

impl<W: World<f32, N>, L: PortLayer, const N: usize> LocalBoard<W, N, L> {
    /// `board`, driven by the link's sensor frames.
    fn driven(board: Board<W, REGION_POINTS, N, L>) -> Self {
        let mut board = board.with_pil(true);
        // As the QEMU images boot: the configuration from a RAM flash.
        let mut store = Store::new(RamFlash::<512, 256>::new(), 0, 256);
        board.boot_config(&mut store);
        LocalBoard {
            board,
            link: HostLink::default(),
            store,
        }
    }
}

impl<W: World<f32, N>, L: PortLayer, const N: usize> LocalBoard<W, N, L> {
    /// The same board with each axis homing with its `cfg` (e.g. on an
    /// encoder's index).
    pub fn with_homing(mut self, cfg: [twoport_control::homing::HomingConfig; N]) -> Self {
        self.board = self.board.with_homing(cfg);
        self
    }
}

impl LocalBoard {
    /// The image the firmware ships ([`excalibur::stiff_wall_board`]).
    pub fn excalibur() -> Result<Self, String> {
        excalibur::stiff_wall_board()
            .map(Self::driven)
            .map_err(|e| format!("the Excalibur board image: {e:?}"))
    }
}

impl LocalBoard<UnilateralWall, 1, SeriesDamper> {
    /// The passivity image ([`excalibur::stiff_wall_board_with_passivity`]).
    pub fn excalibur_with_passivity() -> Result<Self, String> {
        excalibur::stiff_wall_board_with_passivity()
            .map(Self::driven)
            .map_err(|e| format!("the Excalibur passivity image: {e:?}"))
    }
}

impl LocalBoard<xyz::World, 3> {
    /// The three-axis image ([`xyz::board`]).
    pub fn excalibur_xyz() -> Result<Self, String> {
        xyz::board()
            .map(Self::driven)
            .map_err(|e| format!("the three-axis Excalibur image: {e:?}"))
    }
}

impl<W: World<f32, N>, L: PortLayer, const N: usize> BoardPort for LocalBoard<W, N, L> {
    fn send(&mut self, bytes: &[u8]) -> Result<(), String> {
        // What the images do: the control tick runs each sensor frame as
        // it completes, and the main loop sends what was queued.
        self.link.rx.extend(bytes);
        loop {
            let ready = self.board.poll_link(&mut self.link);
            if ready {
                let store = &mut self.store;
                self.board
                    .control_tick_serving(&mut self.link, |b| b.service_config(store));
            }
            self.board.service_config(&mut self.store);
            self.board.flush(&mut self.link);
            if !ready && self.link.rx.is_empty() {
                return Ok(());
            }
        }
    }
    fn recv(&mut self, buf: &mut [u8], _: Duration) -> Result<usize, String> {
        let out = &mut self.link.out;
        let n = buf.len().min(out.len());
        buf[..n].copy_from_slice(&out[..n]);
        out.drain(..n);
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

/// One PIL run's record, its samples `S` (the one-axis simulation's by
/// default, or the three-axis one's [`XyzSample`]).
#[derive(Clone, Debug)]
pub struct Run<S = Sample> {
    /// One sample per tick.
    pub samples: Vec<S>,
    /// The duties the board answered each tick, one per axis.
    pub duties: Vec<Axes<i16>>,
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
    /// How the board was armed.
    pub start: Option<Start>,
    /// Where its configuration came from at boot, and after the run saved
    /// it (disarmed, before arming).
    pub config: Option<(ConfigSource, ConfigSource)>,
    /// The tick the board armed at.
    pub armed_at_tick: u64,
    /// Homing: the ticks it took, and how far the board's calibrated
    /// position was from the plant's then (m).
    pub homing: Option<(u64, f64)>,
}

impl<S> Default for Run<S> {
    fn default() -> Self {
        Run {
            samples: Vec::new(),
            duties: Vec::new(),
            telemetry: Vec::new(),
            corrupted_sent: 0,
            board_stats: LinkStats::default(),
            host_dropped: 0,
            zero_after_loss_ticks: None,
            start: None,
            config: None,
            armed_at_tick: 0,
            homing: None,
        }
    }
}

/// What a PIL run records of a tick: every axis's handle position and
/// delivered force.
pub trait PilSample: Clone {
    /// Axis `axis`'s handle position (m).
    fn handle_m(&self, axis: usize) -> f64;
    /// The force axis `axis`'s actuator delivered (N).
    fn actuator_n(&self, axis: usize) -> f64;
}

impl PilSample for Sample {
    fn handle_m(&self, _: usize) -> f64 {
        self.handle_m
    }
    fn actuator_n(&self, _: usize) -> f64 {
        self.actuator_n
    }
}

impl PilSample for XyzSample {
    fn handle_m(&self, axis: usize) -> f64 {
        self.handle_m[axis]
    }
    fn actuator_n(&self, axis: usize) -> f64 {
        self.actuator_n[axis]
    }
}

/// How a PIL run gets its board going.
#[derive(Clone, Copy, Debug)]
pub struct Setup {
    /// Calibrated or homed, then armed.
    pub start: Start,
    /// Where each axis stands at rest before the run, as the host tells a
    /// board it calibrates (pm).
    pub at_rest_pm: Axes<i64>,
    /// The encoder's index mark (m), if the scene's encoder has one.
    pub index_m: Option<f64>,
}

/// A simulated device a PIL run drives through a board: the one-axis
/// [`Simulation`] or the three-axis [`XyzSimulation`].
pub trait PilPlant {
    /// What a tick records.
    type Sample: PilSample;
    /// The device's axes.
    const AXES: u8;
    /// How a run begins, once the scene's device is checked to be the
    /// board's (its sensors, its world).
    fn setup(&self) -> Result<Setup, String>;
    /// One tick with the board at the other end of `session` as its
    /// controller: the sample and the duties the board answered.
    fn step_with<P: BoardPort>(
        &mut self,
        session: &mut Session<P>,
    ) -> Result<(Self::Sample, Axes<i16>), String>;
}

impl PilPlant for Simulation {
    type Sample = Sample;
    const AXES: u8 = 1;
    fn setup(&self) -> Result<Setup, String> {
        check_scene(self.scene())?;
        Ok(Setup {
            start: Start::for_scene(self.scene()),
            at_rest_pm: Axes::one(0),
            index_m: self.scene().effects.encoder.and_then(|e| e.index_m),
        })
    }
    fn step_with<P: BoardPort>(
        &mut self,
        session: &mut Session<P>,
    ) -> Result<(Sample, Axes<i16>), String> {
        session.step(self).map(|(s, d)| (s, Axes::one(d)))
    }
}

impl PilPlant for XyzSimulation {
    type Sample = XyzSample;
    const AXES: u8 = 3;
    fn setup(&self) -> Result<Setup, String> {
        check_xyz_scene(self.scene())?;
        // Calibrated where the image's world starts its cursor.
        let x = xyz::world().map(|w| w.cursor()).unwrap_or_default();
        Ok(Setup {
            start: Start::Calibrate,
            at_rest_pm: Axes::new(x.map(|p| p.nm() as i64 * 1000)).unwrap_or_default(),
            index_m: None,
        })
    }
    fn step_with<P: BoardPort>(
        &mut self,
        session: &mut Session<P>,
    ) -> Result<(XyzSample, Axes<i16>), String> {
        session.tick_heartbeat()?;
        let io = session.io;
        let (bits, pm) = excalibur::ENCODER;
        let mask = ((1u64 << bits) - 1) as u32;
        let tick = self.ticks();
        let mut answer = Ok(Axes::one(0));
        let mut ctl = |x_m: [f64; 3]| -> [f64; 3] {
            // The counter keeps the count's low `bits`, as in the one-axis
            // simulation's sensing.
            let raw = x_m.map(|x| (round_counts(x * 1e12 / pm as f64) as u32) & mask);
            let sensors = LinkSensors {
                tick: tick as u32,
                encoder_raw: Axes::new(raw).unwrap_or_default(),
                load_cell_raw: Axes::new([0; 3]).unwrap_or_default(),
                dead_man_closed: true,
                index_raw: Axes::new([None; 3]).unwrap_or_default(),
            };
            answer = session.exchange(tick, sensors);
            let duty = |a: usize| answer.as_ref().ok().and_then(|d| d.get(a).copied());
            [0, 1, 2].map(|a| io.force_n(duty(a).unwrap_or(0)) as f64)
        };
        let sample = self.step_external(&mut ctl);
        Ok((sample, answer?))
    }
}

/// How a run gets its board from disarmed to armed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub enum Start {
    /// Tell the board where it stands: every scene starts at rest at 0.
    Calibrate,
    /// Home it onto the scene's hard stop (`effects.hard_stop`).
    Home,
}

impl Start {
    /// Home where the scene has a hard stop, else calibrate.
    pub fn for_scene(scene: &Scene) -> Start {
        if scene.effects.hard_stop.is_some() {
            Start::Home
        } else {
            Start::Calibrate
        }
    }
}

/// The host side of a lockstep link to a board: handshake, heartbeats,
/// one sensor frame out and one actuator frame back per tick, and whatever
/// else the board says kept for the caller.
pub struct Session<P: BoardPort> {
    port: P,
    /// The axes this host drives.
    axes: u8,
    seq: u16,
    decoder: Decoder,
    inbox: Vec<Message>,
    io: twoport_board::IoScale,
    faults: Faults,
    tick: u64,
    /// The encoder's index mark as a count, and the unwrapped count of
    /// the last frame: the host plays the encoder's index hardware.
    index: Option<(i64, Option<i64>)>,
    /// Frames the host injected corrupted.
    pub corrupted_sent: u64,
}

impl<P: BoardPort> Session<P> {
    /// Shake hands with the one-axis board at `port`. It is disarmed until
    /// [`arm`](Self::arm).
    pub fn open(port: P, faults: Faults) -> Result<Self, String> {
        Self::open_axes(port, faults, 1)
    }

    /// Shake hands with the board of `axes` axes at `port`: a board of
    /// another count is refused, with both counts named.
    pub fn open_axes(port: P, faults: Faults, axes: u8) -> Result<Self, String> {
        let mut s = Session {
            port,
            axes,
            seq: 0,
            decoder: Decoder::new(),
            inbox: Vec::new(),
            io: twoport_board::IoScale::EXCALIBUR,
            faults,
            tick: 0,
            index: None,
            corrupted_sent: 0,
        };
        s.handshake()?;
        Ok(s)
    }

    /// Ask for a mode change and wait for the board's status that shows it
    /// done, or its refusal of it: over a real link, other statuses may
    /// still be on their way.
    fn ask(
        &mut self,
        msg: Message,
        asked: ModeRequest,
        done: fn(&Status) -> bool,
    ) -> Result<Status, String> {
        self.drop_stale_statuses();
        self.send(&msg)?;
        let what = format!("{asked:?}");
        let r = self.wait(&what, |m| match m {
            Message::Status(s) if done(s) => Some(Ok(*s)),
            Message::ModeRefused { asked: a, why } if *a == asked => Some(Err(*why)),
            _ => None,
        })?;
        r.map_err(|why| format!("the board refused {what}: {why:?}"))
    }

    /// Statuses and refusals already received answer earlier questions,
    /// not the next one.
    fn drop_stale_statuses(&mut self) {
        self.inbox
            .retain(|m| !matches!(m, Message::Status(_) | Message::ModeRefused { .. }));
    }

    /// Calibrate a disarmed board: each axis stands at its `position_pm`
    /// (pm).
    pub fn calibrate(&mut self, position_pm: Axes<i64>) -> Result<Status, String> {
        self.ask(
            Message::Calibrate { position_pm },
            ModeRequest::Calibrate,
            |s| s.calibrated,
        )
    }

    /// Arm the board (it must have had a tick, to see its dead-man).
    pub fn arm(&mut self) -> Result<Status, String> {
        self.ask(Message::Arm, ModeRequest::Arm, |s| s.mode == Mode::Armed)
    }

    /// Start homing; the caller runs ticks until [`homed`].
    pub fn home(&mut self) -> Result<Status, String> {
        self.ask(Message::Home, ModeRequest::Home, |s| s.mode == Mode::Homing)
    }

    /// Where the board's configuration came from.
    pub fn config(&mut self) -> Result<ConfigSource, String> {
        self.inbox.retain(|m| !matches!(m, Message::Config(_)));
        self.send(&Message::GetConfig)?;
        self.wait("GetConfig", |m| match m {
            Message::Config(c) => Some(*c),
            _ => None,
        })
    }

    /// The scene's encoder has an index mark at `index_m` (m): send the
    /// count it latches in the sensor frame of each tick that passes it.
    pub fn set_index(&mut self, index_m: Option<f64>) {
        let (_, pm) = excalibur::ENCODER;
        self.index = index_m.map(|m| ((m * 1e12 / pm as f64).round() as i64, None));
    }

    /// The count the index latched this tick, if the axis passed it
    /// between the last frame's `raw` and this one.
    fn index_crossing(&mut self, raw: u32) -> Option<u32> {
        let (bits, _) = excalibur::ENCODER;
        let (mark, last) = self.index.as_mut()?;
        let shift = 32 - u32::from(bits);
        let now = match *last {
            // The counter's difference, sign-extended (it wraps).
            Some(l) => l + (((raw.wrapping_sub(l as u32) << shift) as i32) >> shift) as i64,
            None => ((raw << shift) as i32 >> shift) as i64,
        };
        let crossed = last.is_some_and(|l| (l.min(now) < *mark) && (*mark <= l.max(now)));
        *last = Some(now);
        let mask = (1u64 << bits) - 1;
        crossed.then_some((*mark as u64 & mask) as u32)
    }

    /// The board's state machine, asked for.
    pub fn status(&mut self) -> Result<Status, String> {
        self.drop_stale_statuses();
        self.send(&Message::GetStatus)?;
        self.wait("GetStatus", |m| match m {
            Message::Status(s) => Some(*s),
            _ => None,
        })
    }

    fn frame(&mut self, msg: &Message) -> Result<Vec<u8>, String> {
        let mut buf = [0u8; MAX_FRAME];
        let n = encode(self.seq, msg, &mut buf).map_err(|e| format!("encode: {e:?}"))?;
        self.seq = self.seq.wrapping_add(1);
        Ok(buf[..n].to_vec())
    }

    /// Send one message.
    pub fn send(&mut self, msg: &Message) -> Result<(), String> {
        let f = self.frame(msg)?;
        self.port.send(&f)
    }

    fn pump(&mut self, timeout: Duration) -> Result<(), String> {
        let mut buf = [0u8; 256];
        let n = self.port.recv(&mut buf, timeout)?;
        let inbox = &mut self.inbox;
        self.decoder.feed(&buf[..n], |env| inbox.push(env.msg));
        Ok(())
    }

    /// Read until `want` picks a message out, or time out.
    pub fn wait<T>(
        &mut self,
        what: &str,
        mut want: impl FnMut(&Message) -> Option<T>,
    ) -> Result<T, String> {
        let deadline = Instant::now() + ANSWER_TIMEOUT;
        loop {
            if let Some((i, v)) = self
                .inbox
                .iter()
                .enumerate()
                .find_map(|(i, m)| want(m).map(|v| (i, v)))
            {
                self.inbox.remove(i);
                return Ok(v);
            }
            let now = Instant::now();
            if now > deadline {
                return Err(format!(
                    "the board did not answer {what} within {} s",
                    ANSWER_TIMEOUT.as_secs()
                ));
            }
            self.pump((deadline - now).min(Duration::from_millis(50)))?;
        }
    }

    /// Hello until the board answers (a pty drops what is sent before the
    /// other end opens it).
    fn handshake(&mut self) -> Result<(), String> {
        let deadline = Instant::now() + ANSWER_TIMEOUT;
        loop {
            self.send(&Message::hello(Role::Host, self.axes))?;
            self.pump(Duration::from_millis(100))?;
            if let Some(i) = self
                .inbox
                .iter()
                .position(|m| matches!(m, Message::HelloAck { .. }))
            {
                return self
                    .inbox
                    .remove(i)
                    .accept_ack(self.axes)
                    .map_err(|e| e.to_string());
            }
            if Instant::now() > deadline {
                // (A board of another protocol may answer in a form this
                // host cannot decode.)
                return Err(format!(
                    "no handshake answer from the board (this host speaks protocol {})",
                    twoport_link::PROTOCOL_VERSION
                ));
            }
        }
    }

    /// Read whatever the board has sent, waiting at most a millisecond
    /// (a free-running board: telemetry, replies, fault reports).
    pub fn poll(&mut self) -> Result<(), String> {
        self.pump(Duration::from_millis(1))
    }

    /// Messages the board sent that no one waited for (telemetry, fault
    /// reports, gain replies), oldest first.
    pub fn take_messages(&mut self) -> Vec<Message> {
        std::mem::take(&mut self.inbox)
    }

    /// The board's link counters.
    pub fn board_stats(&mut self) -> Result<LinkStats, String> {
        self.send(&Message::GetStats)?;
        self.wait("GetStats", |m| match m {
            Message::Stats(s) => Some(*s),
            _ => None,
        })
    }

    /// Frames from the board this host dropped.
    pub fn host_dropped(&self) -> u32 {
        self.decoder.stats().dropped()
    }

    /// One tick of `sim` with the board as its controller; returns the
    /// sample and the duty the board answered.
    pub fn step(&mut self, sim: &mut Simulation) -> Result<(Sample, i16), String> {
        let tick = self.tick_heartbeat()?;
        let mut answer: Result<i16, String> = Ok(0);
        let io = self.io;
        let mut ctl = |f: &SensorFrame| -> ServoOutput {
            let sensors = LinkSensors {
                tick: f.tick,
                encoder_raw: Axes::one(f.encoder_raw[0]),
                load_cell_raw: Axes::one(io.load_cell_counts(f.load_cell_n[0])),
                dead_man_closed: f.dead_man_closed,
                index_raw: Axes::one(self.index_crossing(f.encoder_raw[0])),
            };
            answer = self.exchange(tick, sensors).map(|d| d[0]);
            let force = io.force_n(*answer.as_ref().unwrap_or(&0));
            ServoOutput {
                actuator_force_n: [force],
                commanded_force_n: [force],
                ..ServoOutput::default()
            }
        };
        let sample = sim.step_external(&mut ctl);
        Ok((sample, answer?))
    }

    /// The next tick's number, with its heartbeat sent where one is due
    /// and the link is not lost.
    fn tick_heartbeat(&mut self) -> Result<u64, String> {
        let tick = self.tick;
        self.tick += 1;
        let lost = self.faults.link_loss_at.is_some_and(|t| tick >= t);
        if tick.is_multiple_of(HEARTBEAT_EVERY) && !lost {
            self.send(&Message::Heartbeat)?;
        }
        Ok(tick)
    }

    /// Send tick `tick`'s sensors (and, on schedule, a corrupted copy
    /// first) and wait for the board's duties.
    fn exchange(&mut self, tick: u64, sensors: LinkSensors) -> Result<Axes<i16>, String> {
        let want = sensors.tick;
        let good = self.frame(&Message::Sensors(sensors))?;
        let every = self.faults.corrupt_every;
        if every > 0 && tick % every == every / 2 {
            let mut bad = good.clone();
            let i = bad.len() / 2;
            bad[i] ^= 0x5A;
            if bad[i] == 0 {
                bad[i] = 0x33;
            }
            self.port.send(&[0x17, 0xFF, 0x42, 0x00])?;
            self.port.send(&bad)?;
            self.corrupted_sent += 2;
        }
        self.port.send(&good)?;
        self.wait(&format!("tick {want}"), |m| match m {
            Message::Actuator(a) if a.tick == want => Some(a.duty),
            _ => None,
        })
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

/// The three-axis scene's device must be the three-axis image's: its
/// world holds the image's blocks, which the board simulates (the scene's
/// grab and release times cannot reach it over the link).
pub fn check_xyz_scene(scene: &XyzScene) -> Result<(), String> {
    use crate::engine::xyz::XyzVe;
    let want: Vec<_> = xyz::BLOCKS.to_vec();
    match &scene.ve {
        XyzVe::Blocks {
            blocks,
            grab_at_s,
            release_at_s,
            ..
        } if grab_at_s.is_empty() && release_at_s.is_empty() => {
            let have: Vec<_> = blocks
                .iter()
                .map(|b| {
                    (
                        b.at_m.map(|x| x as f32),
                        b.size_m.map(|x| x as f32),
                        b.mass_kg as f32,
                    )
                })
                .collect();
            if have == want {
                Ok(())
            } else {
                Err(format!(
                    "the scene's blocks must be the three-axis image's (twoport_board::excalibur::xyz::BLOCKS): {want:?}"
                ))
            }
        }
        XyzVe::Blocks { .. } => Err(
            "a processor-in-the-loop scene cannot grab or release: the board's world runs there, \
             and the link carries no grab; remove ve.grab_at_s and ve.release_at_s"
                .into(),
        ),
        _ => Err(
            "the three-axis image runs the building-block world: set ve.kind = \"blocks\"".into(),
        ),
    }
}

/// How homing has ended, from the statuses a board sent: `None` while it
/// goes on, the error where it failed.
pub fn homed(statuses: &[Status]) -> Option<Result<(), String>> {
    statuses.iter().find_map(|s| match s.mode {
        Mode::Homing => None,
        _ if s.faults != 0 => Some(Err(format!(
            "homing ended with faults: {}",
            BoardFaults(s.faults)
        ))),
        _ if s.calibrated => Some(Ok(())),
        m => Some(Err(format!("homing ended uncalibrated, in mode {m:?}"))),
    })
}

/// One tick of a run, recorded; returns the statuses the board sent.
fn record<P: BoardPort, M: PilPlant>(
    session: &mut Session<P>,
    sim: &mut M,
    r: &mut Run<M::Sample>,
) -> Result<Vec<Status>, String> {
    let (s, duty) = sim.step_with(session)?;
    r.samples.push(s);
    r.duties.push(duty);
    let mut statuses = Vec::new();
    for m in session.take_messages() {
        match m {
            Message::Telemetry(t) => r.telemetry.push(t),
            Message::Status(s) => statuses.push(s),
            _ => {}
        }
    }
    Ok(statuses)
}

/// Run `scene` for `ticks` against the board at `port`: the first tick
/// disarmed, then the board calibrated (or homed, for a scene with a hard
/// stop) and armed, then the rest.
pub fn run<P: BoardPort>(scene: Scene, ticks: u64, port: P, faults: Faults) -> Result<Run, String> {
    run_plant(Simulation::new(scene)?, ticks, port, faults)
}

/// [`run`] for a three-axis scene against a three-axis board: calibrated
/// where the scene's device starts (the image's world's start), then armed.
pub fn run_xyz<P: BoardPort>(
    scene: XyzScene,
    ticks: u64,
    port: P,
    faults: Faults,
) -> Result<Run<XyzSample>, String> {
    run_plant(XyzSimulation::new(scene)?, ticks, port, faults)
}

/// [`run`] of any simulated device.
pub fn run_plant<P: BoardPort, M: PilPlant>(
    mut sim: M,
    ticks: u64,
    port: P,
    faults: Faults,
) -> Result<Run<M::Sample>, String> {
    let setup = sim.setup()?;
    let start = setup.start;
    let mut session = Session::open_axes(port, faults, M::AXES)?;
    session.set_index(setup.index_m);
    let mut r = Run {
        start: Some(start),
        ..Run::default()
    };
    // The configuration: what it booted with, then saved, which a PIL
    // board does while it waits for its first tick.
    let booted = session.config()?;
    session.send(&Message::SaveConfig)?;
    let saved = session.wait("SaveConfig", |m| match m {
        Message::Config(c @ ConfigSource::Stored { .. }) => Some(Ok(*c)),
        Message::ModeRefused {
            asked: ModeRequest::SaveConfig,
            why,
        } => Some(Err(format!("the board refused SaveConfig: {why:?}"))),
        _ => None,
    })??;
    r.config = Some((booted, saved));
    record(&mut session, &mut sim, &mut r)?;
    match start {
        Start::Calibrate => {
            session.calibrate(setup.at_rest_pm)?;
        }
        Start::Home => {
            session.home()?;
            loop {
                let statuses = record(&mut session, &mut sim, &mut r)?;
                if let Some(done) = homed(&statuses) {
                    done?;
                    break;
                }
                if r.samples.len() as u64 >= ticks {
                    return Err(format!("the board had not homed after {ticks} ticks"));
                }
            }
            r.homing = Some((r.samples.len() as u64 - 1, f64::NAN));
        }
    }
    // Armed straight after the status that allowed it, which the board
    // sends before that tick's actuator frame: the same tick on every
    // transport.
    session.arm()?;
    r.armed_at_tick = r.samples.len() as u64;
    while (r.samples.len() as u64) < ticks {
        record(&mut session, &mut sim, &mut r)?;
    }
    if let Some((n, err)) = &mut r.homing {
        // The board's position in its first telemetry after homing
        // against the plant's where that tick read its sensors: the end of
        // the tick before.
        if let Some(t) = r.telemetry.iter().find(|t| u64::from(t.tick) > *n) {
            if let Some(s) = r.samples.get(t.tick as usize - 1) {
                *err = t.axes[0].position_pm as f64 * 1e-12 - s.handle_m(0);
            }
        }
    }
    r.board_stats = session.board_stats()?;
    r.host_dropped = session.host_dropped();
    r.corrupted_sent = session.corrupted_sent;
    if let Some(t0) = faults.link_loss_at {
        // The last tick with a non-zero duty after the loss, plus one.
        let last_nonzero = r
            .duties
            .iter()
            .skip(t0 as usize)
            .rposition(|d| d.iter().any(|d| *d != 0));
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
    /// Whether the two boards armed (or homed) at different ticks.
    pub start_differs: bool,
}

/// Compare a run with its reference, tick by tick, every axis.
pub fn compare<S: PilSample>(a: &Run<S>, b: &Run<S>) -> Comparison {
    let mut c = Comparison {
        ticks: a.samples.len().min(b.samples.len()) as u64,
        ..Comparison::default()
    };
    let axes = a.duties.first().map_or(1, |d| d.len());
    for (x, y) in a.samples.iter().zip(&b.samples) {
        for i in 0..axes {
            let dx = (x.handle_m(i) - y.handle_m(i)).abs();
            let df = (x.actuator_n(i) - y.actuator_n(i)).abs();
            c.max_position_error_m = c.max_position_error_m.max(dx);
            c.max_force_error_n = c.max_force_error_n.max(df);
        }
    }
    c.start_differs =
        (a.armed_at_tick, a.homing.map(|h| h.0)) != (b.armed_at_tick, b.homing.map(|h| h.0));
    c.duty_mismatches = a
        .duties
        .iter()
        .zip(&b.duties)
        .filter(|(x, y)| x != y)
        .count() as u64;
    c
}
/// Why a PIL run fails its check, or nothing where it passes. `run` is the
/// board's, compared with the in-process loop as `c`; it was to take
/// `ticks` ticks with the host's heartbeats stopping at `faults.link_loss_at`,
/// after which the board must have zeroed the force within
/// `deadline_ticks`. A run fails where the board differs from the loop at
/// all (bit for bit), where ticks are missing, where it dropped fewer frames
/// than were corrupted on purpose, or where it was late to zero the force
/// (or was not pushing before the loss, so the check would prove nothing).
pub fn failures<S: PilSample>(
    run: &Run<S>,
    c: &Comparison,
    ticks: u64,
    faults: Faults,
    deadline_ticks: u64,
) -> Vec<String> {
    let mut bad = Vec::new();
    if c.duty_mismatches > 0 || c.max_position_error_m > 0.0 || c.max_force_error_n > 0.0 {
        bad.push(format!(
            "the board differs from the in-process loop ({} duties, {:.3e} m, {:.3e} N)",
            c.duty_mismatches, c.max_position_error_m, c.max_force_error_n
        ));
    }
    match run.config {
        Some((ConfigSource::Defaults { .. }, ConfigSource::Stored { .. })) => {}
        Some((booted, saved)) => bad.push(format!(
            "a fresh board should boot on its defaults and save: {booted:?}, then {saved:?}"
        )),
        None => bad.push("the board never said where its configuration came from".into()),
    }
    if c.start_differs {
        bad.push(format!(
            "the board armed at tick {}, the in-process loop at another",
            run.armed_at_tick
        ));
    }
    if c.ticks != ticks {
        bad.push(format!("{} of {ticks} ticks ran", c.ticks));
    }
    if u64::from(run.board_stats.rx.dropped()) < run.corrupted_sent {
        bad.push(format!(
            "{} corrupted frames sent, the board dropped {}",
            run.corrupted_sent,
            run.board_stats.rx.dropped()
        ));
    }
    if let Some((n, err_m)) = run.homing {
        if err_m.is_nan() || err_m.abs() > HOMING_TOLERANCE_M {
            bad.push(format!(
                "homing calibrated {:.1} um off the plant (tolerance {:.0} um)",
                err_m * 1e6,
                HOMING_TOLERANCE_M * 1e6
            ));
        }
        let limit = excalibur::HOMING.force_limit_n as f64;
        let io = twoport_board::IoScale::EXCALIBUR;
        let peak = run.duties[..(n as usize + 1).min(run.duties.len())]
            .iter()
            .flat_map(|d| d.iter())
            .map(|d| io.force_n(*d).abs() as f64)
            .fold(0.0, f64::max);
        if peak > limit + 0.01 {
            bad.push(format!("homing pushed {peak:.2} N (limit {limit} N)"));
        }
    }
    if let (Some(t0), Some(z)) = (faults.link_loss_at, run.zero_after_loss_ticks) {
        let before = &run.duties[..(t0 as usize).min(run.duties.len())];
        if !before
            .iter()
            .rev()
            .take(10)
            .any(|d| d.iter().any(|d| *d != 0))
        {
            bad.push("no force before the link loss: the check would prove nothing".into());
        }
        if z > deadline_ticks {
            bad.push(format!(
                "zero force {z} ticks after the link loss (deadline {deadline_ticks})"
            ));
        }
    }
    bad
}
