//! A board image's loop run on the PC, in a thread of its own, against a
//! device the PC drives over USB: the servo loop of the devices whose
//! firmware leaves the loop to the host (a Falcon, a Haply board, a
//! Touch). Behind the same [`BoardPort`] as a board on a wire, so an
//! application holds it as it holds any board.
//!
//! Each tick the thread does what a board's control interrupt does: one
//! exchange with the device (the duty computed last tick out, the
//! sensors in: a USB round trip puts the loop one tick late on the
//! device, as a board's is), one tick of the image's law, and the link
//! served. A device that fails an exchange stops the loop: it is sent
//! zero force with its outputs off, and the application's next read of
//! the link gets [`LinkError::Device`] naming what failed.

use crate::in_process::ByteQueues;
use crate::{BoardPort, LinkError};
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};
use twoport_board::{Board, BoardSupport, RawSensors};
use twoport_control::drive::Drive;

/// A device's I/O as the PC's loop uses it: one exchange a tick.
pub trait DeviceIo<const N: usize>: Send {
    /// Command each axis's `duty` (as a board's amplifiers take it:
    /// ±[`DUTY_FULL_SCALE`](twoport_board::DUTY_FULL_SCALE) at full-scale
    /// force), with the amplifiers' outputs `on` or off, and read the
    /// sensors. An error stops the loop; its text is what the application
    /// is told, so it names the device and what to do.
    fn exchange(&mut self, duty: [i16; N], on: bool) -> Result<RawSensors<N>, String>;
}

/// How many ticks' times the statistics are taken over (the latest).
pub const TIMING_WINDOW: usize = 4096;

/// A tick that starts this many periods after the one before is late.
pub const LATE_PERIODS: f64 = 1.5;

/// The loop's timing: the period between ticks' starts and the time of
/// each tick's device exchange, over the latest [`TIMING_WINDOW`] ticks.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LoopTiming {
    /// Ticks run.
    pub ticks: u64,
    /// Ticks that started more than [`LATE_PERIODS`] periods after the one
    /// before, since the start.
    pub late: u64,
    /// The period between ticks' starts (s): median, 99th percentile,
    /// greatest.
    pub period_s: Percentiles,
    /// The device exchange's time (s), the same three.
    pub io_s: Percentiles,
    /// The latency from a sample to its force (s), the same three: from
    /// the start of the exchange that read a tick's sensors to the end of
    /// the one that wrote the force computed from them, the next tick's.
    /// The device sampled no earlier and applied no later, so this bounds
    /// what the proof must allow (a whole tick and the part of one past
    /// it: `twoport spec`'s latency).
    pub latency_s: Percentiles,
}

/// A sample's median, 99th percentile and greatest value.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Percentiles {
    /// The median.
    pub p50: f64,
    /// The 99th percentile.
    pub p99: f64,
    /// The greatest.
    pub max: f64,
}

impl Percentiles {
    fn of(ring: &[f64]) -> Self {
        if ring.is_empty() {
            return Percentiles::default();
        }
        let mut v = ring.to_vec();
        v.sort_by(f64::total_cmp);
        let at = |q: f64| v[((v.len() - 1) as f64 * q).round() as usize];
        Percentiles {
            p50: at(0.5),
            p99: at(0.99),
            max: v[v.len() - 1],
        }
    }
}

/// The priority the loop's thread runs at.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Priority {
    /// Real-time (first-in first-out, the highest the system gives): no
    /// ordinary thread delays a tick.
    RealTime,
    /// The system's normal priority, and why no higher: other work on the
    /// machine may delay a tick (see [`LoopTiming::late`]).
    Normal(String),
    /// The device's library runs the loop in its own thread, at the
    /// priority it sets (what it is, and what it says of it).
    Library(String),
}

/// Raise the calling thread to real-time priority where the system allows
/// it, and say what it got.
fn raise_priority() -> Priority {
    use thread_priority::*;
    #[cfg(unix)]
    let raised = set_thread_priority_and_policy(
        thread_native_id(),
        ThreadPriority::Max,
        ThreadSchedulePolicy::Realtime(RealtimeThreadSchedulePolicy::Fifo),
    );
    #[cfg(not(unix))]
    let raised = set_current_thread_priority(ThreadPriority::Max);
    match raised {
        Ok(()) => Priority::RealTime,
        Err(e) => Priority::Normal(format!(
            "the system refused real-time scheduling ({e:?}): on Linux allow it \
             with a line `@YOURGROUP - rtprio 99` in /etc/security/limits.conf \
             (then log in again), or give the program CAP_SYS_NICE"
        )),
    }
}

