//! The loop: servo tick, link in, frames out.

use crate::io::IoScale;
use crate::region::{Bound, Region};
use heapless::{Deque, Vec};
use twoport_control::servo::{SensorFrame, ServoOutput};
use twoport_control::ve::VirtualEnvironment;
use twoport_control::{AdmittanceServo, Faults, ImpedanceServo};
use twoport_link::{
    encode, ActuatorFrame, Decoder, Gains, GainsReply, LinkStats, Message, Refusal, Stats,
    Telemetry, MAX_FRAME,
};

/// One encoded frame, delimiter included.
pub type Frame = Vec<u8, MAX_FRAME>;
/// Frames each outgoing queue holds: replies and fault reports in one,
/// telemetry in the other, so a telemetry flood never crowds out an answer.
pub const TX_FRAMES: usize = 8;

/// The display's law, with the board's VE.
#[derive(Clone, Debug)]
pub enum Law<V> {
    /// Impedance display.
    Impedance(ImpedanceServo<V>),
    /// Admittance display.
    Admittance(AdmittanceServo<V>),
}

macro_rules! both {
    ($self:expr, $s:ident => $e:expr) => {
        match $self {
            Law::Impedance($s) => $e,
            Law::Admittance($s) => $e,
        }
    };
}

impl<V: VirtualEnvironment> Law<V> {
    fn tick(&mut self, f: &SensorFrame) -> ServoOutput {
        both!(self, s => s.tick(f))
    }

    fn gains(&self) -> Gains {
        match self {
            Law::Impedance(s) => {
                let (k, b) = s.coupling().gains();
                Gains::Impedance {
                    k_npm: k,
                    b_nspm: b,
                }
            }
            Law::Admittance(s) => {
                let (kp, bp) = s.regulator().gains();
                let (m, b) = s.coupling().gains();
                Gains::Admittance {
                    kp_npm: kp,
                    bp_nspm: bp,
                    m_kg: m,
                    b_nspm: b,
                }
            }
        }
    }

    /// The VE position (pm).
    fn ve_position_pm(&self) -> i64 {
        both!(self, s => s.ve().position().nm() as i64 * 1000)
    }
}

/// The portable firmware loop.
#[derive(Clone, Debug)]
pub struct Board<V, const R: usize> {
    law: Law<V>,
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
}

fn all_finite(g: &Gains) -> bool {
    match *g {
        Gains::Impedance { k_npm, b_nspm } => k_npm.is_finite() && b_nspm.is_finite(),
        Gains::Admittance {
            kp_npm,
            bp_nspm,
            m_kg,
            b_nspm,
        } => kp_npm.is_finite() && bp_nspm.is_finite() && m_kg.is_finite() && b_nspm.is_finite(),
    }
}

impl<V: VirtualEnvironment, const R: usize> Board<V, R> {
    /// A board running `law`, accepting gain changes inside `region`, and
    /// sending telemetry every `telemetry_every` ticks (0: never).
    pub fn new(law: Law<V>, region: Region<R>, telemetry_every: u32) -> Self {
        Board {
            law,
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
        }
    }

    /// The same board driven by sensor frames from the link (processor in
    /// the loop: the QEMU image, the host's reference). Off by default: a
    /// board with real sensors ignores sensor frames and counts them.
    pub fn with_pil(mut self, on: bool) -> Self {
        self.pil = on;
        self
    }

    /// Sensor frames ignored because this board reads its own sensors.
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

