//! A session with one board: the handshake that opens it, the calls that
//! ask and wait for answers, the lockstep exchange of a processor-in-the-
//! loop run, and the link faults a test injects.

use crate::{BoardPort, LinkError};
use std::sync::atomic::{AtomicU16, Ordering};
use std::time::{Duration, Instant};
use twoport_board::excalibur;
use twoport_link::{
    encode, Axes, BoardMode, ConfigSource, Contact, Decoder, Gains, GainsReply, LinkStats, Message,
    ModeRequest, PilSensors, Role, Spec, Status, VeParam, VeSource, VeUpdate, MAX_FRAME,
    NO_SESSION,
};

/// How long the host waits for the board's answer to one frame.
pub const ANSWER_TIMEOUT: Duration = Duration::from_secs(5);
/// Heartbeats go out every this many ticks (the board's watchdog allows
/// [`excalibur::HEARTBEAT_TIMEOUT_TICKS`]).
pub const HEARTBEAT_EVERY: u64 = 10;

/// What to do to the link during a run.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LinkFaults {
    /// Every this many ticks, send a corrupted copy of the tick's sensor
    /// frame (one byte flipped) and a burst of garbage first (0: never).
    pub corrupt_every: u64,
    /// Stop the heartbeats from this tick on (a lost host).
    pub link_loss_at: Option<u64>,
}

/// The host side of a lockstep link to a board: handshake, heartbeats,
/// one sensor frame out and one actuator frame back per tick, and whatever
/// else the board says kept for the caller.
pub struct Session<P: BoardPort> {
    port: P,
    /// The axes this host drives.
    axes: u8,
    /// The session this host opened (never `NO_SESSION`), and whether the
    /// handshake is done: from then on every stamped answer must carry it.
    session: u16,
    open: bool,
    /// The first other session a stamped answer carried since the
    /// handshake, noted as it arrived (so no caller's taking it can hide it).
    foreign: Option<u16>,
    seq: u16,
    decoder: Decoder,
    inbox: Vec<Message>,
    /// The board's sensor and actuator scaling (counts to SI), for a host
    /// that plays its plant.
    pub io: twoport_board::IoScale,
    faults: LinkFaults,
    tick: u64,
    /// The encoder's index mark as a count, and the unwrapped count of
    /// the last frame: the host plays the encoder's index hardware.
    index: Option<(i64, Option<i64>)>,
    /// Frames the host injected corrupted.
    pub corrupted_sent: u64,
    /// Heartbeats sent this often while a call waits for its answer (a
    /// board that runs on its own clock), or none (lockstep: the host's
    /// ticks carry them, and the board's watchdog counts its ticks).
    heartbeat_while_waiting: Option<Duration>,
}

impl<P: BoardPort> Session<P> {
    /// Shake hands with the one-axis board at `port`. It is disarmed until
    /// [`arm`](Self::arm).
    pub fn open(port: P, faults: LinkFaults) -> Result<Self, LinkError> {
        Self::open_axes(port, faults, 1)
    }

    /// Shake hands with the board of `axes` axes at `port`: a board of
    /// another count is refused, with both counts named.
    pub fn open_axes(port: P, faults: LinkFaults, axes: u8) -> Result<Self, LinkError> {
        let mut s = Session {
            port,
            axes,
            session: new_session(),
            open: false,
            foreign: None,
            seq: 0,
            decoder: Decoder::new(),
            inbox: Vec::new(),
            io: twoport_board::IoScale::EXCALIBUR,
            faults,
            tick: 0,
            index: None,
            corrupted_sent: 0,
            heartbeat_while_waiting: None,
        };
        s.handshake()?;
        Ok(s)
    }

    /// The port the board is on.
    pub fn port(&self) -> &P {
        &self.port
    }

    /// Send a heartbeat every `period` while a call waits for its answer:
    /// for a board on its own clock, whose watchdog runs while the host
    /// waits (the device object sets it; lockstep sessions do not).
    pub fn heartbeat_while_waiting(&mut self, period: Duration) {
        self.heartbeat_while_waiting = Some(period);
    }

