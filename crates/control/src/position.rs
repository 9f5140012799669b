//! Absolute positions as integers, so that a loop running for hours never
//! accumulates f32 rounding in a position.
//!
//! A haptic loop turns velocities into positions every tick (the virtual
//! coupling's spring, the admittance display's position command, a VE's
//! proxy). Summing f32 metres drifts: after 10^7 ticks of 1 kHz the last bit
//! of an f32 near 0.3 m is 30 nm and rounding errors add up. Positions are
//! therefore `i64` picometres; only *differences* of positions, which are
//! small, become f32 metres.

use core::ops::{Add, Sub};

/// Picometres per metre.
pub const PM_PER_M: f32 = 1.0e12;
const M_PER_PM: f32 = 1.0e-12;

/// An absolute position along one device axis, in integer picometres
/// (1 pm = 1e-12 m). Range ±9.2e6 m; positive is the axis' positive direction.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Position(pub i64);

impl Position {
    /// The origin.
    pub const ZERO: Position = Position(0);

    /// A position from picometres.
    pub const fn from_pm(pm: i64) -> Self {
        Position(pm)
    }

    /// A position from metres, rounded to the nearest picometre.
    /// `None` for a non-finite value or one beyond ±9.2e6 m.
    /// Computed in f64 (1e12 is not an f32), so `from_m(0.25)` is exactly
    /// 2.5e11 pm; meant for configuration, not for the tick.
    pub fn from_m(m: f32) -> Option<Self> {
        let pm = m as f64 * 1.0e12;
        // 9.2e18 pm is just inside i64; `as` would saturate silently.
        if !pm.is_finite() || pm.abs() >= 9.2e18 {
            return None;
        }
        Some(Position(round_to_i64(pm)))
    }

    /// Picometres.
    pub const fn pm(self) -> i64 {
        self.0
    }

    /// This position in metres (f32: relative precision 6e-8 of the value).
    pub fn m(self) -> f32 {
        self.0 as f32 * M_PER_PM
    }

    /// `self - other` in metres, computed exactly in integers first, so a
    /// small difference of two large positions keeps full f32 precision.
    pub fn minus_m(self, other: Position) -> f32 {
        pm_to_f32(self.0.saturating_sub(other.0)) * M_PER_PM
    }

    /// This position moved by `delta_pm` picometres, saturating at the ends
    /// of the range instead of wrapping.
    pub const fn offset_pm(self, delta_pm: i64) -> Self {
        Position(self.0.saturating_add(delta_pm))
    }
}

impl Sub for Position {
    /// The difference in picometres (saturating).
    type Output = i64;
    fn sub(self, rhs: Position) -> i64 {
        self.0.saturating_sub(rhs.0)
    }
}

impl Add<i64> for Position {
    type Output = Position;
    fn add(self, rhs_pm: i64) -> Position {
        self.offset_pm(rhs_pm)
    }
}

/// `pm as f32`, exactly, without the `i64` conversion a 32-bit core makes a
/// library call of ~37 instructions. Split `pm = hi 2^24 + lo` with
/// `0 <= lo < 2^24`: both halves convert exactly (one instruction each on
/// the FPU), `hi 2^24` is exact, and the one rounding of the sum is IEEE
/// round-to-nearest-even of the exact value, which is what `as` does.
/// (A `try_from::<i32>` fast path does not survive LLVM, which sees both
/// branches compute the same value and keeps the library call.)
///
/// On a 64-bit host the one-instruction `as` is the faster way to the same
/// bits; the split is for 32-bit cores.
#[cfg(target_pointer_width = "64")]
#[inline]
pub(crate) fn pm_to_f32(pm: i64) -> f32 {
    pm as f32
}

/// See the 64-bit version: the split path, the same bits.
#[cfg(not(target_pointer_width = "64"))]
#[inline]
pub(crate) fn pm_to_f32(pm: i64) -> f32 {
    pm_to_f32_split(pm)
}

#[cfg_attr(target_pointer_width = "64", allow(dead_code))]
#[inline]
fn pm_to_f32_split(pm: i64) -> f32 {
    const TWO_24: f32 = 16_777_216.0;
    let hi = pm >> 24;
    if (-(1 << 23)..(1 << 23)).contains(&hi) {
        let lo = (pm & 0x00FF_FFFF) as i32;
        hi as i32 as f32 * TWO_24 + lo as f32
    } else {
        // Beyond 140 m: the library conversion.
        pm as f32
    }
}

/// `x as i64` (toward zero, saturating) for a finite `x`: on a 32-bit core
/// through `i32` when it fits, for the same reason as [`pm_to_f32`] (this
/// fast path does survive LLVM); on a 64-bit host `as` is one instruction.
#[inline]
fn f32_to_pm(x: f32) -> i64 {
    if cfg!(target_pointer_width = "64") || x.abs() >= 2.0e9 {
        x as i64
    } else {
        x as i32 as i64
    }
}

/// Round half away from zero; `as` saturates and maps NaN to 0, so this
/// cannot panic. Only called on finite, in-range values.
fn round_to_i64(x: f64) -> i64 {
    let t = x as i64; // toward zero
    let frac = x - t as f64;
    if frac >= 0.5 {
        t + 1
    } else if frac <= -0.5 {
        t - 1
    } else {
        t
    }
}

