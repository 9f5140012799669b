//! Quadrature-encoder counts to absolute position, across hardware counter
//! wrap-around.

use crate::Position;

/// Why an encoder configuration or reading was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum EncoderError {
    /// The counter width is not between 2 and 32 bits.
    BadWidth(u8),
    /// The resolution is not between 1 pm and 2.097 mm per count.
    BadResolution(i64),
    /// A raw reading has bits set above the counter width: the value did not
    /// come from a counter of this width (bus glitch or wrong register).
    RawOutOfRange(u32),
}

/// Unwraps a free-running `bits`-wide hardware counter (16 or 32 bits on
/// common timers) into an unwrapped `i32` count and a [`Position`].
///
/// Between two reads the shaft must move less than half the counter range
/// (`2^(bits-1)` counts); the safety layer's velocity limit is what enforces
/// that, so set it below `2^(bits-1) * resolution / T`.
///
/// The resolution is configured in integer picometres per count and kept as
/// a fixed-point number of 2^-10 nm (0.98 pm) per count, so that a count
/// becomes a position with one 32 x 32-bit multiply: the scale is exact to
/// 0.49 pm per count (5e-7 of a 1 µm count). The unwrapped count saturates
/// where the position reaches an end of its range (±2.147 m), so a shaft
/// driven past it moves the position again as soon as it turns back.
#[derive(Clone, Copy, Debug)]
pub struct Encoder {
    /// `32 - bits`: shifting a difference up by this and back down
    /// (arithmetically) sign-extends it.
    shift: u32,
    /// `2^bits - 1`: the bits the counter has.
    mask: u32,
    pm_per_count: i64,
    /// The resolution in 2^-10 nm per count.
    q10_per_count: i32,
    last_raw: u32,
    count: i32,
    /// The counts whose positions are the ends of the range.
    count_min: i32,
    count_max: i32,
    origin: Position,
}

/// The largest resolution: `i32::MAX` units of 2^-10 nm, 2.097 mm per count.
const MAX_PM_PER_COUNT: i64 = 2_097_151_999;

