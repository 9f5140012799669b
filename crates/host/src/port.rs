//! The transport to a board: a serial port (the firmware in QEMU through a
//! pty, or a real board), or anything else that moves the link's bytes.

use crate::LinkError;
use std::time::Duration;

/// The board end of the link.
pub trait BoardPort {
    /// Send bytes to the board.
    fn send(&mut self, bytes: &[u8]) -> Result<(), LinkError>;
    /// Bytes from the board: waits up to `timeout` for at least one.
    fn recv(&mut self, buf: &mut [u8], timeout: Duration) -> Result<usize, LinkError>;
    /// The servo loop's timing, where it runs on this computer
    /// ([`PcBoard`](crate::PcBoard)); `None` where a board runs it.
    fn loop_timing(&self) -> Option<crate::LoopTiming> {
        None
    }
}

/// Any port behind a box: one chosen at run time (the scope's, a serial
/// port or a board in-process; the C ABI's and the Python package's, which
/// may move to another thread).
impl<P: BoardPort + ?Sized> BoardPort for Box<P> {
    fn send(&mut self, bytes: &[u8]) -> Result<(), LinkError> {
        (**self).send(bytes)
    }
    fn recv(&mut self, buf: &mut [u8], timeout: Duration) -> Result<usize, LinkError> {
        (**self).recv(buf, timeout)
    }
    fn loop_timing(&self) -> Option<crate::LoopTiming> {
        (**self).loop_timing()
    }
}

/// A serial port: the firmware in QEMU (`-serial pty`) or a real board.
pub struct SerialBoard(Box<dyn serialport::SerialPort>);

impl SerialBoard {
    /// Open `path` (115200 8N1; a pty ignores the rate).
    pub fn open(path: &str) -> Result<Self, LinkError> {
        let port = serialport::new(path, 115_200)
            .timeout(Duration::from_millis(20))
            .open()
            .map_err(|e| LinkError::Open {
                path: path.to_string(),
                why: e.to_string(),
            })?;
        // What the board sent before this host opened the port was for
        // another host.
        let _ = port.clear(serialport::ClearBuffer::All);
        Ok(SerialBoard(port))
    }
}

/// How long a write may wait for the port to take its bytes: a board that
/// has not drained its link in this time is not reading it.
pub const WRITE_TIMEOUT: Duration = Duration::from_millis(500);

impl BoardPort for SerialBoard {
    fn send(&mut self, bytes: &[u8]) -> Result<(), LinkError> {
        // (A read leaves its own, shorter, timeout on the port: a full
        // buffer must not fail a write that waits a millisecond more.)
        let _ = self.0.set_timeout(WRITE_TIMEOUT);
        std::io::Write::write_all(&mut self.0, bytes)
            .map_err(|e| LinkError::Transport(format!("write: {e}")))
    }
    fn recv(&mut self, buf: &mut [u8], timeout: Duration) -> Result<usize, LinkError> {
        let _ = self.0.set_timeout(timeout);
        match std::io::Read::read(&mut self.0, buf) {
            Ok(n) => Ok(n),
            Err(e) if e.kind() == std::io::ErrorKind::TimedOut => Ok(0),
            Err(e) => Err(LinkError::Transport(format!("read: {e}"))),
        }
    }
}
