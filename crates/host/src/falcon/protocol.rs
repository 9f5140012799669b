//! The Novint Falcon's USB protocol, as libnifalcon documents it (its
//! `FalconCommLibFTDI` and `FalconFirmwareNovintSDK`): the loader's
//! handshake and firmware upload, then the running firmware's packets.
//! Written once, for the driver and for the emulator that stands in for a
//! Falcon.
//!
//! - **The loader.** At power-up the Falcon's FTDI chip (USB id
//!   `0403:cb48`) holds a loader. At 9600 baud, 8N1, no flow control, RTS
//!   low and DTR pulsed low then high, the host sends [`CHECK_1`] and the
//!   loader answers [`CHECK_1_ANSWER`]; with DTR low, at 140,000 baud, the
//!   host sends [`CHECK_2`] and it answers [`CHECK_2_ANSWER`]. The host
//!   then sends the firmware in chunks of [`CHUNK`] bytes, each echoed
//!   back, and the Falcon runs it.
//! - **The firmware.** At 1,456,312 baud (and the FTDI latency timer at
//!   1 ms), each 16-byte packet is framed by `<` and `>`. The host's
//!   carries three signed 16-bit motor values, each as four nibbles (the
//!   least significant first) offset by `0x41`, a byte of LED bits and the
//!   homing flag, and a spare; the Falcon's answer carries the three
//!   encoders' signed 16-bit counts the same way and a byte of grip
//!   buttons (low nibble) and homed motors (next three bits).

pub use crate::PacketError;

/// The Falcon's USB vendor id (its FTDI chip's).
pub const USB_VENDOR_ID: u16 = 0x0403;
/// The Falcon's USB product id.
pub const USB_PRODUCT_ID: u16 = 0xcb48;
/// The loader's first handshake's rate (baud).
pub const CHECK_BAUD: u32 = 9_600;
/// The firmware upload's rate (baud).
pub const LOAD_BAUD: u32 = 140_000;
/// The running firmware's rate (baud).
pub const RUN_BAUD: u32 = 1_456_312;
/// The host's first handshake.
pub const CHECK_1: [u8; 3] = [0x0a, 0x43, 0x0d];
/// The loader's answer to it.
pub const CHECK_1_ANSWER: [u8; 4] = [0x0a, 0x44, 0x2c, 0x0d];
/// The host's second handshake.
pub const CHECK_2: [u8; 1] = [0x41];
/// The loader's answer to it.
pub const CHECK_2_ANSWER: [u8; 2] = [0x13, 0x41];
/// The firmware's chunks (bytes): a full-speed USB packet less the FTDI
/// chip's two status bytes.
pub const CHUNK: usize = 62;
/// A packet's length, each way.
pub const PACKET: usize = 16;
/// libnifalcon's motor value per N m of torque at the arm's joint.
pub const MOTOR_PER_NM: f32 = 10_000.0;

/// The LEDs' bits.
pub const LED_GREEN: u8 = 0x2;
/// See [`LED_GREEN`].
pub const LED_BLUE: u8 = 0x4;
/// See [`LED_GREEN`].
pub const LED_RED: u8 = 0x8;

const OFFSET: u8 = 0x41;

/// What the host sends the running firmware.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Command {
    /// Each motor's value (libnifalcon's units: [`MOTOR_PER_NM`]).
    pub motor: [i16; 3],
    /// The LED bits.
    pub leds: u8,
    /// Whether the firmware homes the motors (drives each to its index).
    pub homing: bool,
}

/// What the running firmware answers.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FalconStatus {
    /// Each encoder's count since power-up (wrapping at 16 bits).
    pub encoder: [i16; 3],
    /// The grip's buttons, a bit each.
    pub buttons: u8,
    /// The motors homed, a bit each.
    pub homed: u8,
}

/// `v` as four nibbles, the least significant first, into `four`.
fn put(four: &mut [u8], v: i16) {
    let u = v as u16;
    for (k, b) in four.iter_mut().enumerate() {
        *b = OFFSET + ((u >> (4 * k)) & 0xf) as u8;
    }
}

