//! The configuration record: what a board keeps across power cycles, and
//! its byte layout in flash.
//!
//! ```text
//! offset  size  field
//!      0     4  magic "TPCF" (written last: a record without it is absent)
//!      4     2  format version, little-endian
//!      6     2  payload length n, little-endian (<= MAX_PAYLOAD)
//!      8     4  sequence number, little-endian (each save adds one)
//!     12     n  payload: the Config, postcard-encoded
//!   12+n     4  CRC-32 of bytes 4 .. 12+n, little-endian
//! ```
//!
//! A board of several axes stores one `Config` per axis, one after the
//! other in the payload; a one-axis record is exactly one.
//!
//! The gains are the link's [`Gains`]: a record and a frame are both bytes
//! that must stay readable across versions, so they share one encoding,
//! and the board converts to the control crate's gains once (see the
//! crate's README).

use crate::crc32::crc32;
use serde::{Deserialize, Serialize};
use twoport_link::Gains;

/// The record's first word, "TPCF" in ASCII.
pub const MAGIC: [u8; 4] = *b"TPCF";
/// The record format this crate writes and reads.
pub const FORMAT_VERSION: u16 = 1;
/// The largest payload (bytes): room for three axes' configs, and a
/// whole record fits a 256-byte erase unit.
pub const MAX_PAYLOAD: usize = 240;
/// Header bytes before the payload.
pub const HEADER: usize = 12;
/// The largest record (bytes).
pub const MAX_RECORD: usize = HEADER + MAX_PAYLOAD + 4;

/// What a board keeps across power cycles. Units are SI.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Config {
    /// The gains in force.
    pub gains: Gains,
    /// The load cell's calibration.
    pub load_cell: LoadCell,
    /// How the axis homes.
    pub homing: HomingSetup,
    /// The safety limits.
    pub limits: Limits,
}

/// A load cell's calibration: force = (counts - offset) x scale.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct LoadCell {
    /// ADC counts at zero force.
    pub offset_counts: i32,
    /// Force per count (N).
    pub n_per_count: f32,
}

/// Where the hard stop is and how hard homing may push.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct HomingSetup {
    /// The stop's position, as the encoder reads it once homed (nm).
    pub stop_nm: i32,
    /// Whether the stop lies toward positive positions.
    pub toward_positive: bool,
    /// The largest force homing pushes with (N).
    pub force_limit_n: f32,
    /// The encoder's index mark (nm), where homing uses the index pulse.
    pub index_nm: Option<i32>,
}

/// The safety layer's limits that a lab sets for its device.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Limits {
    /// Largest force at any instant (N).
    pub peak_force_n: f32,
    /// Largest force held indefinitely (N).
    pub continuous_force_n: f32,
    /// Largest handle speed (m/s).
    pub max_velocity_mps: f32,
    /// Ticks without a link heartbeat before a fault (0: unchecked).
    pub heartbeat_timeout_ticks: u32,
}

/// Why bytes are not a record this crate can use.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum RecordError {
    /// No record: the magic word is absent (erased, or a write that never
    /// finished).
    Absent,
    /// The length field exceeds [`MAX_PAYLOAD`] or the bytes available.
    BadLength(u16),
    /// The CRC does not match: the record is corrupt.
    BadCrc,
    /// A format this crate does not read.
    Version(u16),
    /// The CRC matches but the payload does not decode.
    Payload,
    /// A value is out of range; the field is named.
    Invalid(&'static str),
    /// The record holds another number of axes than the reader's board.
    Axes {
        /// The axes the record holds.
        found: u8,
    },
}

/// Encode `config` as a record numbered `seq` into `buf`, returning its
/// length. `None` if `buf` is shorter than [`MAX_RECORD`] or the config
/// does not validate.
pub fn encode(config: &Config, seq: u32, buf: &mut [u8]) -> Option<usize> {
    encode_as(FORMAT_VERSION, config, seq, buf)
}

/// [`encode`] for a board of `N` axes: each axis's config in turn.
pub fn encode_axes<const N: usize>(
    configs: &[Config; N],
    seq: u32,
    buf: &mut [u8],
) -> Option<usize> {
    encode_axes_as(FORMAT_VERSION, configs, seq, buf)
}

/// [`encode`] stamped with another format `version`: for migration tools
/// and for testing how a reader treats records it does not know.
pub fn encode_as(version: u16, config: &Config, seq: u32, buf: &mut [u8]) -> Option<usize> {
    encode_axes_as(version, core::slice::from_ref(config), seq, buf)
}

