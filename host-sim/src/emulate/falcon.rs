//! A Novint Falcon: its loader's handshake at the rates the protocol sets
//! (`twoport_host::falcon::protocol`), the firmware's upload echoed and
//! checked against the image it expects, then the firmware's 16-byte
//! packets, a period of the Falcon-like delta
//! (`models/linkages/falcon_like.toml`, under gravity) for each. A Falcon
//! whose upload was short or garbled runs nothing and answers nothing, as
//! one with the wrong firmware does.

use super::{EmulatedDevice, EmulatedHand, Emulator, Fault, Firmware};
use crate::Error;
use twoport_board::linkage::FALCON;
use twoport_design::linkage::LinkageFile;
use twoport_host::falcon::protocol::{self as p, Command, FalconStatus, PACKET};

/// The shipped Falcon-like file.
pub fn file() -> Result<LinkageFile, Error> {
    LinkageFile::from_toml(
        include_str!("../../../models/linkages/falcon_like.toml"),
        "falcon_like.toml",
    )
    .map_err(|e| Error::Sim(e.to_string()))
}

/// How the emulated Falcon's loader behaves.
#[derive(Clone, Debug, PartialEq)]
pub struct Loader {
    /// The firmware it runs once uploaded (a test's stand-in for Novint's).
    pub image: Vec<u8>,
    /// Whether it answers the handshake at all (a Falcon whose FTDI chip
    /// another driver holds, or powered off, does not).
    pub answers: bool,
    /// A byte of the upload it echoes wrong, if any.
    pub garble_at: Option<usize>,
}

/// The Falcon on a pseudo-terminal, at the image's rest pose under
/// `hand`, going wrong as `fault` says from that command on.
pub fn start(
    loader: Loader,
    hand: Option<EmulatedHand>,
    fault: Option<(u64, Fault)>,
) -> Result<Emulator<3>, Error> {
    let firmware = Falcon {
        loader,
        stage: Stage::Check1,
    };
    Emulator::start(&file()?, FALCON, true, firmware, hand, fault)
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Stage {
    Check1,
    Check2,
    /// Bytes of the upload read, and whether all matched.
    Upload {
        at: usize,
        good: bool,
    },
    Running,
    /// An upload that was not the firmware: nothing runs.
    Dead,
}

struct Falcon {
    loader: Loader,
    stage: Stage,
}

impl Firmware<3> for Falcon {
    fn serve(
        &mut self,
        rx: &mut Vec<u8>,
        baud: u32,
        device: &mut EmulatedDevice<3>,
        tx: &mut Vec<u8>,
    ) -> Result<(), String> {
        loop {
            if rx.is_empty() {
                return Ok(());
            }
            match self.stage {
                Stage::Check1 | Stage::Check2 if !self.loader.answers => rx.clear(),
                Stage::Check1 => {
                    // Anything before the handshake, or at another rate, is
                    // noise to the loader.
                    let Some(at) = rx.iter().position(|b| *b == p::CHECK_1[0]) else {
                        rx.clear();
                        continue;
                    };
                    rx.drain(..at);
                    if rx.len() < p::CHECK_1.len() {
                        return Ok(());
                    }
                    if baud == p::CHECK_BAUD && rx[..3] == p::CHECK_1 {
                        tx.extend(p::CHECK_1_ANSWER);
                        device.note("loader: first handshake");
                        self.stage = Stage::Check2;
                        rx.drain(..3);
                    } else {
                        rx.drain(..1);
                    }
                }
                Stage::Check2 => {
                    if baud == p::LOAD_BAUD && rx[0] == p::CHECK_2[0] {
                        tx.extend(p::CHECK_2_ANSWER);
                        device.note("loader: second handshake");
                        self.stage = Stage::Upload { at: 0, good: true };
                    }
                    rx.drain(..1);
                }
                Stage::Upload { at, good } if baud == p::RUN_BAUD => {
                    let whole = good && at == self.loader.image.len();
                    device.note(format!(
                        "loader: {at} bytes uploaded, {}",
                        if whole { "running" } else { "not the firmware" }
                    ));
                    self.stage = if whole { Stage::Running } else { Stage::Dead };
                }
                Stage::Upload { at, good } => {
                    let b = rx.remove(0);
                    let echo = if self.loader.garble_at == Some(at) {
                        !b
                    } else {
                        b
                    };
                    tx.push(echo);
                    let good = good && self.loader.image.get(at) == Some(&b);
                    self.stage = Stage::Upload { at: at + 1, good };
                }
                Stage::Dead => rx.clear(),
                Stage::Running => {
                    let Some(at) = rx.iter().position(|b| *b == b'<') else {
                        rx.clear();
                        continue;
                    };
                    rx.drain(..at);
                    if rx.len() < PACKET {
                        return Ok(());
                    }
                    let mut packet = [0; PACKET];
                    packet.copy_from_slice(&rx[..PACKET]);
                    rx.drain(..PACKET);
                    let Ok(c) = Command::decode(&packet) else {
                        device.note("firmware: a malformed packet, dropped");
                        continue;
                    };
                    // The motor value is the joint's torque resisting its
                    // motion; the plant's motors turn toward larger angles.
                    let torque = core::array::from_fn(|i| {
                        -f32::from(c.motor[i]) / p::MOTOR_PER_NM / FALCON.hardware.ratios[i]
                    });
                    let period = device.tick(torque)?;
                    let status = FalconStatus {
                        encoder: period.counts.map(|c| c as i16),
                        buttons: u8::from(period.grip),
                        homed: 0b111,
                    };
                    // Garbled: a byte that is no nibble.
                    device.answer(status.encode().to_vec(), |r| r[5] = 0, tx);
                }
            }
        }
    }
}
