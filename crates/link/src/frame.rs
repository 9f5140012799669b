//! Framing: `COBS(postcard(seq, message) ++ CRC-16 LE) 0x00`.

use crate::crc::crc16;
use crate::Message;
use serde::{Deserialize, Serialize};

/// Largest postcard-encoded envelope (bytes): a three-axis telemetry
/// message at its widest takes about 160.
pub const MAX_PAYLOAD: usize = 192;
/// Largest frame on the wire, delimiter included (bytes).
pub const MAX_FRAME: usize = cobs::max_encoding_length(MAX_PAYLOAD + 2) + 1;

/// A message with its sequence number.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Envelope {
    /// Sender's sequence number (wraps).
    pub seq: u16,
    /// The message.
    pub msg: Message,
}

/// Why a frame could not be sent or was dropped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum FrameError {
    /// The output buffer is too small, or the message exceeds `MAX_PAYLOAD`.
    TooLong,
    /// The bytes between delimiters are not valid COBS.
    Cobs,
    /// Shorter than a CRC.
    TooShort,
    /// The CRC does not match.
    Crc,
    /// The CRC matched but the payload is not a message of this protocol.
    Decode,
    /// More bytes than a frame can hold before a delimiter.
    Overflow,
}

/// Encode `msg` with sequence number `seq` into `out`; returns the frame
/// length, delimiter included.
pub fn encode(seq: u16, msg: &Message, out: &mut [u8]) -> Result<usize, FrameError> {
    let mut raw = [0u8; MAX_PAYLOAD + 2];
    let n = postcard::to_slice(&Envelope { seq, msg: *msg }, &mut raw[..MAX_PAYLOAD])
        .map_err(|_| FrameError::TooLong)?
        .len();
    let crc = crc16(&raw[..n]).to_le_bytes();
    raw[n..n + 2].copy_from_slice(&crc);
    let m = cobs::try_encode(&raw[..n + 2], out).map_err(|_| FrameError::TooLong)?;
    let end = out.get_mut(m).ok_or(FrameError::TooLong)?;
    *end = 0;
    Ok(m + 1)
}

/// What the decoder has seen.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Stats {
    /// Good frames.
    pub frames: u32,
    /// Frames dropped, by reason.
    pub cobs: u32,
    /// Too short for a CRC.
    pub too_short: u32,
    /// CRC mismatches.
    pub crc: u32,
    /// Not a message.
    pub decode: u32,
    /// Overlong runs without a delimiter.
    pub overflow: u32,
    /// Frames missing by sequence number.
    pub missing: u32,
}

impl Stats {
    /// Every dropped frame.
    pub fn dropped(&self) -> u32 {
        self.cobs + self.too_short + self.crc + self.decode + self.overflow
    }
}

/// A streaming decoder: feed it bytes as they arrive; a bad frame is
/// dropped and counted, and decoding resumes at the next delimiter.
#[derive(Clone, Debug)]
pub struct Decoder {
    buf: [u8; MAX_FRAME],
    len: usize,
    overflowed: bool,
    expected: Option<u16>,
    stats: Stats,
}

impl Default for Decoder {
    fn default() -> Self {
        Decoder {
            buf: [0; MAX_FRAME],
            len: 0,
            overflowed: false,
            expected: None,
            stats: Stats::default(),
        }
    }
}

impl Decoder {
    /// A decoder waiting for its first delimiter-terminated frame.
    pub fn new() -> Self {
        Self::default()
    }

    /// Counters so far.
    pub fn stats(&self) -> Stats {
        self.stats
    }

    /// One byte in; a finished frame (or the reason it was dropped) out.
    pub fn push(&mut self, byte: u8) -> Option<Result<Envelope, FrameError>> {
        if byte != 0 {
            if self.len < self.buf.len() {
                self.buf[self.len] = byte;
                self.len += 1;
            } else {
                self.overflowed = true;
            }
            return None;
        }
        let (len, overflowed) = (self.len, self.overflowed);
        self.len = 0;
        self.overflowed = false;
        if overflowed {
            self.stats.overflow += 1;
            return Some(Err(FrameError::Overflow));
        }
        if len == 0 {
            return None; // back-to-back delimiters: idle line
        }
        let r = self.finish(len);
        match r {
            Ok(env) => {
                self.stats.frames += 1;
                if let Some(want) = self.expected {
                    self.stats.missing += env.seq.wrapping_sub(want) as u32;
                }
                self.expected = Some(env.seq.wrapping_add(1));
            }
            Err(FrameError::Cobs) => self.stats.cobs += 1,
            Err(FrameError::TooShort) => self.stats.too_short += 1,
            Err(FrameError::Crc) => self.stats.crc += 1,
            Err(_) => self.stats.decode += 1,
        }
        Some(r)
    }

    fn finish(&mut self, len: usize) -> Result<Envelope, FrameError> {
        let n = cobs::decode_in_place(&mut self.buf[..len]).map_err(|_| FrameError::Cobs)?;
        if n < 3 {
            return Err(FrameError::TooShort);
        }
        let (payload, crc) = self.buf[..n].split_at(n - 2);
        if crc16(payload).to_le_bytes() != [crc[0], crc[1]] {
            return Err(FrameError::Crc);
        }
        match postcard::take_from_bytes::<Envelope>(payload) {
            Ok((env, [])) => Ok(env),
            _ => Err(FrameError::Decode),
        }
    }

    /// Feed many bytes; `on_frame` gets each good envelope.
    pub fn feed(&mut self, bytes: &[u8], mut on_frame: impl FnMut(Envelope)) {
        for &b in bytes {
            if let Some(Ok(env)) = self.push(b) {
                on_frame(env);
            }
        }
    }
}
