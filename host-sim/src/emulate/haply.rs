//! A Haply 2DIY's hAPI board: it reads the host's reset, setup and torque
//! packets (`twoport_host::haply::protocol`), runs a period of the
//! pantograph (`models/linkages/haply_2diy.toml`) for each torque packet,
//! and answers with the encoders' angles as the board does. A board not
//! set up answers nothing.

use super::{EmulatedDevice, EmulatedHand, Emulator, Fault, Firmware};
use crate::Error;
use twoport_board::linkage::haply::HAPLY;
use twoport_design::linkage::LinkageFile;
use twoport_host::haply::protocol::{self, PacketError, Setup};

/// The port each of the plant's joints (`q1`, `q2`) is wired to, as Haply
/// wires the hardware v3.
pub const WIRING: [u8; 2] = [2, 1];

/// The shipped 2DIY file.
pub fn file() -> Result<LinkageFile, Error> {
    LinkageFile::from_toml(
        include_str!("../../../models/linkages/haply_2diy.toml"),
        "haply_2diy.toml",
    )
    .map_err(|e| Error::Sim(e.to_string()))
}

/// The 2DIY on a pseudo-terminal, at the image's rest pose under `hand`,
/// going wrong as `fault` says from that torque packet on.
pub fn start(
    hand: Option<EmulatedHand>,
    fault: Option<(u64, Fault)>,
) -> Result<Emulator<2>, Error> {
    Emulator::start(&file()?, HAPLY, false, Board::default(), hand, fault)
}

/// The board's firmware: its setup, once it has one.
#[derive(Default)]
struct Board {
    setup: Option<Setup<2>>,
}

impl Firmware<2> for Board {
    fn serve(
        &mut self,
        rx: &mut Vec<u8>,
        _baud: u32,
        device: &mut EmulatedDevice<2>,
        tx: &mut Vec<u8>,
    ) -> Result<(), String> {
        loop {
            let Some(&kind) = rx.first() else {
                return Ok(());
            };
            let used = match kind {
                protocol::RESET if rx.len() >= 2 => {
                    self.setup = None;
                    device.note("reset");
                    2
                }
                protocol::SETUP => match Setup::<2>::decode(rx) {
                    Ok((setup, used)) => {
                        device.note(format!("setup {setup:?}"));
                        self.setup = Some(setup);
                        used
                    }
                    Err(PacketError::Short { .. }) => return Ok(()),
                    Err(e) => return Err(format!("setup: {e}")),
                },
                protocol::TORQUES if rx.len() >= Setup::<2>::torques_len() => {
                    let n = Setup::<2>::torques_len();
                    if let Some(setup) = &self.setup {
                        let torque = setup
                            .decode_torques(&rx[..n])
                            .map_err(|e| format!("torques: {e}"))?;
                        // The board knows its joints by port: the wiring
                        // says which is the plant's `q1` and which `q2`.
                        let at =
                            WIRING.map(|port| setup.joints.iter().position(|j| j.port == port));
                        let [Some(a), Some(b)] = at else {
                            return Err(format!("a setup without ports {WIRING:?}: {setup:?}"));
                        };
                        let p = device.tick([torque[a], torque[b]])?;
                        let mut counts = [0; 2];
                        (counts[a], counts[b]) = (p.counts[0], p.counts[1]);
                        let grip = if p.grip { 1.0 } else { 0.0 };
                        let reply = setup.reply(&vec![grip; setup.sensor_pins.len()], counts);
                        // Garbled: another device's id.
                        device.answer(reply, |r| r[0] = r[0].wrapping_add(1), tx);
                    }
                    n
                }
                protocol::RESET | protocol::TORQUES => return Ok(()),
                other => return Err(PacketError::Type(other).to_string()),
            };
            rx.drain(..used);
        }
    }
}
