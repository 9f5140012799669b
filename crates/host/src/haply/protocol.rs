//! The hAPI boards' USB serial protocol (Haply's 2DIY and its kin): what
//! each byte of a packet means, both ways, written once for the driver
//! and for the emulator that stands in for a board.
//!
//! The host sends a type byte, the device's id, then the payload:
//! - type 0, reset: nothing more; the board forgets its setup and stops
//!   its motors.
//! - type 1, setup: the motors' port mask (bit `p - 1` for port `p`, of
//!   four) and a direction byte for each motor in port order; the same for
//!   the encoders; the analog sensors' count and their pins (ascending);
//!   the PWM pins' count (twoport drives none); then, for each encoder in
//!   port order, two little-endian `f32`: its offset (degrees) and its
//!   counts per revolution.
//! - type 2, torques: a byte for each PWM pin (none here), then each
//!   motor's torque (N m) as a little-endian `f32`, in port order. The
//!   board answers with the device's id, each sensor's reading, then each
//!   encoder's angle (degrees: the offset plus the counts' share of a
//!   revolution, signed by its direction), all little-endian `f32`.
//!
//! Direction 0 is counter-clockwise (the angle grows with the counts, a
//! positive torque turns the joint toward larger angles), 1 clockwise.

pub use crate::PacketError;

/// The packet types the host sends.
pub const RESET: u8 = 0;
/// See [`RESET`].
pub const SETUP: u8 = 1;
/// See [`RESET`].
pub const TORQUES: u8 = 2;

/// The ports a board has.
pub const PORTS: u8 = 4;

/// Which way a joint's motor and encoder count.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Direction {
    /// The angle grows with the counts; a positive torque turns toward it.
    Ccw = 0,
    /// Reversed.
    Cw = 1,
}

impl Direction {
    /// `+1` or `-1`.
    pub fn sign(self) -> f32 {
        match self {
            Direction::Ccw => 1.0,
            Direction::Cw => -1.0,
        }
    }
    fn from_byte(b: u8) -> Option<Self> {
        match b {
            0 => Some(Direction::Ccw),
            1 => Some(Direction::Cw),
            _ => None,
        }
    }
}

/// One joint: its motor and its encoder, on one port.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Joint {
    /// The port (1 to [`PORTS`]).
    pub port: u8,
    /// The motor's direction.
    pub motor: Direction,
    /// The encoder's direction.
    pub encoder: Direction,
    /// The angle the encoder reports at zero counts (degrees).
    pub offset_deg: f32,
    /// The encoder's counts per revolution.
    pub counts_per_rev: f32,
}

/// A device's setup: its id, its `N` joints (joint `i` of the linkage on
/// `joints[i]`), and the analog pins it reads.
#[derive(Clone, Debug, PartialEq)]
pub struct Setup<const N: usize> {
    /// The device's id, which every packet and reply carries.
    pub device_id: u8,
    /// The joints, in the linkage's order.
    pub joints: [Joint; N],
    /// The analog pins read, ascending.
    pub sensor_pins: Vec<u8>,
}

impl<const N: usize> Setup<N> {
    /// The joints' indices in port order (the order every payload takes).
    fn port_order(&self) -> [usize; N] {
        let mut order: [usize; N] = core::array::from_fn(|i| i);
        order.sort_by_key(|&i| self.joints[i].port);
        order
    }

    /// Check what the protocol can carry: ports 1 to 4, each once; finite
    /// offsets and positive resolutions; at most 8 pins, ascending.
    pub fn check(&self) -> Result<(), PacketError> {
        let bad = |s: String| Err(PacketError::Setup(s));
        let mut used = 0u8;
        for (i, j) in self.joints.iter().enumerate() {
            if !(1..=PORTS).contains(&j.port) {
                return bad(format!(
                    "joint {i} on port {}: ports are 1 to {PORTS}",
                    j.port
                ));
            }
            if used & (1 << (j.port - 1)) != 0 {
                return bad(format!("joint {i} on port {}, taken by another", j.port));
            }
            used |= 1 << (j.port - 1);
            if !(j.offset_deg.is_finite() && j.counts_per_rev.is_finite() && j.counts_per_rev > 0.0)
            {
                return bad(format!(
                    "joint {i}: offset {} degrees and {} counts per revolution",
                    j.offset_deg, j.counts_per_rev
                ));
            }
        }
        if self.sensor_pins.len() > 8 || !self.sensor_pins.windows(2).all(|w| w[0] < w[1]) {
            return bad(format!(
                "sensor pins {:?}: at most 8, ascending, each once",
                self.sensor_pins
            ));
        }
        Ok(())
    }