/// The discrete integrator `T / (1 - z^-1)`: `x[k] = x[k-1] + T v[k]`, kept as
/// an integer [`Position`] with the sub-picometre remainder carried to the
/// next tick, so the sum of any number of increments is exact to 1 pm plus
/// the f32 rounding of each `v T` product itself.
///
/// This is the velocity-to-position step of the admittance display's position
/// command and of the virtual couplings' VE side.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Integrator {
    position: Position,
    /// Remainder below one picometre, in picometres, |r| < 1.
    remainder_pm: f32,
    /// `T` in picometres per (m/s): `v [m/s] * pm_per_mps` is the step in pm.
    pm_per_mps: f32,
    period_s: f32,
}

impl Integrator {
    /// An integrator at `start` for sample period `period_s` (s).
    pub fn new(period_s: f32, start: Position) -> Self {
        Integrator {
            position: start,
            remainder_pm: 0.0,
            pm_per_mps: period_s * PM_PER_M,
            period_s,
        }
    }

    /// Move to `x` and forget the remainder.
    pub fn reset(&mut self, x: Position) {
        self.position = x;
        self.remainder_pm = 0.0;
    }

    /// `x[k] = x[k-1] + T v[k]`; returns `x[k]`. A non-finite `v` is ignored
    /// (the position holds) so that state can never become poisoned; the
    /// safety layer reports the fault that produced it.
    pub fn step(&mut self, velocity_mps: f32) -> Position {
        let d = velocity_mps * self.pm_per_mps + self.remainder_pm;
        if !d.is_finite() || d.abs() >= 9.2e18 {
            return self.position;
        }
        let whole = f32_to_pm(d); // toward zero
        self.remainder_pm = d - pm_to_f32(whole);
        self.position = self.position.offset_pm(whole);
        self.position
    }

    /// The current position `x[k]`.
    pub fn position(&self) -> Position {
        self.position
    }

    /// The sample period `T` (s).
    pub fn period_s(&self) -> f32 {
        self.period_s
    }

    /// `X(z)/V(z) = T / (1 - z^-1)` (m per m/s), with the `T` this
    /// integrator really adds per (m/s) (the f32 product `T * 1e12`).
    pub fn tf(&self) -> crate::ZTransfer {
        let t = self.pm_per_mps as f64 * 1.0e-12;
        crate::ZTransfer::first_order([t, 0.0], -1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn from_m_rounds_and_rejects_non_finite() {
        assert_eq!(Position::from_m(1.0e-6).unwrap().pm(), 1_000_000);
        assert_eq!(Position::from_m(-0.25).unwrap().pm(), -250_000_000_000);
        assert!(Position::from_m(f32::NAN).is_none());
        assert!(Position::from_m(f32::INFINITY).is_none());
        assert!(Position::from_m(1.0e7).is_none());
    }

    #[test]
    fn the_split_conversion_equals_as_f32_bit_for_bit() {
        // Ties, carries across the split, both signs, every magnitude.
        let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
        // The split path is what a 32-bit board runs; test it on the host.
        let check = |pm: i64| {
            assert_eq!(pm_to_f32_split(pm).to_bits(), (pm as f32).to_bits(), "{pm}");
        };
        for e in 0..63 {
            for d in [-2i64, -1, 0, 1, 2] {
                let v = (1i64 << e).saturating_add(d);
                check(v);
                check(-v);
                check(v | 0x80_0000);
            }
        }
        for _ in 0..200_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let shift = (x % 64) as u32;
            check((x as i64) >> shift);
        }
        check(i64::MIN);
        check(i64::MAX);
        // Exact ties at 2^24 + 1 and its multiples round to even.
        check((1 << 24) + 1);
        check((1 << 25) + 2);
        check((3 << 40) + (1 << 16));
    }

    #[test]
    fn difference_of_large_positions_keeps_precision() {
        // 1000 km apart from the origin, 1 nm apart from each other.
        let a = Position::from_pm(1_000_000_000_000_000_000);
        let b = a + 1000;
        assert_eq!(b.minus_m(a), 1.0e-9);
    }

    #[test]
    fn integrator_sum_is_exact_over_many_small_steps() {
        // 0.3 pm per tick never moves an integer-only integrator; with the
        // carried remainder 10^6 ticks move it by 300,000 pm (±1).
        let mut x = Integrator::new(1.0e-3, Position::ZERO);
        for _ in 0..1_000_000 {
            x.step(0.3e-9);
        }
        assert!(
            (x.position().pm() - 300_000).abs() <= 1,
            "{:?}",
            x.position()
        );
    }

    #[test]
    fn integrator_ignores_non_finite_velocity() {
        let mut x = Integrator::new(1.0e-3, Position::from_pm(5));
        x.step(f32::NAN);
        x.step(f32::INFINITY);
        assert_eq!(x.position(), Position::from_pm(5));
        x.step(1.0);
        // T = 1 ms in f32 is 1.0000000475e-3 s; in pm per (m/s) it rounds
        // to the f32 nearest 1.0000000475e9.
        assert_eq!(x.position().pm(), 5 + (1.0e-3f32 * PM_PER_M) as i64);
    }
}
