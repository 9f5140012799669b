//! The loop: servo tick, link in, frames out.

mod arming;
mod persist;

use crate::io::IoScale;
use crate::region::Region;
use crate::support::BoardSupport;
use heapless::{Deque, Vec};
use twoport_control::homing::{Homing, HomingConfig};
use twoport_control::servo::{Direct, Gains, PortLayer, SensorFrame, Servo, ServoOutput};
use twoport_control::ve::VirtualEnvironment;
use twoport_control::{Faults, Position};
use twoport_link::{
    encode, ActuatorFrame, Axes, AxisRefusal, AxisTelemetry, Decoder, GainsReply, LinkStats,
    Message, Mode, Refusal, Stats, Telemetry, MAX_FRAME,
};

/// One encoded frame, delimiter included.
pub type Frame = Vec<u8, MAX_FRAME>;
/// The axes this loop drives, as its handshake declares them: one, until
/// the N-axis servo runs here.
pub const AXES: u8 = 1;

/// Frames each outgoing queue holds: replies and fault reports in one,
/// telemetry in the other, so a telemetry flood never crowds out an answer.
pub const TX_FRAMES: usize = 8;

/// The portable firmware loop, around a servo with port layer `L` (none by
/// default; the passivity image runs the series damper).
#[derive(Clone, Debug)]
pub struct Board<V, const R: usize, L = Direct> {
    servo: Servo<V, f32, L>,
    region: Region<R>,
    decoder: Decoder,
    /// Replies and fault reports, sent first.
    control: Deque<Frame, TX_FRAMES>,
    /// Telemetry, newest kept.
    telemetry: Deque<Frame, TX_FRAMES>,
    seq: u16,
    telemetry_every: u32,
    since_telemetry: u32,
    reported: Faults,
    loop_cycles: u32,
    tx_dropped: u32,
    io: IoScale,
    last: ServoOutput,
    /// Whether sensor frames from the link drive ticks (processor in the
    /// loop). A board with real sensors must never let the host move it.
    pil: bool,
    pil_refused: u32,
    /// The host's sensor frame waiting for the next control tick (PIL).
    pending: Option<SensorFrame>,
    /// Ticks run from the board's own sensors (their frame's `tick`).
    ticks: u32,
    /// The state machine: disarmed at boot.
    mode: Mode,
    /// Whether the encoder's offset is known.
    calibrated: bool,
    /// How to home, and the run in progress (in [`Mode::Homing`]).
    homing_cfg: HomingConfig,
    homing: Option<Homing>,
    /// The dead-man switch at the last tick (open before the first).
    dead_man_closed: bool,
    /// Whether the amplifier's outputs are on (as last commanded).
    outputs_on: bool,
    /// Where the configuration in force came from.
    config_source: Option<twoport_link::ConfigSource>,
    /// A `SaveConfig` waiting for the main loop.
    save_pending: bool,
    /// The encoder count an index pulse latched, for this tick.
    index: Option<u32>,
    /// The host's index count waiting with its sensor frame (PIL).
    pending_index: Option<u32>,
    /// Loop timing: the last tick's stages, its start, the overruns and
    /// the worst jitter since boot.
    timing: Timing,
}

/// The loop's timing, in the support's count.
#[derive(Clone, Copy, Debug, Default)]
struct Timing {
    stages: [u32; 3],
    last_start: Option<u32>,
    deadline_misses: u32,
    worst_jitter: u32,
}

impl Timing {
    /// A tick that started at `start` and ran its stages through the
    /// instants `t`, against a period of `period` (0: unchecked).
    fn record(&mut self, start: u32, t: [u32; 3], period: u32) {
        self.stages = [
            t[0].wrapping_sub(start),
            t[1].wrapping_sub(t[0]),
            t[2].wrapping_sub(t[1]),
        ];
        if period > 0 {
            let took = t[2].wrapping_sub(start);
            let late = self.last_start.is_some_and(|s0| {
                let dt = start.wrapping_sub(s0);
                self.worst_jitter = self.worst_jitter.max(dt.abs_diff(period));
                dt > period + period / 2
            });
            if took > period || late {
                self.deadline_misses = self.deadline_misses.saturating_add(1);
            }
        }
        self.last_start = Some(start);
    }
}

