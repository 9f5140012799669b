//! The 2DIY over its serial port: one torque packet out and one reply in
//! a tick, as the PC's loop asks through [`DeviceIo`].

use super::protocol::Setup;
use crate::device_port::{DevicePort, Grip};
use crate::DeviceIo;
use twoport_board::IoScale;
use twoport_board::RawSensors;

/// A 2DIY's board, set up, on its port.
pub struct HaplyIo {
    port: DevicePort,
    setup: Setup<2>,
    io: [IoScale; 2],
    grip: Grip,
    buf: Vec<u8>,
}

impl HaplyIo {
    /// The board on `port`, reset and set up with `setup`, each joint's
    /// duty scaled by `io` (full scale at the joint's peak torque), the
    /// dead-man switch from `grip`.
    pub fn open(
        mut port: DevicePort,
        setup: Setup<2>,
        io: [IoScale; 2],
        grip: Grip,
    ) -> Result<Self, String> {
        let packet = setup
            .encode()
            .map_err(|e| format!("the 2DIY's setup: {e}"))?;
        port.send(&setup.reset())?;
        port.send(&packet)?;
        let buf = vec![0; setup.reply_len()];
        Ok(HaplyIo {
            port,
            setup,
            io,
            grip,
            buf,
        })
    }
}

impl DeviceIo<2> for HaplyIo {
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
        self.port.send(&self.setup.torques(torque))?;
        self.port.receive(&mut self.buf)?;
        let reply = self
            .setup
            .decode_reply(&self.buf)
            .map_err(|e| format!("the 2DIY's reply: {e}"))?;
        let pins = &self.setup.sensor_pins;
        let reading = |pin| {
            let k = pins.iter().position(|p| *p == pin)?;
            reply.sensors.get(k).copied()
        };
        let dead_man_closed = self.grip.closed(reading, 0);
        Ok(RawSensors {
            encoder_raw: reply.counts.map(|c| c as u32),
            dead_man_closed,
            ..RawSensors::default()
        })
    }
}
