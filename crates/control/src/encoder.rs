//! Quadrature-encoder counts to absolute position, across hardware counter
//! wrap-around.

use crate::Position;

/// Why an encoder configuration or reading was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EncoderError {
    /// The counter width is not between 2 and 32 bits.
    BadWidth(u8),
    /// The resolution is not a positive number of picometres per count.
    BadResolution(i64),
    /// A raw reading has bits set above the counter width: the value did not
    /// come from a counter of this width (bus glitch or wrong register).
    RawOutOfRange(u32),
}

/// Unwraps a free-running `bits`-wide hardware counter (16 or 32 bits on
/// common timers) into an unbounded `i64` count and a [`Position`].
///
/// Between two reads the shaft must move less than half the counter range
/// (`2^(bits-1)` counts); the safety layer's velocity limit is what enforces
/// that, so set it below `2^(bits-1) * resolution / T`.
#[derive(Clone, Copy, Debug)]
pub struct Encoder {
    bits: u8,
    mask: u32,
    pm_per_count: i64,
    last_raw: u32,
    count: i64,
    origin: Position,
}

impl Encoder {
    /// A counter `bits` wide (2..=32) whose one count is `pm_per_count`
    /// picometres of travel at the actuator. `first_raw` is the counter's
    /// value that maps to `origin`.
    pub fn new(
        bits: u8,
        pm_per_count: i64,
        first_raw: u32,
        origin: Position,
    ) -> Result<Self, EncoderError> {
        if !(2..=32).contains(&bits) {
            return Err(EncoderError::BadWidth(bits));
        }
        if pm_per_count <= 0 {
            return Err(EncoderError::BadResolution(pm_per_count));
        }
        let mask = if bits == 32 {
            u32::MAX
        } else {
            (1u32 << bits) - 1
        };
        if first_raw & !mask != 0 {
            return Err(EncoderError::RawOutOfRange(first_raw));
        }
        Ok(Encoder {
            bits,
            mask,
            pm_per_count,
            last_raw: first_raw,
            count: 0,
            origin,
        })
    }

    /// Largest movement between two reads that unwraps unambiguously (counts).
    pub fn max_counts_per_read(&self) -> u32 {
        (1u32 << (self.bits - 1)) - 1
    }

    /// Travel per count (pm).
    pub fn pm_per_count(&self) -> i64 {
        self.pm_per_count
    }

    /// Take a new raw counter value; returns the unwrapped position. A raw
    /// value wider than the counter is refused and the state is unchanged.
    pub fn update(&mut self, raw: u32) -> Result<Position, EncoderError> {
        if raw & !self.mask != 0 {
            return Err(EncoderError::RawOutOfRange(raw));
        }
        let diff = raw.wrapping_sub(self.last_raw) & self.mask;
        // Sign-extend the `bits`-wide difference.
        let half = 1u32 << (self.bits - 1);
        let delta = if diff >= half {
            diff as i64 - (self.mask as i64 + 1)
        } else {
            diff as i64
        };
        self.last_raw = raw;
        self.count = self.count.saturating_add(delta);
        Ok(self.position())
    }

    /// Unwrapped counts since construction.
    pub fn count(&self) -> i64 {
        self.count
    }

    /// The current position: `origin + count * resolution`.
    pub fn position(&self) -> Position {
        self.origin
            .offset_pm(self.count.saturating_mul(self.pm_per_count))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refuses_bad_configuration_and_wide_raw_values() {
        assert_eq!(
            Encoder::new(1, 1, 0, Position::ZERO).unwrap_err(),
            EncoderError::BadWidth(1)
        );
        assert_eq!(
            Encoder::new(33, 1, 0, Position::ZERO).unwrap_err(),
            EncoderError::BadWidth(33)
        );
        assert_eq!(
            Encoder::new(16, 0, 0, Position::ZERO).unwrap_err(),
            EncoderError::BadResolution(0)
        );
        let mut e = Encoder::new(16, 1000, 0, Position::ZERO).unwrap();
        assert_eq!(
            e.update(0x1_0000).unwrap_err(),
            EncoderError::RawOutOfRange(0x1_0000)
        );
        assert_eq!(e.count(), 0);
    }

    /// A 16-bit and a 32-bit counter driven at the largest unambiguous speed,
    /// forwards then backwards, for 10^6 reads each: the unwrapped count is
    /// exactly the true count every tick.
    #[test]
    fn unwraps_exactly_at_maximum_speed_for_a_million_reads() {
        for bits in [16u8, 32] {
            let mut e = Encoder::new(bits, 1, 0, Position::ZERO).unwrap();
            let vmax = e.max_counts_per_read() as i64;
            let modulus: i128 = 1i128 << bits;
            let mut truth: i64 = 0;
            for k in 0..1_000_000i64 {
                // Full speed forward for the first 600k reads, then a
                // pattern that reverses at full speed.
                let step = if k < 600_000 {
                    vmax
                } else if (k / 7) % 2 == 0 {
                    -vmax
                } else {
                    vmax - (k % 13)
                };
                truth += step;
                let raw = (truth as i128).rem_euclid(modulus) as u32;
                e.update(raw).unwrap();
                assert_eq!(e.count(), truth, "bits {bits}, read {k}");
            }
            assert_eq!(e.position().pm(), truth);
        }
    }

    #[test]
    fn position_uses_origin_and_resolution() {
        let mut e = Encoder::new(16, 2_500_000, 65_535, Position::from_pm(7)).unwrap();
        e.update(1).unwrap(); // wrapped forward by 2 counts
        assert_eq!(e.position().pm(), 7 + 2 * 2_500_000);
    }
}
