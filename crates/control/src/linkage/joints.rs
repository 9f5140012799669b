//! A joint's encoder: a free-running counter to a joint angle.

use crate::param::positive;
use crate::{Encoder, EncoderError, ParamError, Position};

/// One joint's quadrature encoder, read as an angle at the joint (rad,
/// after the transmission): `q = q_0 + count · rad_per_count`.
///
/// The counter is unwrapped as [`Encoder`] unwraps a linear axis's, so a
/// 16-bit timer serves a joint that turns many times its range; between two
/// reads the joint must move less than half the counter's range.
#[derive(Clone, Copy, Debug)]
pub struct JointEncoder {
    counter: Encoder,
    rad_per_count: f32,
    origin_rad: f32,
}

impl JointEncoder {
    /// A `bits`-wide counter (2..=32) of `counts_per_rev` counts per joint
    /// turn (the motor's counts times the transmission ratio), reading
    /// `origin_rad` (rad) where the counter reads `first_raw`.
    ///
    /// # Examples
    ///
    /// ```
    /// use twoport_control::linkage::JointEncoder;
    /// // A 2,000-count encoder on a motor geared 10:1 to its joint.
    /// let mut j = JointEncoder::new(16, 20_000.0, 0, 0.5).unwrap();
    /// let q = j.update(5_000).unwrap();
    /// assert!((q - (0.5 + core::f32::consts::FRAC_PI_2)).abs() < 1e-6);
    /// assert!(JointEncoder::new(16, 0.0, 0, 0.0).is_err());
    /// ```
    pub fn new(
        bits: u8,
        counts_per_rev: f32,
        first_raw: u32,
        origin_rad: f32,
    ) -> Result<Self, JointEncoderError> {
        let counts_per_rev = positive("joints.counts_per_rev", counts_per_rev)?;
        if !origin_rad.is_finite() {
            return Err(JointEncoderError::Param(ParamError {
                name: "joints.origin_rad (rad)",
                value: origin_rad,
                problem: "must be finite",
            }));
        }
        // One nanometre per count: the counter's position is its count.
        let counter = Encoder::new(bits, 1_000, first_raw, Position::ZERO)
            .map_err(JointEncoderError::Counter)?;
        Ok(JointEncoder {
            counter,
            rad_per_count: core::f32::consts::TAU / counts_per_rev,
            origin_rad,
        })
    }

    /// Take the counter's `raw` value; the joint angle (rad). A raw value
    /// wider than the counter is refused and the state is unchanged.
    #[inline(always)]
    pub fn update(&mut self, raw: u32) -> Result<f32, EncoderError> {
        let count = self.counter.update(raw)?.nm();
        Ok(self.origin_rad + count as f32 * self.rad_per_count)
    }

    /// The joint angle at the last read (rad).
    pub fn angle_rad(&self) -> f32 {
        self.origin_rad + self.counter.position().nm() as f32 * self.rad_per_count
    }

    /// Where the joint is now reads as `angle_rad` (rad) from this read on
    /// (homing's result).
    pub fn rezero(&mut self, angle_rad: f32) {
        self.counter.rezero(Position::ZERO);
        self.origin_rad = angle_rad;
    }

    /// One count (rad).
    pub fn rad_per_count(&self) -> f32 {
        self.rad_per_count
    }
}

/// Why a joint encoder's configuration was refused.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum JointEncoderError {
    /// A parameter out of its range.
    Param(ParamError),
    /// The counter's width or first value.
    Counter(EncoderError),
}

impl From<ParamError> for JointEncoderError {
    fn from(e: ParamError) -> Self {
        JointEncoderError::Param(e)
    }
}

impl core::fmt::Display for JointEncoderError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            JointEncoderError::Param(e) => e.fmt(f),
            JointEncoderError::Counter(e) => write!(f, "joint encoder counter: {e:?}"),
        }
    }
}

impl core::error::Error for JointEncoderError {}