impl Encoder {
    /// A counter `bits` wide (2..=32) whose one count is `pm_per_count`
    /// picometres (1 ..= 2.097e9) of travel at the actuator. `first_raw` is
    /// the counter's value that maps to `origin`.
    ///
    /// # Examples
    ///
    /// ```
    /// use twoport_control::{Encoder, EncoderError, Position};
    /// // A 16-bit timer counting 1 µm steps, read as 0 at the origin.
    /// let mut enc = Encoder::new(16, 1_000_000, 0, Position::ZERO).unwrap();
    /// assert_eq!(enc.update(250).unwrap(), Position::from_nm(250_000));
    /// // The counter wrapping past zero is unwrapped: -10 counts.
    /// assert_eq!(enc.update(65_526).unwrap(), Position::from_nm(-10_000));
    /// assert!(matches!(Encoder::new(40, 1_000_000, 0, Position::ZERO), Err(EncoderError::BadWidth(40))));
    /// ```
    pub fn new(
        bits: u8,
        pm_per_count: i64,
        first_raw: u32,
        origin: Position,
    ) -> Result<Self, EncoderError> {
        if !(2..=32).contains(&bits) {
            return Err(EncoderError::BadWidth(bits));
        }
        if !(1..=MAX_PM_PER_COUNT).contains(&pm_per_count) {
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
        Ok(Self::build(bits, mask, pm_per_count, first_raw, origin))
    }

    /// A 32-bit counter of 1 nm counts reading `at` where it reads
    /// `at`'s nanometres: a position a computation (a linkage's
    /// kinematics) drives, unwrapped and read like a sensor's.
    pub(crate) fn nanometre_counter(at: Position) -> Self {
        Self::build(32, u32::MAX, 1_000, at.nm() as u32, at)
    }

    /// The counter, its arguments checked.
    fn build(bits: u8, mask: u32, pm_per_count: i64, first_raw: u32, origin: Position) -> Self {
        // pm * 1024 / 1000, rounded half up; >= 1 for pm >= 1.
        let q10 = (pm_per_count * 128 + 62) / 125;
        // The position of count c is origin + floor((c q10 + 512) / 1024);
        // these are the extreme counts that keep it within i32.
        let room_up = i32::MAX as i64 - origin.nm() as i64;
        let room_down = origin.nm() as i64 - i32::MIN as i64;
        let count_max = ((room_up + 1) * 1024 - 513) / q10;
        let count_min = -((room_down * 1024 + 512) / q10);
        Encoder {
            shift: 32 - bits as u32,
            mask,
            pm_per_count,
            q10_per_count: q10 as i32,
            last_raw: first_raw,
            count: 0,
            count_min: count_min.max(i32::MIN as i64) as i32,
            count_max: count_max.min(i32::MAX as i64) as i32,
            origin,
        }
    }

    /// Largest movement between two reads that unwraps unambiguously (counts).
    pub fn max_counts_per_read(&self) -> u32 {
        self.mask >> 1 // 2^(bits-1) - 1
    }

    /// Travel per count as configured (pm).
    pub fn pm_per_count(&self) -> i64 {
        self.pm_per_count
    }

    /// Take a new raw counter value; returns the unwrapped position. A raw
    /// value wider than the counter is refused and the state is unchanged.
    #[inline]
    pub fn update(&mut self, raw: u32) -> Result<Position, EncoderError> {
        if raw & !self.mask != 0 {
            return Err(EncoderError::RawOutOfRange(raw));
        }
        // The `bits`-wide difference, sign-extended: bits above the
        // counter's width leave through the top.
        let delta = ((raw.wrapping_sub(self.last_raw) << self.shift) as i32) >> self.shift;
        self.last_raw = raw;
        self.count = self
            .count
            .saturating_add(delta)
            .max(self.count_min)
            .min(self.count_max);
        Ok(self.position())
    }

    /// Calibrate: from now on the counter's present value reads as
    /// `position` (what homing does once it has found the hard stop).
    /// Resolution and width are kept; the unwrapped count restarts at 0.
    ///
    /// # Examples
    ///
    /// ```
    /// use twoport_control::{Encoder, Position};
    /// let mut enc = Encoder::new(16, 1_000_000, 0, Position::ZERO).unwrap();
    /// enc.update(500).unwrap(); // 0.5 mm from where it powered on
    /// enc.rezero(Position::from_nm(-20_000_000)); // this is the stop, -20 mm
    /// assert_eq!(enc.update(510).unwrap(), Position::from_nm(-19_990_000));
    /// ```
    pub fn rezero(&mut self, position: Position) {
        let bits = (32 - self.shift) as u8;
        // The width, resolution and last reading were all accepted once.
        if let Ok(e) = Encoder::new(bits, self.pm_per_count, self.last_raw, position) {
            *self = e;
        }
    }

    /// Calibrate from a reading in the past: the counter read `raw` at
    /// `position` (an index pulse latched it), and it has moved on to its
    /// last reading since. Returns the position now; a `raw` wider than the
    /// counter is refused and nothing changes.
    ///
    /// # Examples
    ///
    /// ```
    /// use twoport_control::{Encoder, Position};
    /// let mut enc = Encoder::new(16, 1_000_000, 0, Position::ZERO).unwrap();
    /// enc.update(1_200).unwrap();
    /// // The index mark, at +5 mm, latched the counter at 1,180.
    /// let now = enc.rezero_at(1_180, Position::from_nm(5_000_000)).unwrap();
    /// assert_eq!(now, Position::from_nm(5_020_000));
    /// ```
    pub fn rezero_at(&mut self, raw: u32, position: Position) -> Result<Position, EncoderError> {
        let bits = (32 - self.shift) as u8;
        let now = self.last_raw;
        let mut e = Encoder::new(bits, self.pm_per_count, raw, position)?;
        let p = e.update(now)?;
        *self = e;
        Ok(p)
    }

    /// Unwrapped counts since construction.
    pub fn count(&self) -> i32 {
        self.count
    }

    /// The current position: `origin + count * resolution`, to the nearest
    /// nanometre.
    #[inline]
    pub fn position(&self) -> Position {
        let nm = (self.count as i64 * self.q10_per_count as i64 + 512) >> 10;
        // The count's limits keep the sum within i32, so it is exact modulo
        // 2^32 and exact: no clamp, no saturation.
        Position(self.origin.nm().wrapping_add(nm as i32))
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
            let mut e = Encoder::new(bits, 1000, 0, Position::ZERO).unwrap();
            let vmax = e.max_counts_per_read() as i64;
            let modulus: i128 = 1i128 << bits;
            let mut truth: i64 = 0;
            // Full speed forward until half the count range, then a
            // pattern that reverses at full speed every read.
            let forward = (i32::MAX as i64 / 2 / vmax).min(600_000);
            for k in 0..1_000_000i64 {
                let step = if k < forward {
                    vmax
                } else if k % 2 == 0 {
                    -vmax + (k % 13)
                } else {
                    vmax
                };
                truth += step;
                let raw = (truth as i128).rem_euclid(modulus) as u32;
                e.update(raw).unwrap();
                assert_eq!(e.count() as i64, truth, "bits {bits}, read {k}");
            }
            assert_eq!(e.position().nm() as i64, truth);
        }
    }

