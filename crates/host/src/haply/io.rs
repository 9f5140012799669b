//! The 2DIY over its serial port: one torque packet out and one reply in
//! a tick, as the PC's loop asks through [`DeviceIo`].

use super::protocol::{PacketError, Setup};
use crate::DeviceIo;
use std::io::{ErrorKind, Read, Write};
use std::time::Duration;
use twoport_board::IoScale;
use twoport_board::RawSensors;

/// How long a reply may take before the board counts as silent: ten of
/// the loop's ticks, far past a USB frame.
pub const REPLY_TIMEOUT: Duration = Duration::from_millis(10);

/// Where the dead-man switch comes from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Grip {
    /// A switch wired to analog pin `pin`, closed while its reading is
    /// above `closed_above` (the board's units).
    Pin {
        /// The analog pin.
        pin: u8,
        /// The reading above which the switch is closed.
        closed_above: f32,
    },
    /// No switch: the hand is taken to be on the handle whenever the loop
    /// is armed. The region is proven for a grasp of at least 2 N s/m, so
    /// this is the user's explicit choice, and opening says so.
    Assumed,
}

/// A 2DIY's board, set up, on its port.
pub struct HaplyIo<P> {
    port: P,
    setup: Setup<2>,
    io: [IoScale; 2],
    grip: Grip,
    buf: Vec<u8>,
}

impl<P: Read + Write + Send> HaplyIo<P> {
    /// The board on `port`, reset and set up with `setup`, each joint's
    /// duty scaled by `io` (full scale at the joint's peak torque), the
    /// dead-man switch from `grip`.
    pub fn open(
        mut port: P,
        setup: Setup<2>,
        io: [IoScale; 2],
        grip: Grip,
    ) -> Result<Self, String> {
        let packet = setup
            .encode()
            .map_err(|e| format!("the 2DIY's setup: {e}"))?;
        port.write_all(&setup.reset())
            .and_then(|()| port.write_all(&packet))
            .map_err(|e| format!("the 2DIY's port would not take its setup: {e}"))?;
        let buf = vec![0; setup.reply_len()];
        Ok(HaplyIo {
            port,
            setup,
            io,
            grip,
            buf,
        })
    }

    /// Read the whole reply, or say why not.
    fn read_reply(&mut self) -> Result<(), String> {
        let need = self.buf.len();
        let mut got = 0;
        while got < need {
            match self.port.read(&mut self.buf[got..]) {
                Ok(0) => return Err(unplugged()),
                Ok(n) => got += n,
                Err(e) if e.kind() == ErrorKind::Interrupted => {}
                Err(e) if e.kind() == ErrorKind::TimedOut || e.kind() == ErrorKind::WouldBlock => {
                    return Err(if got == 0 {
                        format!(
                            "the 2DIY stopped answering: no reply to a torque packet within \
                             {} ms; check its USB cable and power, then open it again",
                            REPLY_TIMEOUT.as_millis()
                        )
                    } else {
                        format!(
                            "the 2DIY's reply was cut short: {}; its USB link is failing, or \
                             another program is reading the port",
                            PacketError::Short { got, need }
                        )
                    });
                }
                Err(e) => return Err(io_failed(&e)),
            }
        }
        Ok(())
    }
}

fn unplugged() -> String {
    "the 2DIY's port closed: the device was unplugged or lost power; plug it in and \
     open it again"
        .into()
}

fn io_failed(e: &std::io::Error) -> String {
    // (EIO or a broken pipe: the USB device went away under the open
    // port.)
    if e.raw_os_error() == Some(5) || e.kind() == ErrorKind::BrokenPipe {
        unplugged()
    } else {
        format!("the 2DIY's port failed: {e}")
    }
}

impl<P: Read + Write + Send> DeviceIo<2> for HaplyIo<P> {
    fn exchange(&mut self, duty: [i16; 2], on: bool) -> Result<RawSensors<2>, String> {
        // The board image's torque resists the joint's motion; the
        // protocol's turns it toward larger angles.
        let torque = core::array::from_fn(|i| {
            if on {
                -self.io[i].force_n(duty[i])
            } else {
                0.0
            }
        });
        self.port
            .write_all(&self.setup.torques(torque))
            .map_err(|e| io_failed(&e))?;
        self.read_reply()?;
        let reply = self
            .setup
            .decode_reply(&self.buf)
            .map_err(|e| format!("the 2DIY's reply: {e}"))?;
        let dead_man_closed = match self.grip {
            Grip::Assumed => true,
            Grip::Pin { pin, closed_above } => {
                let at = self.setup.sensor_pins.iter().position(|p| *p == pin);
                at.and_then(|k| reply.sensors.get(k))
                    .is_some_and(|v| *v > closed_above)
            }
        };
        Ok(RawSensors {
            encoder_raw: reply.counts.map(|c| c as u32),
            dead_man_closed,
            ..RawSensors::default()
        })
    }
}