/// What the loop and the application share.
#[derive(Default)]
struct Shared {
    /// The loop thread's priority, once it has asked for one.
    priority: Option<Priority>,
    link: ByteQueues,
    periods: Vec<f64>,
    ios: Vec<f64>,
    latencies: Vec<f64>,
    ticks: u64,
    late: u64,
    /// Why the loop stopped, once it has.
    failed: Option<String>,
    stop: bool,
    /// The loop has sent its last zero force and runs no more ticks.
    ended: bool,
    /// When the latest tick ran (the loop's start, before the first).
    last_tick: Option<Instant>,
    /// Sets of gains the board accepted outside its proven region, and
    /// how many of them have been logged.
    unproven_sets: u32,
    unproven_logged: u32,
}

impl Shared {
    /// The application's bytes for the board, unless the loop has stopped.
    fn send(&mut self, bytes: &[u8]) -> Result<(), LinkError> {
        if let Some(e) = &self.failed {
            return Err(LinkError::Device(e.clone()));
        }
        self.link.send(bytes);
        Ok(())
    }
}

/// The board support the image's loop runs against on the PC: the device
/// through [`DeviceIo`], the link through the shared queues.
struct PcSupport<Io, const N: usize> {
    io: Io,
    shared: Arc<(Mutex<Shared>, Condvar)>,
    duty: [i16; N],
    on: bool,
    last: RawSensors<N>,
    failed: Option<String>,
    io_s: f64,
    /// When the last exchange began, and the latency its sensors' force
    /// had by the end of this one (none before the second).
    exchanged: Option<Instant>,
    latency: Option<Duration>,
    start: Instant,
    period_ns: u32,
}

impl<Io, const N: usize> PcSupport<Io, N> {
    /// `io`, nothing exchanged yet, its tick `period_ns` long.
    fn new(io: Io, period_ns: u32) -> Self {
        PcSupport {
            io,
            shared: Arc::new((Mutex::new(Shared::default()), Condvar::new())),
            duty: [0; N],
            on: false,
            last: RawSensors::default(),
            failed: None,
            io_s: 0.0,
            exchanged: None,
            latency: None,
            start: Instant::now(),
            period_ns,
        }
    }

    fn shared(&self) -> MutexGuard<'_, Shared> {
        lock(&self.shared.0)
    }
}

/// The lock, whoever held it last: the shared state stays consistent
/// through a panic, as every write to it is one assignment.
fn lock(m: &Mutex<Shared>) -> MutexGuard<'_, Shared> {
    m.lock().unwrap_or_else(|p| p.into_inner())
}

impl<Io: DeviceIo<N>, const N: usize> BoardSupport<N> for PcSupport<Io, N> {
    fn sample(&mut self) -> RawSensors<N> {
        let t = Instant::now();
        match self.io.exchange(self.duty, self.on) {
            Ok(raw) => self.last = raw,
            Err(e) => {
                // The hand is taken off: the loop commands no force on
                // this tick, and stops after it.
                self.failed.get_or_insert(e);
                self.last.dead_man_closed = false;
            }
        }
        self.io_s = t.elapsed().as_secs_f64();
        if let Some(before) = self.exchanged.replace(t) {
            self.latency = Some(before.elapsed());
        }
        self.last
    }
    fn set_duty(&mut self, duty: [i16; N]) {
        self.duty = duty;
    }
    fn set_outputs(&mut self, on: bool) {
        self.on = on;
    }
    fn feed_watchdog(&mut self) {}
    fn read_byte(&mut self) -> Option<u8> {
        self.shared().link.host_byte()
    }
    fn write(&mut self, bytes: &[u8]) {
        let (m, c) = &*self.shared;
        lock(m).link.board_write(bytes);
        c.notify_all();
    }
    fn cycles(&mut self) -> u32 {
        // Nanoseconds, wrapping every 4.3 s: the board's timing takes
        // differences within a tick.
        self.start.elapsed().as_nanos() as u32
    }
    fn cycles_per_tick(&self) -> u32 {
        self.period_ns
    }
    fn force_latency(&self) -> Option<u32> {
        // The force the device took at this exchange was computed from
        // the last exchange's sensors.
        self.latency
            .map(|l| u32::try_from(l.as_nanos()).unwrap_or(u32::MAX))
    }
}

