//! The serial port of a device the PC drives: whole packets out and in,
//! and every way that fails, named with what to do. The drivers (the
//! Haply 2DIY's, the Falcon's) stand on it.

use crate::LinkError;
use std::io::{ErrorKind, Read, Write};
use std::time::Duration;

/// How long a reply may take before the device counts as silent: ten of
/// the loop's ticks, far past a USB frame.
pub const REPLY_TIMEOUT: Duration = Duration::from_millis(10);

/// Where a device's dead-man switch comes from. The PC images' regions
/// are proven for a hand that grasps the handle; hands off, force is off.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Grip {
    /// A switch wired to analog pin `pin` (a Haply board's), closed while
    /// its reading is above `closed_above` (the board's units).
    Pin {
        /// The analog pin.
        pin: u8,
        /// The reading above which the switch is closed.
        closed_above: f32,
    },
    /// The device's own grip buttons (a Falcon's): closed while any button
    /// in `mask` is held.
    Button {
        /// The buttons, a bit each.
        mask: u8,
    },
    /// No switch: the hand is taken to be on the handle whenever the loop
    /// is armed. The user's explicit choice: opening says so.
    Assumed,
}

impl Grip {
    /// Whether the hand is on the handle, given the device's analog
    /// readings by pin and its buttons held (a bit each).
    pub fn closed(&self, reading: impl Fn(u8) -> Option<f32>, buttons: u8) -> bool {
        match *self {
            Grip::Pin { pin, closed_above } => reading(pin).is_some_and(|v| v > closed_above),
            Grip::Button { mask } => buttons & mask != 0,
            Grip::Assumed => true,
        }
    }

    /// Refuse a switch the device `name` has no way to read (it has analog
    /// pins where `pins`, buttons where `buttons`); say, once, that the
    /// grip is assumed.
    pub fn check(
        &self,
        path: &str,
        name: &str,
        pins: bool,
        buttons: bool,
    ) -> Result<(), LinkError> {
        let refuse = |why: String| {
            Err(LinkError::Open {
                path: path.to_string(),
                why,
            })
        };
        match self {
            Grip::Pin { .. } if !pins => refuse(format!(
                "the {name} has no analog pins: use its grip buttons (Grip::Button)"
            )),
            Grip::Button { .. } if !buttons => refuse(format!(
                "the {name} has no buttons: wire a switch to an analog pin (Grip::Pin)"
            )),
            Grip::Assumed => {
                eprintln!(
                    "twoport: {path}: the {name}'s grip is assumed (Grip::Assumed): force is \
                     on whenever the loop is armed, hands on the handle or not; its region is \
                     proven only for a grasp of at least 2 N s/m"
                );
                Ok(())
            }
            _ => Ok(()),
        }
    }
}

/// A device's open serial port.
pub struct DevicePort {
    port: Box<dyn serialport::SerialPort>,
    /// The device's name, for the messages.
    name: &'static str,
    timeout: Duration,
}

impl DevicePort {
    /// Open `path` at `baud` for the device `name` (in messages), in the
    /// port's exclusive mode under an advisory lock: a second program on
    /// it is refused.
    pub fn open(path: &str, baud: u32, name: &'static str) -> Result<Self, LinkError> {
        let port = serialport::new(path, baud)
            .timeout(REPLY_TIMEOUT)
            .open()
            .map_err(|e| {
                let there = std::path::Path::new(path).exists();
                let kind = match e.kind {
                    serialport::ErrorKind::NoDevice if !there => ErrorKind::NotFound,
                    serialport::ErrorKind::NoDevice if e.description.contains("lock") => {
                        ErrorKind::ResourceBusy
                    }
                    serialport::ErrorKind::Io(k) => k,
                    _ => ErrorKind::Other,
                };
                match kind {
                    ErrorKind::Other => LinkError::Open {
                        path: path.to_string(),
                        why: e.to_string(),
                    },
                    k => open_error(path, k, name),
                }
            })?;
        // What the device sent before this program opened the port is
        // stale.
        let _ = port.clear(serialport::ClearBuffer::All);
        Ok(DevicePort {
            port,
            name,
            timeout: REPLY_TIMEOUT,
        })
    }

    /// The port, for what only its device needs (rates, modem lines).
    pub fn port_mut(&mut self) -> &mut dyn serialport::SerialPort {
        &mut *self.port
    }