    #[test]
    fn position_uses_origin_and_resolution() {
        let mut e = Encoder::new(16, 2_500_000, 65_535, Position::from_nm(7)).unwrap();
        e.update(1).unwrap(); // wrapped forward by 2 counts
        assert_eq!(e.position().nm(), 7 + 2 * 2_500);
        // A resolution that is not a whole number of nanometres: 1.5 µm
        // over a 2π·10 mm / 4096 count wheel is 15,339,807.88 pm.
        let mut e = Encoder::new(32, 15_339_808, 0, Position::ZERO).unwrap();
        e.update(100_000).unwrap();
        let want_nm = 100_000.0 * 15_339_807.878_856 / 1000.0;
        assert!((e.position().nm() as f64 - want_nm).abs() < 60.0);
    }

    #[test]
    fn count_and_position_saturate_instead_of_wrapping() {
        // 1 mm per count from 2 m: the end of the range is 147 counts away.
        let mut e = Encoder::new(32, 1_000_000_000, 0, Position::from_nm(2_000_000_000)).unwrap();
        let step = e.max_counts_per_read();
        let mut raw = 0u32;
        for _ in 0..4 {
            raw = raw.wrapping_add(step);
            e.update(raw).unwrap();
        }
        assert_eq!(e.count(), 147);
        assert_eq!(e.position().nm(), 2_147_000_000);
        // Back the other way: it moves at once, from the end of the range.
        e.update(raw.wrapping_sub(10)).unwrap();
        assert_eq!(e.count(), 137);
        assert_eq!(e.position().nm(), 2_137_000_000);
    }

    /// At every resolution and origin, the count stops exactly where the
    /// next count's position would leave the range, at both ends.
    #[test]
    fn count_limits_are_the_ends_of_the_range() {
        let exact = |e: &Encoder, c: i64| -> i64 {
            e.origin.nm() as i64 + ((c * e.q10_per_count as i64 + 512) >> 10)
        };
        for pm in [1, 999, 1_000, 15_339_808, 1_000_000_000, MAX_PM_PER_COUNT] {
            for origin in [i32::MIN, -1_000_000_007, 0, 123_456_789, i32::MAX] {
                let e = Encoder::new(32, pm, 0, Position::from_nm(origin)).unwrap();
                let (lo, hi) = (e.count_min as i64, e.count_max as i64);
                let range = i32::MIN as i64..=i32::MAX as i64;
                assert!(range.contains(&exact(&e, lo)) && range.contains(&exact(&e, hi)));
                assert!(hi == i32::MAX as i64 || exact(&e, hi + 1) > i32::MAX as i64);
                assert!(lo == i32::MIN as i64 || exact(&e, lo - 1) < i32::MIN as i64);
            }
        }
    }

    #[test]
    fn rezero_keeps_unwrapping_across_the_counter_wrap() {
        let mut e = Encoder::new(16, 1_000_000, 65_000, Position::ZERO).unwrap();
        e.update(65_500).unwrap();
        e.rezero(Position::from_nm(-30_000_000));
        assert_eq!(e.position().nm(), -30_000_000);
        // 100 counts on, across the 16-bit wrap.
        assert_eq!(e.update(64).unwrap().nm(), -30_000_000 + 100_000);
        assert_eq!(e.pm_per_count(), 1_000_000);
        assert_eq!(e.max_counts_per_read(), 32_767);
    }

    #[test]
    fn resolution_limits() {
        assert!(Encoder::new(16, 1, 0, Position::ZERO).is_ok());
        assert!(Encoder::new(16, MAX_PM_PER_COUNT, 0, Position::ZERO).is_ok());
        assert_eq!(
            Encoder::new(16, MAX_PM_PER_COUNT + 1, 0, Position::ZERO).unwrap_err(),
            EncoderError::BadResolution(MAX_PM_PER_COUNT + 1)
        );
    }
}