    /// Ask for a mode change and wait for the board's status that shows it
    /// done, or its refusal of it: over a real link, other statuses may
    /// still be on their way.
    fn ask(
        &mut self,
        msg: Message,
        asked: ModeRequest,
        done: fn(&Status) -> bool,
    ) -> Result<Status, LinkError> {
        self.drop_stale_statuses();
        self.send(&msg)?;
        let what = format!("{asked:?}");
        let r = self.wait(&what, |m| match m {
            Message::Status(s) if done(s) => Some(Ok(*s)),
            Message::ModeRefused { asked: a, why } if *a == asked => Some(Err(*why)),
            _ => None,
        })?;
        r.map_err(|why| LinkError::Refused { asked, why })
    }

    /// Statuses and refusals already received answer earlier questions,
    /// not the next one.
    fn drop_stale_statuses(&mut self) {
        self.inbox
            .retain(|m| !matches!(m, Message::Status(_) | Message::ModeRefused { .. }));
    }

    /// Calibrate a disarmed board: each axis stands at its `position_pm`
    /// (pm).
    pub fn calibrate(&mut self, position_pm: Axes<i64>) -> Result<Status, LinkError> {
        self.ask(
            Message::Calibrate { position_pm },
            ModeRequest::Calibrate,
            |s| s.calibrated,
        )
    }

    /// Arm the board (it must have had a tick, to see its dead-man).
    pub fn arm(&mut self) -> Result<Status, LinkError> {
        self.ask(Message::Arm, ModeRequest::Arm, |s| {
            s.mode == BoardMode::Armed
        })
    }

    /// Start an identification experiment on an armed board; the caller
    /// runs its ticks, the board streaming each.
    pub fn identify(&mut self, x: twoport_link::ExperimentRequest) -> Result<Status, LinkError> {
        self.ask(Message::Identify(x), ModeRequest::Identify, |s| {
            s.mode == BoardMode::Identifying
        })
    }

    /// Start homing; the caller runs ticks until the board's status says
    /// it has homed.
    pub fn home(&mut self) -> Result<Status, LinkError> {
        self.ask(Message::Home, ModeRequest::Home, |s| {
            s.mode == BoardMode::Homing
        })
    }

    /// Where the board's configuration came from.
    pub fn config(&mut self) -> Result<ConfigSource, LinkError> {
        self.call(&Message::GetConfig, "GetConfig", |m| match m {
            Message::Config(c) => Some(*c),
            _ => None,
        })
    }

    /// Send `msg` and wait for the answer `pick` takes. Any such answer
    /// already received answered an earlier question, and goes first.
    pub fn call<T>(
        &mut self,
        msg: &Message,
        what: &str,
        mut pick: impl FnMut(&Message) -> Option<T>,
    ) -> Result<T, LinkError> {
        self.inbox.retain(|m| pick(m).is_none());
        self.send(msg)?;
        self.wait(what, pick)
    }

    /// What the board can do: its period, each axis's limits and proven
    /// region, and the telemetry rate in force (protocol 8).
    pub fn spec(&mut self) -> Result<Spec, LinkError> {
        self.call(&Message::GetSpec, "GetSpec", |m| match m {
            Message::Spec(s) => Some(*s),
            _ => None,
        })
    }

    /// Have the board send telemetry every `every_ticks` ticks (0: none
    /// outside an experiment), and wait until it says so (protocol 8).
    pub fn set_stream(&mut self, every_ticks: u32) -> Result<(), LinkError> {
        let msg = Message::SetStream { every_ticks };
        self.call(&msg, "SetStream", |m| match m {
            Message::Stream { every_ticks: e } if *e == every_ticks => Some(()),
            _ => None,
        })
    }

    /// New gains, one per axis: all in force from the next tick, or none,
    /// with the first axis the board refused and why.
    pub fn set_gains(&mut self, gains: Axes<Gains>) -> Result<Axes<Gains>, LinkError> {
        let r = self.call(&Message::SetGains(gains), "SetGains", |m| match m {
            Message::GainsReply(r) => Some(*r),
            _ => None,
        })?;
        match r {
            GainsReply::Accepted(g) => Ok(g),
            GainsReply::Refused(why) => Err(LinkError::GainsRefused(why)),
        }
    }

    /// Run the VE on the board or on the host (disarmed only), and wait
    /// for the board to say which it runs (protocol 8).
    pub fn set_ve(&mut self, source: VeSource) -> Result<VeSource, LinkError> {
        self.request(&Message::SetVe(source), ModeRequest::SetVe, |m| match m {
            Message::Ve(s) => Some(*s),
            _ => None,
        })
    }

