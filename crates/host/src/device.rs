//! The device object an application holds: one board, opened, asked what
//! it can do, homed or calibrated, armed, its state streamed into a
//! buffer, its VE on the board or on the host, and disarmed when the
//! object goes.

use crate::{BoardPort, LinkError, LinkFaults, SerialBoard, Session};
use std::collections::VecDeque;
use std::time::{Duration, Instant};
use twoport_link::{
    Axes, BoardMode, ConfigSource, Contact, Gains, Message, Spec, Status, Telemetry, VeParam,
    VeSource,
};

/// States kept for the application before the oldest are dropped (about
/// a minute of a 1 kHz stream).
pub const STATE_BUFFER: usize = 1 << 16;

/// A heartbeat goes out with a poll at least this often (the board's
/// watchdog allows 50 ms).
pub const HEARTBEAT_PERIOD: Duration = Duration::from_millis(10);

/// ... or every this many polls, whichever comes first.
pub const HEARTBEAT_POLLS: u32 = 10;

/// One axis at one tick, in SI units. Its layout is C's: the C ABI hands
/// it over as `TpAxisState`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AxisState {
    /// Handle position (m).
    pub position_m: f64,
    /// Handle velocity (m/s).
    pub velocity_mps: f64,
    /// Load-cell force (N).
    pub load_cell_n: f64,
    /// Force the law commanded (N; positive resists positive motion).
    pub commanded_n: f64,
    /// Force sent to the amplifier, after the safety layer (N).
    pub actuator_n: f64,
    /// The VE point the coupling holds (m).
    pub ve_position_m: f64,
}

/// The board at one tick.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct State {
    /// The board's tick.
    pub tick: u32,
    /// Each axis's.
    pub axes: Axes<AxisState>,
    /// Latched fault bits (`twoport_control::Faults`).
    pub faults: u16,
    /// What the board was doing.
    pub mode: BoardMode,
    /// The host VE update the board held.
    pub ve_seq: u32,
    /// Ticks since boot that overran their period, or came more than
    /// half a period late.
    pub deadline_misses: u32,
    /// The loop's last tick, in the board's count (cycles, or
    /// instructions in an emulator).
    pub loop_cycles: u32,
    /// The largest difference since boot between a tick's start-to-start
    /// time and the period, in the same count.
    pub worst_jitter_cycles: u32,
    /// The longest time since boot from sampling the sensors to writing
    /// the amplifiers' command, in the same count: the latency inside the
    /// tick (the spec's `count_hz` gives it in seconds).
    pub worst_latency_cycles: u32,
}

impl From<&Telemetry> for State {
    fn from(t: &Telemetry) -> Self {
        State {
            tick: t.tick,
            axes: t.axes.map(|a| AxisState {
                position_m: a.position_pm as f64 * 1e-12,
                velocity_mps: f64::from(a.velocity_mps),
                load_cell_n: f64::from(a.load_cell_n),
                commanded_n: f64::from(a.commanded_n),
                actuator_n: f64::from(a.actuator_n),
                ve_position_m: a.ve_position_pm as f64 * 1e-12,
            }),
            faults: t.faults,
            mode: t.mode,
            ve_seq: t.ve_seq,
            deadline_misses: t.deadline_misses,
            loop_cycles: t.loop_cycles,
            worst_jitter_cycles: t.worst_jitter_cycles,
            worst_latency_cycles: t.worst_latency_cycles,
        }
    }
}

/// A board, as an application holds it. Every call waits for the board's
/// answer and names a refusal's reason. [`poll`](Self::poll) reads what
/// the board streams and keeps its watchdog fed: an application calls it
/// at least every 20 ms while the board is armed, or the board gives zero
/// force. Dropping the object disarms the board.
pub struct HostBoard<P: BoardPort> {
    session: Session<P>,
    spec: Spec,
    states: VecDeque<State>,
    dropped: u64,
    latest: Option<State>,
    last_heartbeat: Instant,
    polls: u32,
    ve_seq: u32,
    closed: bool,
}

impl HostBoard<SerialBoard> {
    /// Open the board of `axes` axes at the serial port `path` (a real
    /// board, or the firmware in QEMU through its pty).
    pub fn open_serial(path: &str, axes: u8) -> Result<Self, LinkError> {
        HostBoard::open(SerialBoard::open(path)?, axes)
    }
}

