//! The loop: servo tick, link in, frames out.

mod arming;
mod host_ve;
mod identify;
mod latency;
mod persist;
mod spec;
mod ve_param;

use latency::Timing;
pub use latency::GUARD_TICKS;

use crate::io::IoScale;
use crate::region::{check_axes, Region};
use crate::support::BoardSupport;
use heapless::{Deque, Vec};
use twoport_control::drive::Drive;
use twoport_control::experiment::Experiment;
use twoport_control::homing::{Homing, HomingConfig};
use twoport_control::servo::{Gains, SensorFrame, Servo, ServoOutput};
use twoport_control::world::World;
use twoport_control::{Faults, Position};
use twoport_link::{
    encode, ActuatorFrame, Axes, AxisRefusal, AxisTelemetry, BoardMode, Decoder, GainsReply,
    LinkStats, Message, Refusal, Stats, Telemetry, MAX_AXES, MAX_FRAME, NO_SESSION,
};

/// One encoded frame, delimiter included.
pub type Frame = Vec<u8, MAX_FRAME>;

/// Frames each outgoing queue holds: replies and fault reports in one,
/// telemetry in the other, so a telemetry flood never crowds out an answer.
pub const TX_FRAMES: usize = 8;

/// The portable firmware loop around the [`Drive`] `D` of `N` axes (one by
/// default): a [`Servo`] on its world with its port layer
/// (`Board<Servo<UnilateralWall>, R>`), or a linkage's servo whose `N`
/// motors turn joints. Each Cartesian axis has its own proven region of
/// `R` grid points, load-cell scaling and homing; the handshake declares
/// `N`.
#[derive(Clone, Debug)]
pub struct Board<D, const R: usize, const N: usize = 1> {
    servo: D,
    regions: [Region<R>; N],
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
    io: [IoScale; N],
    last: ServoOutput<f32, N>,
    /// Each motor's command at the last tick (N, or N m at a joint).
    motor: [f32; N],
    /// Whether sensor frames from the link drive ticks (processor in the
    /// loop). A board with real sensors must never let the host move it.
    pil: bool,
    pil_refused: u32,
    /// The host's sensor frame waiting for the next control tick, with
    /// the encoders' index counts it carries (PIL).
    pending: Option<(SensorFrame<f32, N>, [Option<u32>; N])>,
    /// Ticks run from the board's own sensors (their frame's `tick`).
    ticks: u32,
    /// The state machine: disarmed at boot.
    mode: BoardMode,
    /// The host's session, stamped on every answer ([`NO_SESSION`] from
    /// boot until a handshake): a host sees a reset by it.
    session: u16,
    /// Whether the encoder's offset is known.
    calibrated: bool,
    /// How each axis homes, and the run in progress (in
    /// [`BoardMode::Homing`]): an axis that has homed holds no force while the
    /// others go on.
    homing_cfg: [HomingConfig; N],
    homing: Option<[Option<Homing>; N]>,
    /// The identification experiment in progress (in
    /// [`BoardMode::Identifying`]).
    experiment: Option<Experiment<N>>,
    /// The host's VE, when the coupling holds it instead of the image's
    /// (protocol 8).
    host: Option<host_ve::HostVe<N>>,
    /// Each axis's travel (lowest, highest), where the image knows it,
    /// and what the link carries (bytes/s): stated in the spec.
    workspace: [Option<(Position, Position)>; N],
    link_bytes_per_s: Option<u32>,
    /// Gains outside the proven regions are accepted: the user's explicit
    /// choice ([`Board::accepting_unproven_gains`]).
    unproven_allowed: bool,
    /// Sets of gains accepted outside the proven regions.
    unproven_sets: u32,
    /// The dead-man switch at the last tick (open before the first).
    dead_man_closed: bool,
    /// Whether the amplifier's outputs are on (as last commanded).
    outputs_on: bool,
    /// Where the configuration in force came from.
    config_source: Option<twoport_link::ConfigSource>,
    /// A `SaveConfig` waiting for the main loop.
    save_pending: bool,
    /// The encoder counts index pulses latched, for this tick.
    index: [Option<u32>; N],
    /// Loop timing (the last tick's stages, its start, the overruns and
    /// the worst jitter since boot) and the latency gate's state.
    timing: Timing,
}

