//! The 2DIY over its serial port: one torque packet out and one reply in
//! a tick, as the PC's loop asks through [`DeviceIo`].

use super::protocol::{Reply, Setup};
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

/// The torques the board takes (N m, toward larger angles) for the
/// image's `duty`, its outputs `on`, each joint scaled by `io`.
pub fn torques_nm(duty: [i16; 2], on: bool, io: &[IoScale; 2]) -> [f32; 2] {
    // The board image's torque resists the joint's motion.
    core::array::from_fn(|i| if on { -io[i].force_n(duty[i]) } else { 0.0 })
}

/// The image's sensors for the board's `reply` to `setup`: the encoders'
/// counts, and the grip from its pin.
pub fn sensors(setup: &Setup<2>, reply: &Reply<2>, grip: Grip) -> RawSensors<2> {
    let reading = |pin| {
        let k = setup.sensor_pins.iter().position(|p| *p == pin)?;
        reply.sensors.get(k).copied()
    };
    RawSensors {
        encoder_raw: reply.counts.map(|c| c as u32),
        dead_man_closed: grip.closed(reading, 0),
        ..RawSensors::default()
    }
}

impl DeviceIo<2> for HaplyIo {
    fn exchange(&mut self, duty: [i16; 2], on: bool) -> Result<RawSensors<2>, String> {
        let torque = torques_nm(duty, on, &self.io);
        self.port.send(&self.setup.torques(torque))?;
        self.port.receive(&mut self.buf)?;
        let reply = self
            .setup
            .decode_reply(&self.buf)
            .map_err(|e| format!("the 2DIY's reply: {e}"))?;
        Ok(sensors(&self.setup, &reply, self.grip))
    }
}