    /// Set one parameter of the board's own VE on `axis` (disarmed only),
    /// and wait for the board to say what it set (protocol 9).
    pub fn set_ve_param(&mut self, axis: u8, param: VeParam) -> Result<VeParam, LinkError> {
        let msg = Message::SetVeParam { axis, param };
        self.request(&msg, ModeRequest::SetVeParam, |m| match m {
            Message::VeParamSet { axis: a, param } if *a == axis => Some(*param),
            _ => None,
        })
    }

    /// Store the configuration in force in the board's flash (disarmed
    /// only), and where it is now.
    pub fn save(&mut self) -> Result<ConfigSource, LinkError> {
        self.request(&Message::SaveConfig, ModeRequest::SaveConfig, |m| match m {
            Message::Config(c @ ConfigSource::Stored { .. }) => Some(*c),
            _ => None,
        })
    }

    /// [`call`](Self::call) for a request the board may refuse: the answer
    /// `pick` takes, or the board's refusal of `asked` as an error.
    fn request<T>(
        &mut self,
        msg: &Message,
        asked: ModeRequest,
        mut pick: impl FnMut(&Message) -> Option<T>,
    ) -> Result<T, LinkError> {
        let r = self.call(msg, &format!("{asked:?}"), |m| match m {
            Message::ModeRefused { asked: a, why } if *a == asked => Some(Err(*why)),
            m => pick(m).map(Ok),
        })?;
        r.map_err(|why| LinkError::Refused { asked, why })
    }

    /// Send the host VE's surfaces and what each is, update `seq` (no
    /// answer: the telemetry's `ve_seq` says which update the board holds).
    pub fn ve_update(
        &mut self,
        seq: u32,
        position_pm: Axes<i64>,
        contact: Axes<Contact>,
    ) -> Result<(), LinkError> {
        self.send(&Message::VeUpdate(VeUpdate {
            seq,
            position_pm,
            contact,
        }))
    }

    /// The scene's encoder has an index mark at `index_m` (m): send the
    /// count it latches in the sensor frame of each tick that passes it.
    pub fn set_index(&mut self, index_m: Option<f64>) {
        let pm = excalibur::ENCODER.pm_per_count;
        self.index = index_m.map(|m| ((m * 1e12 / pm as f64).round() as i64, None));
    }

    /// The count the index latched this tick, if the axis passed it
    /// between the last frame's `raw` and this one.
    pub fn index_crossing(&mut self, raw: u32) -> Option<u32> {
        let bits = excalibur::ENCODER.bits;
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
    pub fn status(&mut self) -> Result<Status, LinkError> {
        self.drop_stale_statuses();
        self.send(&Message::GetStatus)?;
        self.wait("GetStatus", |m| match m {
            Message::Status(s) => Some(*s),
            _ => None,
        })
    }

    fn frame(&mut self, msg: &Message) -> Result<Vec<u8>, LinkError> {
        let mut buf = [0u8; MAX_FRAME];
        let n = encode(self.seq, msg, &mut buf).map_err(|e| LinkError::Encode(format!("{e:?}")))?;
        self.seq = self.seq.wrapping_add(1);
        Ok(buf[..n].to_vec())
    }

    /// Send one message.
    pub fn send(&mut self, msg: &Message) -> Result<(), LinkError> {
        let f = self.frame(msg)?;
        self.port.send(&f)
    }

    fn pump(&mut self, timeout: Duration) -> Result<(), LinkError> {
        let mut buf = [0u8; 256];
        let n = self.port.recv(&mut buf, timeout)?;
        let (inbox, foreign) = (&mut self.inbox, &mut self.foreign);
        let (open, ours) = (self.open, self.session);
        self.decoder.feed(&buf[..n], |env| {
            if open && foreign.is_none() {
                *foreign = env.msg.session().filter(|s| *s != ours);
            }
            inbox.push(env.msg);
        });
        Ok(())
    }

    /// Read until `want` picks a message out, or time out.
    pub fn wait<T>(
        &mut self,
        what: &str,
        mut want: impl FnMut(&Message) -> Option<T>,
    ) -> Result<T, LinkError> {
        let deadline = Instant::now() + ANSWER_TIMEOUT;
        let mut beat = Instant::now();
        loop {
            self.check_session()?;
            if let Some(period) = self.heartbeat_while_waiting {
                if beat.elapsed() >= period {
                    self.send(&Message::Heartbeat)?;
                    beat = Instant::now();
                }
            }
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
                return Err(LinkError::Timeout {
                    what: what.to_string(),
                    seconds: ANSWER_TIMEOUT.as_secs(),
                });
            }
            let slice = self
                .heartbeat_while_waiting
                .unwrap_or(Duration::from_millis(50))
                .min(Duration::from_millis(50));
            self.pump((deadline - now).min(slice))?;
        }
    }