fn get(p: &[u8], at: usize) -> Result<i16, PacketError> {
    let mut u = 0u16;
    for k in 0..4 {
        u |= u16::from(nibble(p, at + k)?) << (4 * k);
    }
    Ok(u as i16)
}

fn nibble(p: &[u8], at: usize) -> Result<u8, PacketError> {
    match p[at].checked_sub(OFFSET) {
        Some(n) if n < 16 => Ok(n),
        _ => Err(PacketError::Nibble(at)),
    }
}

fn framed(p: &[u8; PACKET]) -> Result<(), PacketError> {
    if p[0] == b'<' && p[PACKET - 1] == b'>' {
        Ok(())
    } else {
        Err(PacketError::Frame)
    }
}

impl Command {
    /// Its bytes.
    pub fn encode(&self) -> [u8; PACKET] {
        let mut p = [OFFSET; PACKET];
        (p[0], p[PACKET - 1]) = (b'<', b'>');
        for (i, m) in self.motor.iter().enumerate() {
            put(&mut p[1 + 4 * i..5 + 4 * i], *m);
        }
        p[13] = OFFSET + ((self.leds & 0x0e) | u8::from(self.homing));
        p
    }

    /// Read a packet (the Falcon's side).
    pub fn decode(p: &[u8; PACKET]) -> Result<Self, PacketError> {
        framed(p)?;
        let flags = p[13]
            .checked_sub(OFFSET)
            .filter(|f| *f < 16)
            .ok_or(PacketError::Nibble(13))?;
        nibble(p, 14)?;
        Ok(Command {
            motor: [get(p, 1)?, get(p, 5)?, get(p, 9)?],
            leds: flags & 0x0e,
            homing: flags & 1 != 0,
        })
    }
}

impl FalconStatus {
    /// Its bytes (the Falcon's side).
    pub fn encode(&self) -> [u8; PACKET] {
        let mut p = [OFFSET; PACKET];
        (p[0], p[PACKET - 1]) = (b'<', b'>');
        for (i, e) in self.encoder.iter().enumerate() {
            put(&mut p[1 + 4 * i..5 + 4 * i], *e);
        }
        p[13] = OFFSET + ((self.homed & 7) << 4 | (self.buttons & 0x0f));
        p
    }

    /// Read a packet.
    pub fn decode(p: &[u8; PACKET]) -> Result<Self, PacketError> {
        framed(p)?;
        let flags = p[13]
            .checked_sub(OFFSET)
            .filter(|f| *f < 0x80)
            .ok_or(PacketError::Nibble(13))?;
        nibble(p, 14)?;
        Ok(FalconStatus {
            encoder: [get(p, 1)?, get(p, 5)?, get(p, 9)?],
            buttons: flags & 0x0f,
            homed: flags >> 4,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bytes as libnifalcon lays them out, written by hand: `<`, each
    /// motor's four nibbles from the least significant, each plus 0x41,
    /// the flags, a spare, `>`.
    #[test]
    fn a_command_is_laid_out_as_documented() {
        let c = Command {
            motor: [0x1234, -1, 0],
            leds: LED_GREEN | LED_RED,
            homing: true,
        };
        let want = *b"<EDCBPPPPAAAALA>";
        assert_eq!(c.encode(), want);
        assert_eq!(Command::decode(&want), Ok(c));
    }

    #[test]
    fn a_status_reads_back() {
        for s in [
            FalconStatus::default(),
            FalconStatus {
                encoder: [i16::MIN, i16::MAX, -1234],
                buttons: 0b1010,
                homed: 0b101,
            },
        ] {
            assert_eq!(FalconStatus::decode(&s.encode()), Ok(s));
        }
    }

    /// A broken frame or a byte that is no nibble is named, never read.
    #[test]
    fn bad_packets_are_named() {
        let mut p = FalconStatus::default().encode();
        p[0] = b'x';
        assert_eq!(FalconStatus::decode(&p), Err(PacketError::Frame));
        let mut p = FalconStatus::default().encode();
        p[6] = 0x00;
        assert_eq!(FalconStatus::decode(&p), Err(PacketError::Nibble(6)));
        let mut p = FalconStatus::default().encode();
        p[14] = b'>';
        assert_eq!(FalconStatus::decode(&p), Err(PacketError::Nibble(14)));
    }
}