impl<V: VirtualEnvironment, const R: usize, L: PortLayer> Board<V, R, L> {
    /// A board running `servo`, accepting gain changes inside `region`, and
    /// sending telemetry every `telemetry_every` ticks (0: never). It
    /// boots disarmed and uncalibrated, homing toward the negative end
    /// with [`HomingConfig::gentle`] onto a stop at the origin unless
    /// [`with_homing`](Self::with_homing) says otherwise.
    pub fn new(servo: Servo<V, f32, L>, region: Region<R>, telemetry_every: u32) -> Self {
        let period_s = servo.safety().config().period_s;
        Board {
            servo,
            region,
            decoder: Decoder::new(),
            control: Deque::new(),
            telemetry: Deque::new(),
            seq: 0,
            telemetry_every,
            since_telemetry: 0,
            reported: Faults::NONE,
            loop_cycles: 0,
            tx_dropped: 0,
            io: IoScale::EXCALIBUR,
            last: ServoOutput::default(),
            pil: false,
            pil_refused: 0,
            pending: None,
            ticks: 0,
            mode: Mode::Disarmed,
            calibrated: false,
            homing_cfg: HomingConfig::gentle(Position::ZERO, period_s),
            homing: None,
            dead_man_closed: false,
            outputs_on: false,
            config_source: None,
            save_pending: false,
            index: None,
            pending_index: None,
            timing: Timing::default(),
        }
    }

    /// The same board homing with `cfg` (its `period_s` must be the
    /// servo's; [`Message::Home`] refuses a configuration that does not
    /// validate).
    pub fn with_homing(mut self, cfg: HomingConfig) -> Self {
        self.homing_cfg = cfg;
        self
    }

    /// The same board driven by sensor frames from the link (processor in
    /// the loop: the QEMU image, the host's reference). Off by default: a
    /// board with real sensors ignores sensor frames and counts them.
    pub fn with_pil(mut self, on: bool) -> Self {
        self.pil = on;
        self
    }

    /// Sensor frames ignored: this board reads its own sensors, or the
    /// frame's axes are not this board's.
    pub fn pil_refused(&self) -> u32 {
        self.pil_refused
    }

    /// The same board with `io` scaling its peripherals (default:
    /// [`IoScale::EXCALIBUR`]).
    pub fn with_io(mut self, io: IoScale) -> Self {
        self.io = io;
        self
    }

    /// How the peripherals scale.
    pub fn io(&self) -> IoScale {
        self.io
    }

    /// The last tick's output.
    pub fn last_output(&self) -> &ServoOutput {
        &self.last
    }

    /// The signed PWM duty for the held actuator force.
    pub fn duty(&self) -> i16 {
        self.io.duty(self.last.actuator_force_n)
    }

    /// The servo (gains, safety state).
    pub fn servo(&self) -> &Servo<V, f32, L> {
        &self.servo
    }

    /// The link decoder's counters.
    pub fn link_stats(&self) -> Stats {
        self.decoder.stats()
    }

    /// Outgoing frames dropped because the host did not read them (the
    /// oldest of their queue).
    pub fn tx_dropped(&self) -> u32 {
        self.tx_dropped
    }

    /// Bytes from the link.
    pub fn on_bytes(&mut self, bytes: &[u8]) {
        for &b in bytes {
            if let Some(Ok(env)) = self.decoder.push(b) {
                self.handle(env.msg);
            }
        }
    }

    /// The next frame to send: replies and fault reports before telemetry.
    pub fn pop_tx(&mut self) -> Option<Frame> {
        self.control
            .pop_front()
            .or_else(|| self.telemetry.pop_front())
    }

    fn queue(&mut self, msg: Message) {
        let mut buf = [0u8; MAX_FRAME];
        let Ok(n) = encode(self.seq, &msg, &mut buf) else {
            return;
        };
        let Ok(frame) = Frame::from_slice(&buf[..n]) else {
            return;
        };
        self.seq = self.seq.wrapping_add(1);
        let q = if matches!(msg, Message::Telemetry(_)) {
            &mut self.telemetry
        } else {
            &mut self.control
        };
        if q.is_full() {
            q.pop_front();
            self.tx_dropped = self.tx_dropped.saturating_add(1);
        }
        let _ = q.push_back(frame);
    }