    /// Hello until the board answers (a pty drops what is sent before the
    /// other end opens it).
    fn handshake(&mut self) -> Result<(), LinkError> {
        let deadline = Instant::now() + ANSWER_TIMEOUT;
        loop {
            // A board's link may not take bytes at first (QEMU looks for a
            // pty's new reader once a second): a write that cannot go out
            // yet is tried again until the deadline, like one unanswered.
            let sent = self.send(&Message::hello(Role::Host, self.axes, self.session));
            if let Err(e) = sent {
                if Instant::now() > deadline {
                    return Err(e);
                }
            }
            self.pump(Duration::from_millis(100))?;
            if let Some(i) = self
                .inbox
                .iter()
                .position(|m| matches!(m, Message::HelloAck { .. }))
            {
                // What came before the answer was said in another session.
                let ack = self.inbox.remove(i);
                self.inbox.drain(..i);
                ack.accept_ack(self.axes, self.session)
                    .map_err(|e| LinkError::Handshake(e.to_string()))?;
                self.open = true;
                // What came after the answer in the same read is stamped.
                let ours = self.session;
                self.foreign = self
                    .inbox
                    .iter()
                    .filter_map(Message::session)
                    .find(|s| *s != ours);
                return Ok(());
            }
            if Instant::now() > deadline {
                // (A board of another protocol may answer in a form this
                // host cannot decode.)
                return Err(LinkError::NoHandshake(twoport_link::PROTOCOL_VERSION));
            }
        }
    }

    /// Read whatever the board has sent, waiting at most a millisecond
    /// (a free-running board: telemetry, replies, fault reports).
    pub fn poll(&mut self) -> Result<(), LinkError> {
        self.pump(Duration::from_millis(1))?;
        self.check_session()
    }

    /// The session this host opened with the board.
    pub fn session(&self) -> u16 {
        self.session
    }

    /// An error once the board has answered in another session than this
    /// host's: it has reset since the handshake (or another host has
    /// opened one).
    fn check_session(&self) -> Result<(), LinkError> {
        match self.foreign {
            None => Ok(()),
            Some(NO_SESSION) => Err(LinkError::Reset(self.session)),
            Some(found) => Err(LinkError::Foreign {
                found,
                ours: self.session,
            }),
        }
    }

    /// Messages the board sent that no one waited for (telemetry, fault
    /// reports, gain replies), oldest first.
    pub fn take_messages(&mut self) -> Vec<Message> {
        std::mem::take(&mut self.inbox)
    }

    /// The board's link counters.
    pub fn board_stats(&mut self) -> Result<LinkStats, LinkError> {
        self.call(&Message::GetStats, "GetStats", |m| match m {
            Message::Stats(s) => Some(*s),
            _ => None,
        })
    }

    /// Frames from the board this host dropped.
    pub fn host_dropped(&self) -> u32 {
        self.decoder.stats().dropped()
    }

    /// The next tick's number, with its heartbeat sent where one is due
    /// and the link is not lost.
    pub fn tick_heartbeat(&mut self) -> Result<u64, LinkError> {
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
    pub fn exchange(&mut self, tick: u64, sensors: PilSensors) -> Result<Axes<i16>, LinkError> {
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

/// A session number no other session of this process has had lately and
/// that is not `NO_SESSION`: the clock's low bits, then one more each time.
fn new_session() -> u16 {
    static LAST: AtomicU16 = AtomicU16::new(0);
    let clock = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(1, |d| d.subsec_nanos() as u16);
    let mut s = LAST.fetch_add(1, Ordering::Relaxed).wrapping_add(clock);
    if s == NO_SESSION {
        s = 1;
    }
    s
}
