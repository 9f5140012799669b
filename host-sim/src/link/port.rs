//! The transport to a board: a serial port (the firmware in QEMU through a
//! pty, or a real board), or anything else that moves the link's bytes.

use std::time::Duration;

/// The board end of the link.
pub trait BoardPort {
    /// Send bytes to the board.
    fn send(&mut self, bytes: &[u8]) -> Result<(), String>;
    /// Bytes from the board: waits up to `timeout` for at least one.
    fn recv(&mut self, buf: &mut [u8], timeout: Duration) -> Result<usize, String>;
}

/// Any port, chosen at run time (the scope's: a serial port, or a board
/// in-process).
impl BoardPort for Box<dyn BoardPort> {
    fn send(&mut self, bytes: &[u8]) -> Result<(), String> {
        (**self).send(bytes)
    }
    fn recv(&mut self, buf: &mut [u8], timeout: Duration) -> Result<usize, String> {
        (**self).recv(buf, timeout)
    }
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