    /// Wait up to `timeout` for each read from now on (a slow link's
    /// handshake); [`REPLY_TIMEOUT`] at open.
    pub fn set_timeout(&mut self, timeout: Duration) -> Result<(), String> {
        self.timeout = timeout;
        self.port
            .set_timeout(timeout)
            .map_err(|e| format!("the {}'s port: {e}", self.name))
    }

    /// Send `bytes`, all of them.
    pub fn send(&mut self, bytes: &[u8]) -> Result<(), String> {
        self.port.write_all(bytes).map_err(|e| self.failed(&e))
    }

    /// Fill `buf` from the device, waiting up to the timeout
    /// ([`REPLY_TIMEOUT`] unless set) for each read.
    pub fn receive(&mut self, buf: &mut [u8]) -> Result<(), String> {
        let need = buf.len();
        let mut got = 0;
        while got < need {
            match self.port.read(&mut buf[got..]) {
                Ok(0) => return Err(self.unplugged()),
                Ok(n) => got += n,
                Err(e) if e.kind() == ErrorKind::Interrupted => {}
                Err(e) if e.kind() == ErrorKind::TimedOut || e.kind() == ErrorKind::WouldBlock => {
                    let name = self.name;
                    return Err(if got == 0 {
                        format!(
                            "the {name} stopped answering: no reply within {} ms; check its \
                             USB cable and power, then open it again",
                            self.timeout.as_millis()
                        )
                    } else {
                        format!(
                            "the {name}'s reply was cut short: {got} of its {need} bytes; its \
                             USB link is failing, or another program is reading the port"
                        )
                    });
                }
                Err(e) => return Err(self.failed(&e)),
            }
        }
        Ok(())
    }

    fn unplugged(&self) -> String {
        format!(
            "the {}'s port closed: the device was unplugged or lost power; plug it in and \
             open it again",
            self.name
        )
    }

    fn failed(&self, e: &std::io::Error) -> String {
        // (EIO or a broken pipe: the USB device went away under the open
        // port.)
        if e.raw_os_error() == Some(5) || e.kind() == ErrorKind::BrokenPipe {
            self.unplugged()
        } else {
            format!("the {}'s port failed: {e}", self.name)
        }
    }
}

/// Why `path` would not open for the device `name`, and what to do.
pub fn open_error(path: &str, kind: ErrorKind, name: &str) -> LinkError {
    let why = match kind {
        ErrorKind::NotFound => format!(
            "no such port; is the {name} plugged in? `twoport devices` lists the serial \
             ports this computer has"
        ),
        ErrorKind::PermissionDenied => format!(
            "permission denied on the {name}'s port; on Linux add yourself to the port's \
             group (`sudo usermod -aG dialout $USER`, then log in again), or install \
             twoport's udev rule (udev/60-twoport.rules, docs/devices.md)"
        ),
        ErrorKind::ResourceBusy | ErrorKind::WouldBlock => format!(
            "the {name}'s port is held by another program (its maker's software, a \
             sketch, another twoport); close it and open the port again"
        ),
        _ => format!("the {name}'s port: {kind}"),
    };
    LinkError::Open {
        path: path.to_string(),
        why,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each switch reads what it is wired to; a switch the device cannot
    /// read is refused at open, by name.
    #[test]
    fn a_grip_reads_its_own_switch_and_no_other() {
        let pin = Grip::Pin {
            pin: 2,
            closed_above: 0.5,
        };
        let reading = |p| (p == 2).then_some(0.7);
        assert!(pin.closed(reading, 0));
        assert!(!pin.closed(|_| Some(0.3), 0xff));
        assert!(!pin.closed(|_| None, 0xff));
        let button = Grip::Button { mask: 0b0010 };
        assert!(button.closed(|_| Some(1.0), 0b0010));
        assert!(!button.closed(|_| Some(1.0), 0b0001));
        assert!(Grip::Assumed.closed(|_| None, 0));
        let e = button.check("/dev/x", "2DIY", true, false).unwrap_err();
        assert!(e.to_string().contains("the 2DIY has no buttons"), "{e}");
        let e = pin.check("/dev/x", "Falcon", false, true).unwrap_err();
        assert!(
            e.to_string().contains("the Falcon has no analog pins"),
            "{e}"
        );
        assert!(pin.check("/dev/x", "2DIY", true, false).is_ok());
    }
}