    /// The reset packet.
    pub fn reset(&self) -> [u8; 2] {
        [RESET, self.device_id]
    }

    /// The setup packet.
    pub fn encode(&self) -> Result<Vec<u8>, PacketError> {
        self.check()?;
        let order = self.port_order();
        let mask = self.joints.iter().fold(0u8, |m, j| m | 1 << (j.port - 1));
        let mut p = vec![SETUP, self.device_id, mask];
        p.extend(order.iter().map(|&i| self.joints[i].motor as u8));
        p.push(mask);
        p.extend(order.iter().map(|&i| self.joints[i].encoder as u8));
        p.push(self.sensor_pins.len() as u8);
        p.extend(&self.sensor_pins);
        p.push(0);
        for &i in &order {
            p.extend(self.joints[i].offset_deg.to_le_bytes());
            p.extend(self.joints[i].counts_per_rev.to_le_bytes());
        }
        Ok(p)
    }

    /// The setup packet's length for `joints` joints and `pins` sensors.
    pub fn len(joints: usize, pins: usize) -> usize {
        2 + 2 * (1 + joints) + 1 + pins + 1 + 8 * joints
    }

    /// Read a setup packet (the board's side): the joints in port order,
    /// as a board knows them. `bytes` holds at least the whole packet.
    pub fn decode(bytes: &[u8]) -> Result<(Self, usize), PacketError> {
        let short = |need| PacketError::Short {
            got: bytes.len(),
            need,
        };
        let need = |n: usize| {
            if bytes.len() < n {
                Err(short(n))
            } else {
                Ok(())
            }
        };
        need(3)?;
        if bytes[0] != SETUP {
            return Err(PacketError::Type(bytes[0]));
        }
        let mask = bytes[2];
        let ports: Vec<u8> = (1..=PORTS).filter(|p| mask & (1 << (p - 1)) != 0).collect();
        if ports.len() != N || mask >> PORTS != 0 {
            return Err(PacketError::Setup(format!(
                "motor mask {mask:#06b}: this device has {N} joints"
            )));
        }
        let at_enc = 3 + N;
        need(at_enc + 1 + N + 1)?;
        if bytes[at_enc] != mask {
            return Err(PacketError::Setup(format!(
                "encoder mask {:#06b} where the motors' is {mask:#06b}",
                bytes[at_enc]
            )));
        }
        let pins_at = at_enc + 1 + N;
        let pins = usize::from(bytes[pins_at]);
        let total = Self::len(N, pins);
        need(total)?;
        let dir = |b: u8| {
            Direction::from_byte(b).ok_or_else(|| PacketError::Setup(format!("direction byte {b}")))
        };
        let float = |at: usize| {
            f32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]])
        };
        let pwm = bytes[pins_at + 1 + pins];
        if pwm != 0 {
            return Err(PacketError::Setup(format!(
                "{pwm} PWM pins: twoport's devices drive none"
            )));
        }
        let floats_at = pins_at + 1 + pins + 1;
        let mut joints = [Joint {
            port: 0,
            motor: Direction::Ccw,
            encoder: Direction::Ccw,
            offset_deg: 0.0,
            counts_per_rev: 1.0,
        }; N];
        for (k, j) in joints.iter_mut().enumerate() {
            *j = Joint {
                port: ports[k],
                motor: dir(bytes[3 + k])?,
                encoder: dir(bytes[at_enc + 1 + k])?,
                offset_deg: float(floats_at + 8 * k),
                counts_per_rev: float(floats_at + 8 * k + 4),
            };
        }
        let setup = Setup {
            device_id: bytes[1],
            joints,
            sensor_pins: bytes[pins_at + 1..pins_at + 1 + pins].to_vec(),
        };
        setup.check()?;
        Ok((setup, total))
    }

    /// The torque packet: joint `i`'s motor torque `torque_nm[i]` (N m,
    /// turning the joint toward larger angles).
    pub fn torques(&self, torque_nm: [f32; N]) -> Vec<u8> {
        let mut p = Vec::with_capacity(2 + 4 * N);
        p.extend([TORQUES, self.device_id]);
        for i in self.port_order() {
            let j = &self.joints[i];
            p.extend((j.motor.sign() * torque_nm[i]).to_le_bytes());
        }
        p
    }

    /// The torque packet's length.
    pub fn torques_len() -> usize {
        2 + 4 * N
    }

    /// Read a torque packet (the board's side): each joint's torque (N m,
    /// toward larger angles).
    pub fn decode_torques(&self, bytes: &[u8]) -> Result<[f32; N], PacketError> {
        let need = Self::torques_len();
        if bytes.len() < need {
            return Err(PacketError::Short {
                got: bytes.len(),
                need,
            });
        }
        if bytes[0] != TORQUES {
            return Err(PacketError::Type(bytes[0]));
        }
        self.id(bytes[1])?;
        let mut out = [0.0; N];
        for (k, i) in self.port_order().into_iter().enumerate() {
            let at = 2 + 4 * k;
            let v = f32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]);
            out[i] = self.joints[i].motor.sign() * v;
        }
        Ok(out)
    }

    fn id(&self, got: u8) -> Result<(), PacketError> {
        if got == self.device_id {
            Ok(())
        } else {
            Err(PacketError::DeviceId {
                got,
                expected: self.device_id,
            })
        }
    }

    /// The reply's length.
    pub fn reply_len(&self) -> usize {
        1 + 4 * (self.sensor_pins.len() + N)
    }

    /// The board's reply: the sensors' readings, then each joint's angle
    /// from its encoder's `counts` (degrees).
    pub fn reply(&self, sensors: &[f32], counts: [i32; N]) -> Vec<u8> {
        let mut p = vec![self.device_id];
        for s in sensors.iter().take(self.sensor_pins.len()) {
            p.extend(s.to_le_bytes());
        }
        for i in self.port_order() {
            let j = &self.joints[i];
            let deg = j.offset_deg
                + j.encoder.sign()
                    * (f64::from(counts[i]) * 360.0 / f64::from(j.counts_per_rev)) as f32;
            p.extend(deg.to_le_bytes());
        }
        p
    }

    /// Read a reply (the host's side): the sensors' readings and each
    /// joint's encoder counts, recovered from its angle.
    pub fn decode_reply(&self, bytes: &[u8]) -> Result<Reply<N>, PacketError> {
        let need = self.reply_len();
        if bytes.len() < need {
            return Err(PacketError::Short {
                got: bytes.len(),
                need,
            });
        }
        self.id(bytes[0])?;
        let value = |k: usize| {
            let at = 1 + 4 * k;
            let v = f32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]);
            if v.is_finite() {
                Ok(v)
            } else {
                Err(PacketError::NotFinite { index: k })
            }
        };
        let pins = self.sensor_pins.len();
        let sensors = (0..pins).map(value).collect::<Result<Vec<_>, _>>()?;
        let mut counts = [0i32; N];
        for (k, i) in self.port_order().into_iter().enumerate() {
            let j = &self.joints[i];
            let deg = f64::from(value(pins + k)?);
            let c = j.encoder.sign() as f64 * (deg - f64::from(j.offset_deg)) / 360.0
                * f64::from(j.counts_per_rev);
            counts[i] = c.round().clamp(f64::from(i32::MIN), f64::from(i32::MAX)) as i32;
        }
        Ok(Reply { sensors, counts })
    }
}

