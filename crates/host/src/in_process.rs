//! The link of a board image run in this process: two byte queues, and
//! no other peripheral. Every in-process board stands on it: the lockstep
//! [`LocalBoard`](crate::LocalBoard), the free-running
//! [`SimulatedBoard`](crate::SimulatedBoard), and the PC's loop
//! [`PcBoard`](crate::PcBoard).

use std::collections::VecDeque;
use twoport_board::{BoardSupport, RawSensors};

/// The bytes the host sent and the board has not read, and the bytes the
/// board wrote and the host has not taken.
#[derive(Default)]
pub(crate) struct ByteQueues {
    rx: VecDeque<u8>,
    out: Vec<u8>,
}

impl ByteQueues {
    /// The host sends `bytes`.
    pub(crate) fn send(&mut self, bytes: &[u8]) {
        self.rx.extend(bytes);
    }

    /// Whether the board has read everything sent.
    pub(crate) fn drained(&self) -> bool {
        self.rx.is_empty()
    }

    /// The board reads a byte the host sent.
    pub(crate) fn host_byte(&mut self) -> Option<u8> {
        self.rx.pop_front()
    }

    /// The board writes `bytes` for the host.
    pub(crate) fn board_write(&mut self, bytes: &[u8]) {
        self.out.extend_from_slice(bytes);
    }

    /// The host takes what fits in `buf` of what the board wrote.
    pub(crate) fn take(&mut self, buf: &mut [u8]) -> usize {
        let n = buf.len().min(self.out.len());
        buf[..n].copy_from_slice(&self.out[..n]);
        self.out.drain(..n);
        n
    }
}

impl<const N: usize> BoardSupport<N> for ByteQueues {
    // What sensors there are are read in front of it (a simulated
    // device), or come in the host's frames (processor in the loop).
    fn sample(&mut self) -> RawSensors<N> {
        RawSensors::default()
    }
    // The duties go back in the board's frames, or to the simulated device.
    fn set_duty(&mut self, _: [i16; N]) {}
    // So do the outputs: a disarmed board answers zero duty.
    fn set_outputs(&mut self, _: bool) {}
    // A loop in this process cannot hang unseen: no watchdog.
    fn feed_watchdog(&mut self) {}
    // The host paces the ticks.
    fn cycles_per_tick(&self) -> u32 {
        0
    }
    fn cycles(&mut self) -> u32 {
        0
    }
    fn read_byte(&mut self) -> Option<u8> {
        self.host_byte()
    }
    fn write(&mut self, bytes: &[u8]) {
        self.board_write(bytes);
    }
}