impl<P: BoardPort> HostBoard<P> {
    /// Shake hands with the board of `axes` axes at `port` and ask what it
    /// can do. A board of another protocol or axis count is refused, both
    /// named.
    pub fn open(port: P, axes: u8) -> Result<Self, LinkError> {
        let mut session = Session::open_axes(port, LinkFaults::default(), axes)?;
        // The board runs on its own clock: its watchdog runs while a call
        // waits for an answer.
        session.heartbeat_while_waiting(HEARTBEAT_PERIOD);
        let spec = session.spec()?;
        Ok(HostBoard {
            session,
            spec,
            states: VecDeque::new(),
            dropped: 0,
            latest: None,
            last_heartbeat: Instant::now(),
            polls: 0,
            ve_seq: 0,
            closed: false,
        })
    }

    /// The port the board is on (a simulated board's, to look at it).
    pub fn port(&self) -> &P {
        self.session.port()
    }

    /// What the board said it can do when it was opened (its period, each
    /// axis's limits and proven region).
    pub fn spec(&self) -> &Spec {
        &self.spec
    }

    /// The board's axes.
    pub fn axes(&self) -> usize {
        self.spec.axes.len()
    }

    /// The session, for what this object does not wrap.
    pub fn session(&mut self) -> &mut Session<P> {
        &mut self.session
    }

    /// The board's state machine now.
    pub fn status(&mut self) -> Result<Status, LinkError> {
        self.session.status()
    }

    /// Tell a disarmed board where each axis stands (m).
    pub fn calibrate(&mut self, position_m: &[f64]) -> Result<Status, LinkError> {
        let pm = self.per_axis(position_m, "calibrate")?;
        self.session.calibrate(pm)
    }

    /// Home a disarmed board onto its stops and wait until it has, up to
    /// `timeout`; a board that faults on the way says which fault.
    pub fn home(&mut self, timeout: Duration) -> Result<Status, LinkError> {
        self.session.home()?;
        let end = Instant::now() + timeout;
        loop {
            self.poll()?;
            let s = self.session.status()?;
            if s.faults != 0 {
                return Err(LinkError::Faulted(s.faults));
            }
            if s.mode == BoardMode::Disarmed && s.calibrated {
                return Ok(s);
            }
            if Instant::now() > end {
                return Err(LinkError::Timeout {
                    what: "homing".into(),
                    seconds: timeout.as_secs(),
                });
            }
        }
    }

    /// Arm: the coupling runs and the force comes on, ramping in.
    pub fn arm(&mut self) -> Result<Status, LinkError> {
        self.heartbeat()?;
        self.session.arm()
    }

    /// Disarm: zero force at once.
    pub fn disarm(&mut self) -> Result<Status, LinkError> {
        self.session.call(&Message::Disarm, "Disarm", |m| match m {
            Message::Status(s) if s.mode == BoardMode::Disarmed => Some(*s),
            _ => None,
        })
    }

    /// Clear latched faults (the board stays disarmed).
    pub fn clear_faults(&mut self) -> Result<Status, LinkError> {
        self.session
            .call(&Message::ClearFaults, "ClearFaults", |m| match m {
                Message::Status(s) => Some(*s),
                _ => None,
            })
    }

    /// The gains in force, one per axis.
    pub fn gains(&mut self) -> Result<Axes<Gains>, LinkError> {
        self.session
            .call(&Message::GetGains, "GetGains", |m| match m {
                Message::Gains(g) => Some(*g),
                _ => None,
            })
    }

    /// New gains, one per axis: all in force from the next tick, or none,
    /// with the first axis the board refused and why (a coupling past the
    /// proven region names the limit at its damping).
    pub fn set_gains(&mut self, gains: &[Gains]) -> Result<Axes<Gains>, LinkError> {
        let g = Axes::from_slice(gains).ok_or(LinkError::Axes {
            what: "set_gains".into(),
            given: gains.len(),
            board: self.axes(),
        })?;
        self.session.set_gains(g)
    }

    /// Stream the state every `every_ticks` ticks (0: none).
    pub fn stream(&mut self, every_ticks: u32) -> Result<(), LinkError> {
        self.session.set_stream(every_ticks)?;
        self.spec.stream_every = every_ticks;
        Ok(())
    }

    /// Read what the board has sent, without waiting long: its streamed
    /// states go into the buffer ([`take_states`](Self::take_states)), and
    /// a heartbeat goes out when one is due. Returns the states read.
    pub fn poll(&mut self) -> Result<usize, LinkError> {
        self.polls += 1;
        if self.polls >= HEARTBEAT_POLLS || self.last_heartbeat.elapsed() >= HEARTBEAT_PERIOD {
            self.heartbeat()?;
        }
        self.session.poll()?;
        let mut n = 0;
        for m in self.session.take_messages() {
            if let Message::Telemetry(t) = &m {
                let s = State::from(t);
                if self.states.len() == STATE_BUFFER {
                    self.states.pop_front();
                    self.dropped += 1;
                }
                self.states.push_back(s);
                self.latest = Some(s);
                n += 1;
            }
        }
        Ok(n)
    }