    fn handle(&mut self, msg: Message) {
        if let Some(ack) = msg.answer(AXES) {
            self.queue(ack);
            return;
        }
        match msg {
            Message::Heartbeat => self.servo.heartbeat(),
            Message::GetGains => self.queue(Message::Gains(Axes::one(self.servo.gains().into()))),
            Message::SetGains(g) => {
                let reply = match g.to_array::<1>() {
                    Some([g]) => {
                        let g = Gains::from(g);
                        match self.check(&g) {
                            Ok(()) => self.apply(g),
                            Err(why) => GainsReply::Refused(AxisRefusal { axis: 0, why }),
                        }
                    }
                    None => GainsReply::Refused(AxisRefusal {
                        axis: 0,
                        why: Refusal::WrongAxisCount { axes: AXES },
                    }),
                };
                self.queue(Message::GainsReply(reply));
            }
            Message::ClearFaults => {
                self.servo.clear();
                self.reported = Faults::NONE;
                self.queue_status();
            }
            Message::Arm => self.arm(),
            Message::Disarm => self.disarm(),
            Message::Home => self.home(),
            Message::Calibrate { position_pm } => self.calibrate(position_pm),
            Message::GetStatus => self.queue_status(),
            Message::SaveConfig => self.request_save(),
            Message::GetConfig => self.report_config(),
            Message::GetStats => self.queue(Message::Stats(LinkStats {
                rx: self.decoder.stats(),
                tx_dropped: self.tx_dropped,
            })),
            // Processor-in-the-loop: the host's sensors wait for the next
            // control tick, which answers with the duty.
            Message::Sensors(_) if !self.pil => {
                self.pil_refused = self.pil_refused.saturating_add(1);
            }
            // (The handshake agreed on the axes, so a frame of another
            // count is a host's error: it is counted and never ticks.)
            Message::Sensors(s) if s.encoder_raw.len() != 1 || s.load_cell_raw.len() != 1 => {
                self.pil_refused = self.pil_refused.saturating_add(1);
            }
            Message::Sensors(s) => {
                self.pending_index = s.index_raw[0];
                self.pending = Some(SensorFrame {
                    tick: s.tick,
                    encoder_raw: s.encoder_raw[0],
                    load_cell_n: self.io.load_cell_n(s.load_cell_raw[0]),
                    dead_man_closed: s.dead_man_closed,
                });
            }
            _ => {}
        }
    }

    /// Whether `g` is inside the proven region for this board's display.
    fn check(&self, g: &Gains) -> Result<(), Refusal> {
        self.region.check(self.servo.display(), g)
    }

    fn apply(&mut self, g: Gains) -> GainsReply {
        match self.servo.set_gains(g) {
            Ok(()) => GainsReply::Accepted(Axes::one(self.servo.gains().into())),
            Err(_) => GainsReply::Refused(AxisRefusal {
                axis: 0,
                why: Refusal::OutOfRange,
            }),
        }
    }

    /// Whether a host's sensor frame waits for a control tick (PIL only).
    pub fn sensors_pending(&self) -> bool {
        self.pending.is_some()
    }

    /// Take the bytes the link has received, stopping early where one
    /// completes a sensor frame (PIL), so that each frame gets its own
    /// tick. Returns whether a sensor frame waits.
    pub fn poll_link(&mut self, io: &mut impl BoardSupport) -> bool {
        while self.pending.is_none() {
            let Some(b) = io.read_byte() else { break };
            self.on_bytes(&[b]);
        }
        self.pending.is_some()
    }

    /// Send every queued frame (replies first, then telemetry).
    pub fn flush(&mut self, io: &mut impl BoardSupport) {
        while let Some(f) = self.pop_tx() {
            io.write(&f);
        }
    }

