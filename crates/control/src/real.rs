//! The float type a law computes in: `f32` on the board, `f64` where a
//! simulation wants to see what the board's rounding costs.
//!
//! Every law is written once, generic over [`Real`], and its plain name is
//! the `f32` law the board runs (`ImpedanceCoupling` is
//! `ImpedanceCoupling<f32>`). Parameters (gains, periods, limits) are `f32`
//! in both, so an `f64` law runs exactly the gains the designer checked and
//! differs from the board's only in the arithmetic of its signals and state.

use core::fmt::Debug;
use core::ops::{Add, AddAssign, Div, Mul, Neg, Sub};

/// `f32` or `f64`: what the laws need of a float.
pub trait Real:
    Copy
    + Default
    + Debug
    + PartialEq
    + PartialOrd
    + Add<Output = Self>
    + AddAssign
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + Send
    + Sync
    + 'static
{
    /// 0.
    const ZERO: Self;
    /// 1.
    const ONE: Self;
    /// 1/2.
    const HALF: Self;
    /// Metres per nanometre (1e-9).
    const M_PER_NM: Self;
    /// Nanometres per metre (1e9).
    const NM_PER_M: Self;

    /// A parameter or reading given in `f32`, exactly.
    fn of(x: f32) -> Self;
    /// Rounded to `f32` (exact for `f32`).
    fn to_f32(self) -> f32;
    /// Widened to `f64`, exactly.
    fn to_f64(self) -> f64;
    /// An integer, rounded to nearest (exact below 2^24 for `f32`).
    fn from_i32(i: i32) -> Self;
    /// `i` rounded to the nearest value (one conversion on a 64-bit host;
    /// a library call on a 32-bit core, where nothing in the tick uses it).
    fn from_i64(i: i64) -> Self;
    /// Toward zero, saturating, NaN to 0 (one `vcvt` on the M4F).
    fn trunc_i32(self) -> i32;
    /// `|self|`.
    fn abs(self) -> Self;
    /// Neither NaN nor infinite.
    fn is_finite(self) -> bool;
    /// `sin(self)` (self in rad).
    fn sin(self) -> Self;
    /// `cos(self)` (self in rad).
    fn cos(self) -> Self;
    /// `(sin(self), cos(self))` (self in rad): in f32 arithmetic for
    /// `f32` (see the kinematics), libm's for `f64`.
    fn sin_cos(self) -> (Self, Self);
    /// `√self` (NaN below 0).
    fn sqrt(self) -> Self;
    /// The angle of `(x, self)` (rad, in `[-π, π]`).
    fn atan2(self, x: Self) -> Self;

    /// `self` within `±limit` (a NaN passes through, for the safety layer
    /// downstream to refuse).
    #[inline(always)]
    fn within(self, limit: Self) -> Self {
        if self > limit {
            limit
        } else if self < -limit {
            -limit
        } else {
            self
        }
    }

    /// `self`, at most `cap` (a NaN gives `cap`).
    #[inline(always)]
    fn at_most(self, cap: Self) -> Self {
        if self < cap {
            self
        } else {
            cap
        }
    }
}

macro_rules! real {
    ($t:ty, $sin:path, $cos:path, $sin_cos:path, $sqrt:path, $atan2:path) => {
        impl Real for $t {
            const ZERO: Self = 0.0;
            const ONE: Self = 1.0;
            const HALF: Self = 0.5;
            const M_PER_NM: Self = 1.0e-9;
            const NM_PER_M: Self = 1.0e9;
            #[inline]
            fn of(x: f32) -> Self {
                x as $t
            }
            #[inline]
            fn to_f32(self) -> f32 {
                self as f32
            }
            #[inline]
            fn to_f64(self) -> f64 {
                self as f64
            }
            #[inline]
            fn from_i32(i: i32) -> Self {
                i as $t
            }
            #[inline]
            fn from_i64(i: i64) -> Self {
                i as $t
            }
            #[inline]
            fn trunc_i32(self) -> i32 {
                self as i32
            }
            #[inline]
            fn abs(self) -> Self {
                <$t>::abs(self)
            }
            #[inline]
            fn is_finite(self) -> bool {
                <$t>::is_finite(self)
            }
            #[inline]
            fn sin(self) -> Self {
                $sin(self)
            }
            #[inline]
            fn cos(self) -> Self {
                $cos(self)
            }
            #[inline]
            fn sin_cos(self) -> (Self, Self) {
                $sin_cos(self)
            }
            #[inline]
            fn sqrt(self) -> Self {
                $sqrt(self)
            }
            #[inline]
            fn atan2(self, x: Self) -> Self {
                $atan2(self, x)
            }
        }
    };
}

real!(
    f32,
    libm::sinf,
    libm::cosf,
    crate::trig::sin_cos_f32,
    crate::root::sqrt_f32,
    libm::atan2f
);
real!(
    f64,
    libm::sin,
    libm::cos,
    sin_cos_f64,
    libm::sqrt,
    libm::atan2
);

fn sin_cos_f64(x: f64) -> (f64, f64) {
    (libm::sin(x), libm::cos(x))
}