    /// The states streamed since the last call, oldest first.
    pub fn take_states(&mut self) -> Vec<State> {
        self.take_states_up_to(usize::MAX)
    }

    /// The oldest `n` states streamed (or all, if fewer), oldest first;
    /// the rest stay.
    pub fn take_states_up_to(&mut self, n: usize) -> Vec<State> {
        let n = n.min(self.states.len());
        self.states.drain(..n).collect()
    }

    /// The newest state streamed.
    pub fn latest(&self) -> Option<&State> {
        self.latest.as_ref()
    }

    /// States dropped because the application did not take them.
    pub fn dropped(&self) -> u64 {
        self.dropped
    }

    /// Run the VE on the host (disarmed only): each
    /// [`send_ve`](Self::send_ve) moves the coupling's VE point over
    /// `ramp_ticks` ticks, and an armed board that runs more than
    /// `deadline_ticks` ticks on one update faults to zero force.
    pub fn host_ve(&mut self, ramp_ticks: u32, deadline_ticks: u32) -> Result<VeSource, LinkError> {
        self.session.set_ve(VeSource::Host {
            ramp_ticks,
            deadline_ticks,
        })
    }

    /// Set one parameter of the board's own VE on `axis` (disarmed only):
    /// its surface, stiffness or damping, built from SI by
    /// [`VeParam::surface_m`] and its siblings. A value out of range is
    /// refused here, by name; a parameter the board's VE does not have, by
    /// the board (`BadVeParam`).
    pub fn set_ve_param(&mut self, axis: usize, param: VeParam) -> Result<VeParam, LinkError> {
        let what = "set_ve_param";
        if axis >= self.axes() {
            return Err(LinkError::Axes {
                what: format!("{what} (axis {axis})"),
                given: axis + 1,
                board: self.axes(),
            });
        }
        let param = param.checked().map_err(|e| LinkError::BadValue {
            what: what.into(),
            why: e.to_string(),
        })?;
        self.session.set_ve_param(axis as u8, param)
    }

    /// Give the VE back to the board's image (disarmed only).
    pub fn board_ve(&mut self) -> Result<VeSource, LinkError> {
        self.session.set_ve(VeSource::Board)
    }

    /// Send the host VE's surface for each axis (m) and what each is (a
    /// point the coupling holds, a surface solid above or below, or none);
    /// returns the update's number, which the streamed states' `ve_seq`
    /// echo once the board holds it.
    pub fn send_ve(&mut self, position_m: &[f64], contact: &[Contact]) -> Result<u32, LinkError> {
        let pm = self.per_axis(position_m, "send_ve")?;
        let contact = Axes::from_slice(contact)
            .filter(|c| c.len() == self.axes())
            .ok_or(LinkError::Axes {
                what: "send_ve (contact)".into(),
                given: contact.len(),
                board: self.axes(),
            })?;
        self.ve_seq = self.ve_seq.wrapping_add(1);
        self.session.ve_update(self.ve_seq, pm, contact)?;
        Ok(self.ve_seq)
    }

    /// Store the configuration in force in the board's flash (disarmed
    /// only).
    pub fn save(&mut self) -> Result<ConfigSource, LinkError> {
        self.session.save()
    }

    /// Disarm and let the board go.
    pub fn close(mut self) -> Result<(), LinkError> {
        self.closed = true;
        self.disarm().map(|_| ())
    }

    fn heartbeat(&mut self) -> Result<(), LinkError> {
        self.polls = 0;
        self.last_heartbeat = Instant::now();
        self.session.send(&Message::Heartbeat)
    }

    /// One value per axis in pm, or an error naming the call and both
    /// counts.
    fn per_axis(&self, m: &[f64], what: &str) -> Result<Axes<i64>, LinkError> {
        let wrong = || LinkError::Axes {
            what: what.into(),
            given: m.len(),
            board: self.axes(),
        };
        if m.len() != self.axes() {
            return Err(wrong());
        }
        let mut pm = Vec::with_capacity(m.len());
        for (axis, x) in m.iter().enumerate() {
            // (The board's range is ±2.147 m.)
            if !(x.is_finite() && x.abs() < 2.147) {
                return Err(LinkError::OutOfRange {
                    what: what.into(),
                    axis,
                    value_m: *x,
                });
            }
            pm.push((x * 1e12).round() as i64);
        }
        Axes::from_slice(&pm).ok_or_else(wrong)
    }
}

impl<P: BoardPort> Drop for HostBoard<P> {
    /// A board let go is disarmed: no force outlives its application.
    fn drop(&mut self) {
        if !self.closed {
            let _ = self.session.send(&Message::Disarm);
        }
    }
}