    /// The control interrupt's body, the same in every image: sample the
    /// sensors, run one [`tick`](Self::tick), command the amplifier.
    ///
    /// A processor-in-the-loop board takes its sensors from the host
    /// instead: it serves the link (answering as it goes) until the host's
    /// sensor frame for this tick has come, which is what an emulated
    /// board's ADC conversion amounts to, and answers with the duty. The
    /// time from the sensors to the command, in the support's
    /// [`cycles`](BoardSupport::cycles), goes out in the next telemetry.
    pub fn control_tick(&mut self, io: &mut impl BoardSupport) -> ServoOutput {
        self.control_tick_serving(io, |_| {})
    }

    /// [`control_tick`](Self::control_tick) that, while a processor-in-
    /// the-loop board waits for its host, also runs `serve` on it: the
    /// main loop's other work, such as [`service_config`](Self::service_config),
    /// which would otherwise wait for the tick the host is waiting on.
    pub fn control_tick_serving(
        &mut self,
        io: &mut impl BoardSupport,
        serve: impl FnMut(&mut Self),
    ) -> ServoOutput {
        let out = self.control_tick_inner(io, serve);
        // Outputs follow the mode, within the tick that changed it.
        self.drive_outputs(io);
        out
    }

    fn control_tick_inner(
        &mut self,
        io: &mut impl BoardSupport,
        mut serve: impl FnMut(&mut Self),
    ) -> ServoOutput {
        let (frame, start) = if self.pil {
            let frame = loop {
                io.feed_watchdog();
                self.poll_link(io);
                if let Some(f) = self.pending.take() {
                    break f;
                }
                serve(self);
                self.flush(io);
            };
            self.index = self.pending_index.take();
            (frame, io.cycles())
        } else {
            let start = io.cycles();
            let raw = io.sample();
            let frame = SensorFrame {
                tick: self.ticks,
                encoder_raw: raw.encoder_raw,
                load_cell_n: self.io.load_cell_n(raw.load_cell_counts),
                dead_man_closed: raw.dead_man_closed,
            };
            self.index = raw.index_raw;
            self.ticks = self.ticks.wrapping_add(1);
            (frame, start)
        };
        let sensed = io.cycles();
        let out = self.tick(&frame);
        self.index = None;
        let ruled = io.cycles();
        let duty = self.duty();
        io.set_duty(duty);
        io.feed_watchdog();
        if self.pil {
            self.queue(Message::Actuator(ActuatorFrame {
                tick: frame.tick,
                duty: Axes::one(duty),
            }));
        }
        let end = io.cycles();
        self.loop_cycles = end.wrapping_sub(start);
        let period = io.cycles_per_tick();
        self.timing.record(start, [sensed, ruled, end], period);
        out
    }

    /// One control tick: the law, a fault report when new faults latch,
    /// telemetry on schedule. Returns the held actuator command.
    pub fn tick(&mut self, frame: &SensorFrame) -> ServoOutput {
        self.dead_man_closed = frame.dead_man_closed;
        let out = match &mut self.homing {
            Some(h) => self.servo.tick_with(frame, |x, v| h.step(x, v)),
            None => self.servo.tick(frame),
        };
        self.last = out;
        self.after_tick(&out);
        if !out.faults.is_empty() && out.faults != self.reported {
            self.reported = out.faults;
            self.queue(Message::FaultReport {
                faults: out.faults.0,
                first: out.faults.lowest().0,
            });
        }
        if self.telemetry_every > 0 {
            self.since_telemetry += 1;
            if self.since_telemetry >= self.telemetry_every {
                self.since_telemetry = 0;
                self.queue(Message::Telemetry(Telemetry {
                    tick: frame.tick,
                    axes: Axes::one(AxisTelemetry {
                        position_pm: out.position.nm() as i64 * 1000,
                        velocity_mps: out.velocity_mps,
                        load_cell_n: frame.load_cell_n,
                        commanded_n: out.commanded_force_n,
                        actuator_n: out.actuator_force_n,
                        ve_position_pm: self.servo.ve().position().nm() as i64 * 1000,
                    }),
                    faults: out.faults.0,
                    loop_cycles: self.loop_cycles,
                    mode: self.mode,
                    stage_cycles: self.timing.stages,
                    deadline_misses: self.timing.deadline_misses,
                    worst_jitter_cycles: self.timing.worst_jitter,
                }));
            }
        }
        out
    }
}