/// `board`, accepting gains outside its proven region where the user
/// chose so (`why`), the choice logged for the device at `path`.
pub fn accept_unproven_gains<D: Drive<N>, const N: usize, const R: usize>(
    board: Board<D, R, N>,
    why: Option<&str>,
    path: &str,
) -> Board<D, R, N> {
    match why {
        Some(why) => {
            eprintln!(
                "twoport: {path}: gains outside the proven region will be accepted, by the \
                 user's choice ({why}): stability is not proven for them"
            );
            board.accepting_unproven_gains()
        }
        None => board,
    }
}

/// What runs the loop's ticks, once a period: a thread of the loop's own
/// ([`PcBoard::start`]), or a device library's scheduler (the Touch's
/// OpenHaptics). Dropping it stops the calls.
pub trait Ticker: Send + 'static {
    /// Call `tick` once every `period_s` (s) until it returns `false`;
    /// say at what priority the calls run.
    fn start(
        &mut self,
        period_s: f64,
        tick: Box<dyn FnMut() -> bool + Send>,
    ) -> Result<Priority, String>;
}

/// A thread of the loop's own, at real-time priority where the system
/// allows it, sleeping to each tick's start.
#[derive(Default)]
pub struct LoopThread {
    thread: Option<JoinHandle<()>>,
}

impl Ticker for LoopThread {
    fn start(
        &mut self,
        period_s: f64,
        mut tick: Box<dyn FnMut() -> bool + Send>,
    ) -> Result<Priority, String> {
        let period = Duration::from_secs_f64(period_s);
        let (tx, rx) = std::sync::mpsc::channel();
        let thread = std::thread::Builder::new()
            .name("twoport-pc-loop".into())
            .spawn(move || {
                let _ = tx.send(raise_priority());
                let mut next = Instant::now();
                loop {
                    let now = Instant::now();
                    if next > now {
                        std::thread::sleep(next - now);
                    }
                    let start = Instant::now();
                    // (Behind by more than a period, the loop keeps its
                    // phase from now rather than run the missed ticks
                    // back to back.)
                    next = if start > next + period { start } else { next } + period;
                    if !tick() {
                        break;
                    }
                }
            })
            .map_err(|e| format!("the loop's thread would not start: {e}"))?;
        self.thread = Some(thread);
        rx.recv()
            .map_err(|_| "the loop's thread ended before its first tick".to_string())
    }
}

