//! The Excalibur board image on a simulated device, in this process and
//! running free, behind the same [`BoardPort`] as a serial board: what a
//! host application is tried on without hardware or an emulator, and
//! what the device object's tests drive.

use crate::in_process::ByteQueues;
use crate::{BoardPort, DeviceIo, LinkError, LoopThread, PcBoard};
use std::time::{Duration, Instant};
use twoport_board::excalibur::{self, REGION_POINTS};
use twoport_board::{Board, BoardSupport, IoScale, RawSensors, SimAxis, Simulated};
use twoport_control::ve::UnilateralWall;
use twoport_control::Servo;

/// How a simulated board's ticks keep time.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pace {
    /// This many ticks each time the host reads: the same run for the same
    /// calls, whatever the machine (tests).
    PerRead(u32),
    /// As many ticks as the wall clock has run periods since the last
    /// read, at most a second's worth (trying an application).
    RealTime,
}

/// The shipped Excalibur image (its wall, its proven region, its safety
/// layer) running on one simulated axis: the actuator's 0.93 kg with
/// 4 N s/m, a hand pushing with a constant force, a 1 µm encoder.
pub struct SimulatedBoard {
    board: Board<Servo<UnilateralWall>, REGION_POINTS>,
    io: Simulated<ByteQueues, 1>,
    pace: Pace,
    last: Option<Instant>,
    ticks: u64,
}

impl SimulatedBoard {
    /// The image on a device the hand pushes along +x with `hand_n` (N),
    /// ticking at `pace`.
    pub fn excalibur(hand_n: f32, pace: Pace) -> Result<Self, LinkError> {
        let board = excalibur::stiff_wall_board()
            .map_err(|e| LinkError::Image(format!("the Excalibur board image: {e:?}")))?;
        let io = Simulated::new(
            ByteQueues::default(),
            [SimAxis::excalibur(hand_n)],
            [IoScale::EXCALIBUR],
            excalibur::ENCODER,
            excalibur::PERIOD_S,
        );
        let mut b = SimulatedBoard {
            board,
            io,
            pace,
            last: None,
            ticks: 0,
        };
        // A board ticks from boot: its first tick has read the dead-man
        // switch before any host can ask it to arm.
        b.run(1);
        Ok(b)
    }

    /// Where the simulated handle is (m).
    pub fn position_m(&self) -> f32 {
        self.io.position_m()[0]
    }

    /// Ticks run since boot.
    pub fn ticks(&self) -> u64 {
        self.ticks
    }

    /// Run `n` control ticks, serving the link between them as a board's
    /// main loop does.
    pub fn run(&mut self, n: u32) {
        for _ in 0..n {
            self.board.poll_link(&mut self.io);
            self.board.control_tick(&mut self.io);
            self.board.flush(&mut self.io);
            self.ticks += 1;
        }
    }
}

impl BoardPort for SimulatedBoard {
    fn send(&mut self, bytes: &[u8]) -> Result<(), LinkError> {
        self.io.inner().send(bytes);
        Ok(())
    }

    fn recv(&mut self, buf: &mut [u8], _timeout: Duration) -> Result<usize, LinkError> {
        let n = match self.pace {
            Pace::PerRead(n) => n,
            Pace::RealTime => {
                let now = Instant::now();
                let period = Duration::from_secs_f32(excalibur::PERIOD_S);
                let since = *self.last.get_or_insert(now);
                let due = (now.duration_since(since).as_secs_f64() / period.as_secs_f64()) as u64;
                // (Behind by more than a second, the board starts afresh
                // from now rather than race.)
                let n = due.min(1000) as u32;
                self.last = Some(if due > 1000 { now } else { since + period * n });
                n
            }
        };
        self.run(n);
        // (The board answers what it has already read even with no tick.)
        self.board.poll_link(&mut self.io);
        self.board.flush(&mut self.io);
        Ok(self.io.inner().take(buf))
    }
}

/// A simulated device for the PC's loop ([`PcBoard`](crate::PcBoard)):
/// the same simulated axes a [`SimulatedBoard`] runs on, exchanged with
/// over [`DeviceIo`] as a USB device is. Each exchange advances it one
/// period under the duty the loop sent.
pub struct SimulatedDevice<const N: usize = 1> {
    sim: Simulated<ByteQueues, N>,
}

impl SimulatedDevice {
    /// One Excalibur axis ([`SimAxis::excalibur`]) that the hand pushes
    /// along +x with `hand_n` (N), read and driven as the Excalibur image
    /// expects.
    pub fn excalibur(hand_n: f32) -> Self {
        SimulatedDevice {
            sim: Simulated::new(
                ByteQueues::default(),
                [SimAxis::excalibur(hand_n)],
                [IoScale::EXCALIBUR],
                excalibur::ENCODER,
                excalibur::PERIOD_S,
            ),
        }
    }
}

impl<const N: usize> DeviceIo<N> for SimulatedDevice<N> {
    fn exchange(&mut self, duty: [i16; N], on: bool) -> Result<RawSensors<N>, String> {
        self.sim.set_outputs(on);
        self.sim.set_duty(duty);
        Ok(self.sim.sample())
    }
}

impl PcBoard {
    /// The Excalibur's image for the PC (`excalibur::pc`: its region
    /// proven for up to 5 ms from sample to force) on the PC's loop at
    /// 1 kHz, against [`SimulatedDevice::excalibur`] with the hand pushing
    /// `hand_n` (N): the PC's loop tried without a device.
    pub fn excalibur_simulated(hand_n: f32) -> Result<Self, LinkError> {
        let board = excalibur::pc::board()
            .map_err(|e| LinkError::Image(format!("the Excalibur board image: {e:?}")))?;
        PcBoard::start(
            board,
            SimulatedDevice::excalibur(hand_n),
            f64::from(excalibur::PERIOD_S),
            LoopThread::default(),
        )
    }
}