    /// The law (gains, safety state).
    pub fn law(&self) -> &Law<V> {
        &self.law
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

    /// What the board support measured the last tick to cost.
    pub fn set_loop_cycles(&mut self, cycles: u32) {
        self.loop_cycles = cycles;
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
        if let Some(ack) = msg.answer() {
            self.queue(ack);
            return;
        }
        match msg {
            Message::Heartbeat => both!(&mut self.law, s => s.heartbeat()),
            Message::GetGains => self.queue(Message::Gains(self.law.gains())),
            Message::SetGains(g) => {
                let reply = match self.check(&g) {
                    Ok(()) => self.apply(g),
                    Err(why) => GainsReply::Refused(why),
                };
                self.queue(Message::GainsReply(reply));
            }
            Message::ClearFaults => {
                both!(&mut self.law, s => s.clear());
                self.reported = Faults::NONE;
            }
            Message::Enable => {
                if let Err(f) = both!(&mut self.law, s => s.enable()) {
                    self.queue(Message::FaultReport {
                        faults: f.0,
                        first: f.lowest().0,
                    });
                }
            }
            Message::Disable => both!(&mut self.law, s => s.disable()),
            Message::GetStats => self.queue(Message::Stats(LinkStats {
                rx: self.decoder.stats(),
                tx_dropped: self.tx_dropped,
            })),
            // Processor-in-the-loop: the host's sensors drive one tick, the
            // duty goes straight back.
            Message::Sensors(_) if !self.pil => {
                self.pil_refused = self.pil_refused.saturating_add(1);
            }
            Message::Sensors(s) => {
                let frame = SensorFrame {
                    tick: s.tick,
                    encoder_raw: s.encoder_raw,
                    load_cell_n: self.io.load_cell_n(s.load_cell_raw),
                    dead_man_closed: s.dead_man_closed,
                };
                self.tick(&frame);
                let duty = self.duty();
                self.queue(Message::Actuator(ActuatorFrame { tick: s.tick, duty }));
            }
            _ => {}
        }
    }

    /// Whether `g` is inside the proven region for this board's display.
    fn check(&self, g: &Gains) -> Result<(), Refusal> {
        if !all_finite(g) {
            return Err(Refusal::NotFinite);
        }
        let r = &self.region;
        match (&self.law, *g) {
            (Law::Impedance(_), Gains::Impedance { k_npm, b_nspm })
                if r.bound() == Bound::MaxStiffness =>
            {
                if k_npm < 0.0 || b_nspm < 0.0 {
                    return Err(Refusal::OutOfRange);
                }
                match r.limit_at(b_nspm) {
                    Some(kmax) if k_npm <= kmax => Ok(()),
                    Some(kmax) => Err(Refusal::NotProvenStable { limit: kmax }),
                    None => Err(Refusal::NotProvenStable { limit: 0.0 }),
                }
            }
            (
                Law::Admittance(_),
                Gains::Admittance {
                    kp_npm,
                    bp_nspm,
                    m_kg,
                    b_nspm,
                },
            ) if r.bound() == Bound::MinMass => {
                if m_kg <= 0.0 || b_nspm <= 0.0 || kp_npm < 0.0 || bp_nspm < 0.0 {
                    return Err(Refusal::OutOfRange);
                }
                // The region holds for the regulator it was proven with.
                match r.regulator() {
                    Some((kp, bp)) if kp == kp_npm && bp == bp_nspm => {}
                    Some((kp, _)) => return Err(Refusal::NotProvenStable { limit: kp }),
                    None => return Err(Refusal::NotProvenStable { limit: 0.0 }),
                }
                match r.limit_at(b_nspm) {
                    Some(mmin) if m_kg >= mmin => Ok(()),
                    Some(mmin) => Err(Refusal::NotProvenStable { limit: mmin }),
                    None => Err(Refusal::NotProvenStable { limit: 0.0 }),
                }
            }
            _ => Err(Refusal::WrongDisplay),
        }
    }

    fn apply(&mut self, g: Gains) -> GainsReply {
        let r = match (&mut self.law, g) {
            (Law::Impedance(s), Gains::Impedance { k_npm, b_nspm }) => s.set_gains(k_npm, b_nspm),
            (
                Law::Admittance(s),
                Gains::Admittance {
                    kp_npm,
                    bp_nspm,
                    m_kg,
                    b_nspm,
                },
            ) => s
                .set_regulator_gains(kp_npm, bp_nspm)
                .and_then(|_| s.set_coupling_gains(m_kg, b_nspm)),
            _ => return GainsReply::Refused(Refusal::WrongDisplay),
        };
        match r {
            Ok(()) => GainsReply::Accepted(self.law.gains()),
            Err(_) => GainsReply::Refused(Refusal::OutOfRange),
        }
    }

    /// One control tick: the law, a fault report when new faults latch,
    /// telemetry on schedule. Returns the held actuator command.
    pub fn tick(&mut self, frame: &SensorFrame) -> ServoOutput {
        let out = self.law.tick(frame);
        self.last = out;
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
                    position_pm: out.position.nm() as i64 * 1000,
                    velocity_mps: out.velocity_mps,
                    load_cell_n: frame.load_cell_n,
                    commanded_n: out.commanded_force_n,
                    actuator_n: out.actuator_force_n,
                    ve_position_pm: self.law.ve_position_pm(),
                    faults: out.faults.0,
                    loop_cycles: self.loop_cycles,
                }));
            }
        }
        out
    }
}