impl Drop for LoopThread {
    fn drop(&mut self) {
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// A board image's loop on the PC against the device `Io`: the image's
/// board `Board<D, R, N>` ticking every period.
pub struct PcBoard {
    shared: Arc<(Mutex<Shared>, Condvar)>,
    ticker: Option<Box<dyn Ticker>>,
}

/// How long dropping a [`PcBoard`] waits for its loop's last tick (s).
const END_WAIT: Duration = Duration::from_secs(1);

/// A loop that has run no tick for this long has stopped: its ticker (a
/// device library's scheduler) no longer calls it.
pub const STALL: Duration = Duration::from_millis(500);

impl PcBoard {
    /// Start `board` ticking every `period_s` (s) against `io`, its
    /// ticks run by `ticker`: a thread of its own ([`LoopThread`]) or a
    /// device library's scheduler.
    ///
    /// The force a tick computes reaches the device at the next tick's
    /// exchange, so the latency is a period and more: `board`'s regions
    /// must be proven for it (the Excalibur's for the PC are
    /// `excalibur::pc`'s, for up to 5 ms). A force later than they allow
    /// faults the board to zero force ("force late"), unless a passivity
    /// layer guards its port, as on every image for the PC's loop.
    pub fn start<Io, D, const N: usize, const R: usize>(
        board: Board<D, R, N>,
        io: Io,
        period_s: f64,
        mut ticker: impl Ticker,
    ) -> Result<Self, LinkError>
    where
        Io: DeviceIo<N> + 'static,
        D: Drive<N> + Send + 'static,
    {
        if !(period_s.is_finite() && period_s > 1e-6 && period_s < 1.0) {
            return Err(LinkError::Device(format!(
                "period_s {period_s}: the loop's period must be between 1 µs and 1 s"
            )));
        }
        let support = PcSupport::new(io, (period_s * 1e9).round() as u32);
        let shared = Arc::clone(&support.shared);
        // The loop's count is nanoseconds: the board holds the latency it
        // measures in them to what its regions are proven for.
        let mut looped = Looped {
            board: board.with_count_rate(1_000_000_000),
            support,
            period_s,
            last_start: None,
            slot: 0,
        };
        let priority = ticker
            .start(period_s, Box::new(move || looped.tick()))
            .map_err(LinkError::Device)?;
        {
            let mut s = lock(&shared.0);
            s.priority = Some(priority);
            s.last_tick.get_or_insert_with(Instant::now);
        }
        Ok(PcBoard {
            shared,
            ticker: Some(Box::new(ticker)),
        })
    }

    /// The loop's timing so far.
    pub fn timing(&self) -> LoopTiming {
        let s = lock(&self.shared.0);
        LoopTiming {
            ticks: s.ticks,
            late: s.late,
            period_s: Percentiles::of(&s.periods),
            io_s: Percentiles::of(&s.ios),
            latency_s: Percentiles::of(&s.latencies),
        }
    }

    /// Why the loop stopped, once a device exchange has failed.
    pub fn failure(&self) -> Option<String> {
        lock(&self.shared.0).failed.clone()
    }

    /// The priority the loop's ticks run at.
    pub fn priority(&self) -> Priority {
        lock(&self.shared.0)
            .priority
            .clone()
            .unwrap_or(Priority::Normal("not started".into()))
    }
}

/// The loop: the image's board against the device, one tick a call.
struct Looped<Io, D, const N: usize, const R: usize> {
    board: Board<D, R, N>,
    support: PcSupport<Io, N>,
    period_s: f64,
    last_start: Option<Instant>,
    slot: usize,
}

impl<Io: DeviceIo<N>, D: Drive<N>, const N: usize, const R: usize> Looped<Io, D, N, R> {
    /// One tick, its timing recorded; `false` once told to stop or the
    /// device has failed, after zero force with the outputs off.
    fn tick(&mut self) -> bool {
        let start = Instant::now();
        let io = &mut self.support;
        self.board.poll_link(io);
        self.board.control_tick(io);
        self.board.flush(io);
        let failed = io.failed.take();
        let (m, c) = &*io.shared;
        let mut s = lock(m);
        let since = self
            .last_start
            .replace(start)
            .map(|l| start.duration_since(l).as_secs_f64());
        s.ticks += 1;
        s.last_tick = Some(start);
        s.unproven_sets = self.board.unproven_sets();
        if let Some(p) = since {
            s.late += u64::from(p > LATE_PERIODS * self.period_s);
            record(&mut s.periods, self.slot, p);
        }
        record(&mut s.ios, self.slot, io.io_s);
        if let Some(l) = io.latency {
            record(&mut s.latencies, self.slot, l.as_secs_f64());
        }
        self.slot = (self.slot + 1) % TIMING_WINDOW;
        if let Some(e) = failed {
            s.failed = Some(e);
        }
        let stop = s.stop || s.failed.is_some();
        drop(s);
        if stop {
            // Zero force, outputs off, whatever the device says to it now.
            let _ = io.io.exchange([0; N], false);
            lock(m).ended = true;
        }
        c.notify_all();
        !stop
    }
}

/// Put `v` in the ring at `slot`, growing it to its window first.
fn record(ring: &mut Vec<f64>, slot: usize, v: f64) {
    if ring.len() < TIMING_WINDOW {
        ring.push(v);
    } else {
        ring[slot] = v;
    }
}

/// A board image's loop on the PC stepped by its caller, with no thread
/// and no clock: each read of the link that finds nothing runs one tick
/// (one exchange with the device). Its count's rate is not set, so the
/// latency gate is off: what it shows is the image, the driver and the
/// device, tick by tick, whatever the machine's load. For tests and
/// studies of a driver; a device is run by [`PcBoard`].
pub struct SteppedPc<Io, D, const N: usize, const R: usize> {
    looped: Looped<Io, D, N, R>,
}

impl<Io: DeviceIo<N>, D: Drive<N>, const N: usize, const R: usize> SteppedPc<Io, D, N, R> {
    /// `board` against `io`, stepped by reads of its link.
    pub fn new(board: Board<D, R, N>, io: Io) -> Self {
        SteppedPc {
            looped: Looped {
                board,
                support: PcSupport::new(io, 1),
                // (No period: no tick is late.)
                period_s: f64::INFINITY,
                last_start: None,
                slot: 0,
            },
        }
    }
}

impl<Io: DeviceIo<N>, D: Drive<N>, const N: usize, const R: usize> BoardPort
    for SteppedPc<Io, D, N, R>
{
    fn send(&mut self, bytes: &[u8]) -> Result<(), LinkError> {
        self.looped.support.shared().send(bytes)
    }

    fn recv(&mut self, buf: &mut [u8], _: Duration) -> Result<usize, LinkError> {
        {
            let mut s = self.looped.support.shared();
            let n = s.link.take(buf);
            if n > 0 {
                return Ok(n);
            }
            if let Some(e) = &s.failed {
                return Err(LinkError::Device(e.clone()));
            }
        }
        // One tick of the loop a thread would run: a failing device is
        // sent zero force with its outputs off, and the next read says why.
        self.looped.tick();
        Ok(self.looped.support.shared().link.take(buf))
    }
}

impl BoardPort for PcBoard {
    fn send(&mut self, bytes: &[u8]) -> Result<(), LinkError> {
        lock(&self.shared.0).send(bytes)
    }

    fn recv(&mut self, buf: &mut [u8], timeout: Duration) -> Result<usize, LinkError> {
        let (m, c) = &*self.shared;
        let deadline = Instant::now() + timeout;
        let mut s = lock(m);
        if s.unproven_sets > s.unproven_logged {
            s.unproven_logged = s.unproven_sets;
            eprintln!(
                "twoport: gains outside the proven region set ({} so far), by the user's \
                 choice: stability is not proven for them",
                s.unproven_sets
            );
        }
        loop {
            let n = s.link.take(buf);
            if n > 0 {
                return Ok(n);
            }
            if let Some(e) = &s.failed {
                return Err(LinkError::Device(e.clone()));
            }
            let now = Instant::now();
            if let Some(idle) = s.last_tick.map(|t| now.saturating_duration_since(t)) {
                if idle > STALL && !s.ended {
                    let e = format!(
                        "the loop has run no tick for {:.1} s: what runs it ({}) has stopped \
                         calling it, so the device has stopped answering or the machine has \
                         stalled; reopen the device",
                        idle.as_secs_f64(),
                        match &s.priority {
                            Some(Priority::Library(_)) => "the device library's scheduler",
                            _ => "the loop's thread",
                        }
                    );
                    s.failed = Some(e.clone());
                    return Err(LinkError::Device(e));
                }
            }
            if now >= deadline {
                return Ok(0);
            }
            s = c
                .wait_timeout(s, deadline - now)
                .map(|(g, _)| g)
                .unwrap_or_else(|p| p.into_inner().0);
        }
    }
    fn loop_timing(&self) -> Option<LoopTiming> {
        Some(self.timing())
    }
}

impl Drop for PcBoard {
    /// Stop the loop: its last act is zero force with the outputs off.
    fn drop(&mut self) {
        let (m, c) = &*self.shared;
        let deadline = Instant::now() + END_WAIT;
        let mut s = lock(m);
        s.stop = true;
        // (A ticker that has stopped calling leaves nothing to wait for.)
        while !s.ended && Instant::now() < deadline {
            s = c
                .wait_timeout(s, deadline - Instant::now())
                .map(|(g, _)| g)
                .unwrap_or_else(|p| p.into_inner().0);
        }
        drop(s);
        self.ticker.take();
    }
}