/// A board's reply, read.
#[derive(Clone, Debug, PartialEq)]
pub struct Reply<const N: usize> {
    /// Each analog sensor's reading, in the setup's pin order.
    pub sensors: Vec<f32>,
    /// Each joint's encoder counts from zero.
    pub counts: [i32; N],
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Joint 0 on port 3 (motor clockwise), joint 1 on port 1 (encoder
    /// clockwise), a switch on pin 2.
    fn setup() -> Setup<2> {
        Setup {
            device_id: 7,
            joints: [
                Joint {
                    port: 3,
                    motor: Direction::Cw,
                    encoder: Direction::Ccw,
                    offset_deg: 10.0,
                    counts_per_rev: 4096.0,
                },
                Joint {
                    port: 1,
                    motor: Direction::Ccw,
                    encoder: Direction::Cw,
                    offset_deg: 20.0,
                    counts_per_rev: 8192.0,
                },
            ],
            sensor_pins: vec![2],
        }
    }

    /// The packets' bytes as the protocol lays them out, written by hand:
    /// masks by port, every per-joint field in port order.
    #[test]
    fn packets_are_laid_out_in_port_order() {
        let s = setup();
        assert_eq!(s.reset(), [0, 7]);
        #[rustfmt::skip]
        let want = [
            1, 7,
            0b0101, 0, 1,          // motors on ports 1 and 3: joint 1 Ccw, joint 0 Cw
            0b0101, 1, 0,          // encoders: joint 1 Cw, joint 0 Ccw
            1, 2,                  // one sensor, on pin 2
            0,                     // no PWM pins
            0, 0, 0xA0, 0x41,      // port 1: offset 20.0
            0, 0, 0, 0x46,         //         8192 counts
            0, 0, 0x20, 0x41,      // port 3: offset 10.0
            0, 0, 0x80, 0x45,      //         4096 counts
        ];
        assert_eq!(s.encode().unwrap(), want);
        assert_eq!(Setup::<2>::len(2, 1), want.len());
        // Joint 1 (port 1) first; joint 0's clockwise motor turns -0.5.
        assert_eq!(
            s.torques([0.5, -1.0]),
            [2, 7, 0, 0, 0x80, 0xBF, 0, 0, 0, 0xBF]
        );
    }

    /// What one side writes the other reads back, each way.
    #[test]
    fn both_sides_read_what_the_other_writes() {
        let s = setup();
        let (read, used) = Setup::<2>::decode(&s.encode().unwrap()).unwrap();
        assert_eq!(used, Setup::<2>::len(2, 1));
        // The board knows the joints by port, not by the linkage's order.
        assert_eq!(read.joints[0], s.joints[1]);
        assert_eq!(read.joints[1], s.joints[0]);
        assert_eq!(
            s.decode_torques(&s.torques([0.25, -0.125])).unwrap(),
            [0.25, -0.125]
        );
        for counts in [[0, 0], [1, -1], [123_456, -98_765], [-4096, 8191]] {
            let r = s.decode_reply(&s.reply(&[0.75], counts)).unwrap();
            assert_eq!((r.counts, r.sensors.as_slice()), (counts, &[0.75][..]));
        }
    }

    /// A reply cut short, for another device, or carrying a NaN is named,
    /// never read.
    #[test]
    fn bad_replies_are_named() {
        let s = setup();
        let good = s.reply(&[1.0], [5, 6]);
        assert_eq!(
            s.decode_reply(&good[..5]),
            Err(PacketError::Short { got: 5, need: 13 })
        );
        let mut other = good.clone();
        other[0] = 8;
        assert_eq!(
            s.decode_reply(&other),
            Err(PacketError::DeviceId {
                got: 8,
                expected: 7
            })
        );
        let mut nan = good.clone();
        nan[9..13].copy_from_slice(&f32::NAN.to_le_bytes());
        assert_eq!(
            s.decode_reply(&nan),
            Err(PacketError::NotFinite { index: 2 })
        );
        assert!(PacketError::Short { got: 5, need: 13 }
            .to_string()
            .contains("5 of its 13"));
    }

    /// A setup the protocol cannot carry is refused before it is sent.
    #[test]
    fn impossible_setups_are_refused() {
        let mut s = setup();
        s.joints[1].port = 3;
        assert!(matches!(s.encode(), Err(PacketError::Setup(w)) if w.contains("taken")));
        let mut s = setup();
        s.joints[0].port = 5;
        assert!(matches!(s.encode(), Err(PacketError::Setup(w)) if w.contains("1 to 4")));
        let mut s = setup();
        s.joints[0].counts_per_rev = 0.0;
        assert!(s.encode().is_err());
        let mut s = setup();
        s.sensor_pins = vec![3, 2];
        assert!(s.encode().is_err());
    }
}