impl<D: Drive<N>, const R: usize, const N: usize> Board<D, R, N> {
    /// A board running `servo`, accepting gain changes on each axis inside
    /// its region of `regions`, and sending telemetry every
    /// `telemetry_every` ticks (0: never). It boots disarmed and
    /// uncalibrated, each axis homing toward its negative end with
    /// [`HomingConfig::gentle`] onto a stop at the origin unless
    /// [`with_homing`](Self::with_homing) says otherwise.
    ///
    /// `N` is between 1 and the link's [`MAX_AXES`] (checked at compile
    /// time).
    pub fn new(servo: D, regions: [Region<R>; N], telemetry_every: u32) -> Self {
        const { assert!(N >= 1 && N <= MAX_AXES, "a board has 1 to MAX_AXES axes") };
        let period_s = servo.servo().safety().configs()[0].period_s;
        let position = servo.servo().position();
        Board {
            servo,
            regions,
            decoder: Decoder::new(),
            control: Deque::new(),
            telemetry: Deque::new(),
            seq: 0,
            telemetry_every,
            since_telemetry: 0,
            reported: Faults::NONE,
            loop_cycles: 0,
            tx_dropped: 0,
            io: [IoScale::EXCALIBUR; N],
            last: ServoOutput::at_rest(position, [0.0; N]),
            motor: [0.0; N],
            pil: false,
            pil_refused: 0,
            pending: None,
            ticks: 0,
            mode: BoardMode::Disarmed,
            session: NO_SESSION,
            calibrated: false,
            homing_cfg: [HomingConfig::gentle(Position::ZERO, period_s); N],
            homing: None,
            experiment: None,
            host: None,
            workspace: [None; N],
            link_bytes_per_s: None,
            unproven_allowed: false,
            unproven_sets: 0,
            dead_man_closed: false,
            outputs_on: false,
            config_source: None,
            save_pending: false,
            index: [None; N],
            timing: Timing::default(),
        }
    }

    /// The same board with each axis homing with its `cfg` (whose
    /// `period_s` must be the servo's; [`Message::Home`] refuses a
    /// configuration that does not validate).
    pub fn with_homing(mut self, cfg: [HomingConfig; N]) -> Self {
        self.homing_cfg = cfg;
        self
    }

    /// The same board stating each axis's travel (lowest, highest
    /// position) in its spec.
    pub fn with_workspace(mut self, travel: [(Position, Position); N]) -> Self {
        self.workspace = travel.map(Some);
        self
    }

    /// The same board stating what its link carries (bytes/s: a UART's
    /// baud over ten) in its spec.
    pub fn with_link_rate(mut self, bytes_per_s: u32) -> Self {
        self.link_bytes_per_s = Some(bytes_per_s);
        self
    }

    /// The same board accepting gains outside its proven regions (each
    /// still inside what the laws take): the user's explicit choice, for
    /// an experiment past the proof. No image ships with it; the host
    /// that makes the choice logs it, and every such set
    /// ([`unproven_sets`](Self::unproven_sets)).
    pub fn accepting_unproven_gains(mut self) -> Self {
        self.unproven_allowed = true;
        self
    }