fn encode_axes_as(version: u16, configs: &[Config], seq: u32, buf: &mut [u8]) -> Option<usize> {
    if configs.is_empty() || configs.iter().any(|c| c.validate().is_err()) {
        return None;
    }
    if buf.len() < MAX_RECORD {
        return None;
    }
    let mut n = 0;
    for c in configs {
        n += postcard::to_slice(c, &mut buf[HEADER + n..HEADER + MAX_PAYLOAD])
            .ok()?
            .len();
    }
    buf[..4].copy_from_slice(&MAGIC);
    buf[4..6].copy_from_slice(&version.to_le_bytes());
    buf[6..8].copy_from_slice(&(n as u16).to_le_bytes());
    buf[8..12].copy_from_slice(&seq.to_le_bytes());
    let end = HEADER + n;
    let crc = crc32(&buf[4..end]);
    buf[end..end + 4].copy_from_slice(&crc.to_le_bytes());
    Some(end + 4)
}

/// Decode a record from the start of `bytes` (which may run on past it):
/// its sequence number and config, or why not. Never panics.
pub fn decode(bytes: &[u8]) -> Result<(u32, Config), RecordError> {
    decode_axes::<1>(bytes).map(|(seq, [c])| (seq, c))
}

/// [`decode`] for a board of `N` axes: the record must hold `N` configs
/// ([`RecordError::Axes`] says how many it holds otherwise).
pub fn decode_axes<const N: usize>(bytes: &[u8]) -> Result<(u32, [Config; N]), RecordError> {
    if bytes.len() < HEADER + 4 || bytes[..4] != MAGIC {
        return Err(RecordError::Absent);
    }
    let word = |i: usize| u16::from_le_bytes([bytes[i], bytes[i + 1]]);
    let (version, len) = (word(4), word(6));
    let n = len as usize;
    if n > MAX_PAYLOAD || bytes.len() < HEADER + n + 4 {
        return Err(RecordError::BadLength(len));
    }
    let end = HEADER + n;
    let stored = u32::from_le_bytes([bytes[end], bytes[end + 1], bytes[end + 2], bytes[end + 3]]);
    if crc32(&bytes[4..end]) != stored {
        return Err(RecordError::BadCrc);
    }
    if version != FORMAT_VERSION {
        return Err(RecordError::Version(version));
    }
    let seq = u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]);
    let mut rest = &bytes[HEADER..end];
    let mut configs: Option<[Config; N]> = None;
    let mut found = 0usize;
    while !rest.is_empty() {
        let (c, r) = postcard::take_from_bytes::<Config>(rest).map_err(|_| RecordError::Payload)?;
        c.validate().map_err(RecordError::Invalid)?;
        let all = configs.get_or_insert([c; N]);
        if let Some(slot) = all.get_mut(found) {
            *slot = c;
        }
        found += 1;
        rest = r;
    }
    match configs {
        Some(c) if found == N => Ok((seq, c)),
        Some(_) => Err(RecordError::Axes {
            found: found.min(u8::MAX as usize) as u8,
        }),
        None => Err(RecordError::Payload),
    }
}

fn positive(name: &'static str, v: f32) -> Result<(), &'static str> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(name)
    }
}

impl Config {
    /// Every value finite and in its range; the error names the field.
    /// (Whether the gains are proven stable is the board's to check: the
    /// region belongs to its image.)
    pub fn validate(&self) -> Result<(), &'static str> {
        let gains_finite = match self.gains {
            Gains::Impedance(g) => [g.k_npm, g.b_nspm, 0.0, 0.0],
            Gains::Admittance(g) => [g.kp_npm, g.bp_nspm, g.m_kg, g.b_nspm],
        };
        if gains_finite.iter().any(|g| !(g.is_finite() && *g >= 0.0)) {
            return Err("gains");
        }
        positive("load_cell.n_per_count (N)", self.load_cell.n_per_count)?;
        positive("limits.peak_force_n (N)", self.limits.peak_force_n)?;
        positive(
            "limits.continuous_force_n (N)",
            self.limits.continuous_force_n,
        )?;
        if self.limits.continuous_force_n > self.limits.peak_force_n {
            return Err("limits.continuous_force_n (N)");
        }
        positive(
            "limits.max_velocity_mps (m/s)",
            self.limits.max_velocity_mps,
        )?;
        positive("homing.force_limit_n (N)", self.homing.force_limit_n)?;
        if self.homing.force_limit_n > self.limits.peak_force_n {
            return Err("homing.force_limit_n (N)");
        }
        Ok(())
    }
}