    /// Sets of gains accepted outside the proven regions.
    pub fn unproven_sets(&self) -> u32 {
        self.unproven_sets
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

    /// The same board with `io` scaling each axis's peripherals (default:
    /// [`IoScale::EXCALIBUR`]).
    pub fn with_io(mut self, io: [IoScale; N]) -> Self {
        self.io = io;
        self
    }

    /// How each axis's peripherals scale.
    pub fn io(&self) -> [IoScale; N] {
        self.io
    }

    /// The last tick's output.
    pub fn last_output(&self) -> &ServoOutput<f32, N> {
        &self.last
    }

    /// Each motor's signed PWM duty for its held command (an axis's force,
    /// or a joint's torque, against its `IoScale`'s full scale).
    pub fn duty(&self) -> [i16; N] {
        core::array::from_fn(|i| self.io[i].duty(self.motor[i]))
    }

    /// The Cartesian servo (gains, safety state).
    pub fn servo(&self) -> &Servo<D::World, f32, N, D::Layer> {
        self.servo.servo()
    }

    /// What the board drives: the Cartesian servo, or the linkage's servo
    /// around it.
    pub fn drive(&self) -> &D {
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

    /// Each axis's value, as the link carries them.
    fn axes<T: Copy>(xs: [T; N]) -> Axes<T> {
        // (`new` checked 1 <= N <= MAX_AXES.)
        Axes::new(xs).unwrap_or(Axes::one(xs[0]))
    }

    fn handle(&mut self, msg: Message) {
        if let Some(ack) = msg.answer(N as u8, self.session) {
            if let Message::HelloAck { session, .. } = ack {
                if session != self.session {
                    // Telemetry queued in the old session would reach the
                    // host after the answer, stamped with the old number.
                    self.telemetry.clear();
                }
                self.session = session;
            }
            self.queue(ack);
            return;
        }
        match msg {
            Message::Heartbeat => self.servo.servo_mut().heartbeat(),
            Message::GetGains => {
                let g = Self::axes(self.servo.servo().gains().map(Into::into));
                self.queue(Message::Gains(g));
            }
            Message::SetGains(g) => {
                let reply = match g.to_array::<N>() {
                    Some(g) => {
                        let g = g.map(Gains::from);
                        match self.check(&g) {
                            Ok(()) => self.apply(g),
                            Err(_) if self.unproven_allowed => {
                                let reply = self.apply(g);
                                if matches!(reply, GainsReply::Accepted(_)) {
                                    self.unproven_sets = self.unproven_sets.saturating_add(1);
                                }
                                reply
                            }
                            Err(why) => GainsReply::Refused(why),
                        }
                    }
                    None => GainsReply::Refused(AxisRefusal {
                        axis: 0,
                        why: Refusal::WrongAxisCount { axes: N as u8 },
                    }),
                };
                self.queue(Message::GainsReply(reply));
            }
            Message::ClearFaults => {
                Drive::clear(&mut self.servo);
                self.reported = Faults::NONE;
                self.queue_status();
            }
            Message::Arm => self.arm(),
            Message::Disarm => {
                // (A board disarmed already answers with its status too:
                // the host's call waits for one.)
                let was = self.mode;
                self.disarm();
                if was == BoardMode::Disarmed {
                    self.queue_status();
                }
            }
            Message::Home => self.home(),
            Message::Identify(req) => self.identify(req),
            Message::GetSpec => self.answer_spec(),
            Message::SetStream { every_ticks } => self.answer_stream(every_ticks),
            Message::SetVe(source) => self.set_ve(source),
            Message::VeUpdate(u) => self.ve_update(u),
            Message::SetVeParam { axis, param } => self.set_ve_param(axis, param),
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
            Message::Sensors(s) => {
                // (The handshake agreed on the axes, so a frame of another
                // count is a host's error: it is counted and never ticks.)
                let (Some(enc), Some(cells), Some(index)) = (
                    s.encoder_raw.to_array::<N>(),
                    s.load_cell_raw.to_array::<N>(),
                    s.index_raw.to_array::<N>(),
                ) else {
                    self.pil_refused = self.pil_refused.saturating_add(1);
                    return;
                };
                let frame = SensorFrame {
                    tick: s.tick,
                    encoder_raw: enc,
                    load_cell_n: core::array::from_fn(|i| self.io[i].load_cell_n(cells[i])),
                    dead_man_closed: s.dead_man_closed,
                };
                self.pending = Some((frame, index));
            }
            _ => {}
        }
    }

    /// Whether each axis's gains of `g` lie inside its proven region for
    /// this board's display; the first axis that does not, and why.
    fn check(&self, g: &[Gains; N]) -> Result<(), AxisRefusal> {
        check_axes(&self.regions, self.servo.servo().display(), g)
    }

    fn apply(&mut self, g: [Gains; N]) -> GainsReply {
        match self.servo.servo_mut().set_gains(g) {
            Ok(()) => GainsReply::Accepted(Self::axes(self.servo.servo().gains().map(Into::into))),
            Err(e) => GainsReply::Refused(AxisRefusal {
                axis: e.axis as u8,
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
    pub fn poll_link(&mut self, io: &mut impl BoardSupport<N>) -> bool {
        while self.pending.is_none() {
            let Some(b) = io.read_byte() else { break };
            self.on_bytes(&[b]);
        }
        self.pending.is_some()
    }

    /// Send every queued frame (replies first, then telemetry).
    pub fn flush(&mut self, io: &mut impl BoardSupport<N>) {
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
    pub fn control_tick(&mut self, io: &mut impl BoardSupport<N>) -> ServoOutput<f32, N> {
        self.control_tick_serving(io, |_| {})
    }

    /// [`control_tick`](Self::control_tick) that, while a processor-in-
    /// the-loop board waits for its host, also runs `serve` on it: the
    /// main loop's other work, such as [`service_config`](Self::service_config),
    /// which would otherwise wait for the tick the host is waiting on.
    pub fn control_tick_serving(
        &mut self,
        io: &mut impl BoardSupport<N>,
        serve: impl FnMut(&mut Self),
    ) -> ServoOutput<f32, N> {
        let out = self.control_tick_inner(io, serve);
        // Outputs follow the mode, within the tick that changed it.
        self.drive_outputs(io);
        out
    }

    fn control_tick_inner(
        &mut self,
        io: &mut impl BoardSupport<N>,
        mut serve: impl FnMut(&mut Self),
    ) -> ServoOutput<f32, N> {
        let (frame, start) = if self.pil {
            let frame = loop {
                io.feed_watchdog();
                self.poll_link(io);
                if let Some((f, index)) = self.pending.take() {
                    self.index = index;
                    break f;
                }
                serve(self);
                self.flush(io);
            };
            (frame, io.cycles())
        } else {
            let start = io.cycles();
            let raw = io.sample();
            let frame = SensorFrame {
                tick: self.ticks,
                encoder_raw: raw.encoder_raw,
                load_cell_n: core::array::from_fn(|i| {
                    self.io[i].load_cell_n(raw.load_cell_counts[i])
                }),
                dead_man_closed: raw.dead_man_closed,
            };
            self.index = raw.index_raw;
            self.ticks = self.ticks.wrapping_add(1);
            (frame, start)
        };
        let sensed = io.cycles();
        let (out, identifying) = self.law(&frame);
        self.index = [None; N];
        let ruled = io.cycles();
        let duty = self.duty();
        io.set_duty(duty);
        let written = io.cycles();
        // What the tick reports is encoded after the command is written:
        // the latency from the sample to the force is the law's alone.
        self.report(&frame, &out, identifying);
        io.feed_watchdog();
        if self.pil {
            self.queue(Message::Actuator(ActuatorFrame {
                tick: frame.tick,
                duty: Self::axes(duty),
                session: self.session,
            }));
        }
        let end = io.cycles();
        self.loop_cycles = end.wrapping_sub(start);
        let period = io.cycles_per_tick();
        let latency = io
            .force_latency()
            .unwrap_or_else(|| written.wrapping_sub(start));
        self.timing
            .record(start, [sensed, ruled, end], latency, period);
        self.hold_latency(latency);
        out
    }

    /// One control tick: the law, a fault report when new faults latch,
    /// telemetry on schedule. Returns the held actuator command.
    pub fn tick(&mut self, frame: &SensorFrame<f32, N>) -> ServoOutput<f32, N> {
        let (out, identifying) = self.law(frame);
        self.report(frame, &out, identifying);
        out
    }

    /// The tick's law: the held actuator command, and whether the tick was
    /// an experiment's (its telemetry goes out in that mode, even on the
    /// tick that ends it).
    fn law(&mut self, frame: &SensorFrame<f32, N>) -> (ServoOutput<f32, N>, bool) {
        self.dead_man_closed = frame.dead_man_closed;
        self.host_ve_tick();
        let driven = match (self.homing.as_mut(), self.experiment.as_ref()) {
            // Each axis's homing law in place of the display's, through the
            // same safety layer; an axis that has homed holds no force.
            (Some(h), _) => self
                .servo
                .tick_with(frame, |i, x, v| h[i].as_mut().map_or(0.0, |h| h.step(x, v))),
            // The experiment's law, through the same safety layer.
            (None, Some(e)) => self.servo.tick_with(frame, |i, x, v| e.force(i, x, v)),
            (None, None) => match self.host.as_mut() {
                Some(h) => self.servo.tick_on(frame, &mut h.world),
                None => self.servo.tick(frame),
            },
        };
        let out = driven.cartesian;
        self.last = out;
        self.motor = driven.motor;
        let identifying = self.mode == BoardMode::Identifying;
        self.after_experiment_tick();
        self.after_tick(&out);
        (out, identifying)
    }

    /// What a tick reports: a fault report when new faults latch, and
    /// telemetry on schedule.
    fn report(
        &mut self,
        frame: &SensorFrame<f32, N>,
        out: &ServoOutput<f32, N>,
        identifying: bool,
    ) {
        if !out.faults.is_empty() && out.faults != self.reported {
            self.reported = out.faults;
            self.queue(Message::FaultReport {
                faults: out.faults.0,
                first: out.faults.lowest().0,
            });
        }
        if self.telemetry_every > 0 || identifying {
            self.since_telemetry += 1;
            // Every tick of an experiment: its record is the point of it.
            if self.since_telemetry >= self.telemetry_every || identifying {
                self.since_telemetry = 0;
                let (ve, ve_seq) = match &self.host {
                    Some(h) => (World::<f32, N>::positions(&h.world), h.seq()),
                    None => (self.servo.servo().world().positions(), 0),
                };
                let axes = core::array::from_fn(|i| AxisTelemetry {
                    position_pm: out.position[i].nm() as i64 * 1000,
                    velocity_mps: out.velocity_mps[i],
                    load_cell_n: frame.load_cell_n[i],
                    commanded_n: out.commanded_force_n[i],
                    actuator_n: out.actuator_force_n[i],
                    ve_position_pm: ve[i].nm() as i64 * 1000,
                });
                self.queue(Message::Telemetry(Telemetry {
                    tick: frame.tick,
                    axes: Self::axes(axes),
                    faults: out.faults.0,
                    loop_cycles: self.loop_cycles,
                    mode: if identifying {
                        BoardMode::Identifying
                    } else {
                        self.mode
                    },
                    stage_cycles: self.timing.stages,
                    deadline_misses: self.timing.deadline_misses,
                    worst_jitter_cycles: self.timing.worst_jitter,
                    worst_latency_cycles: self.timing.worst_latency,
                    session: self.session,
                    ve_seq,
                }));
            }
        }
    }
}
