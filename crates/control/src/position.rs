//! Absolute positions as integers, so that a loop running for hours never
//! accumulates f32 rounding in a position.
//!
//! A haptic loop turns velocities into positions every tick (the virtual
//! coupling's spring, the admittance display's position command, a VE's
//! proxy). Summing f32 metres drifts: after 10^7 ticks of 1 kHz the last bit
//! of an f32 near 0.3 m is 30 nm and rounding errors add up. Positions are
//! therefore integer nanometres, and each integrator carries the part of a
//! step below one nanometre to the next tick; only *differences* of
//! positions, which are small, become f32 metres.
//!
//! Why `i32` nanometres: it is the width of the Cortex-M4F, so adding,
//! subtracting and saturating a position is one instruction (`qadd`,
//! `qsub`) and converting a difference to f32 is one more (`vcvt`). The
//! first version used `i64` picometres; its two-word arithmetic and
//! conversions were 200 of the board tick's 530 instructions. The price is
//! range: ±2.147 m, which holds every desk-top haptic workspace with room to
//! spare; a VE point driven past it stops at the end of the range
//! (saturation) instead of wrapping.

use crate::Real;
use core::ops::{Add, Sub};

/// Nanometres per metre.
pub const NM_PER_M: f32 = 1.0e9;

/// An absolute position along one device axis, in integer nanometres
/// (1 nm = 1e-9 m). Range ±2.147 m (`i32`); arithmetic saturates at the
/// ends. Positive is the axis' positive direction.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Position(pub i32);

impl Position {
    /// The origin.
    pub const ZERO: Position = Position(0);
    /// The most positive position, 2.147483647 m.
    pub const MAX: Position = Position(i32::MAX);
    /// The most negative position, -2.147483648 m.
    pub const MIN: Position = Position(i32::MIN);

    /// A position from nanometres.
    pub const fn from_nm(nm: i32) -> Self {
        Position(nm)
    }

    /// A position from metres, rounded to the nearest nanometre.
    /// `None` for a non-finite value or one beyond the range (±2.147 m).
    /// Computed in f64 (1e9 is not an f32), so `from_m(0.25)` is exactly
    /// 2.5e8 nm; meant for configuration, not for the tick.
    pub fn from_m(m: f32) -> Option<Self> {
        Self::from_m_f64(m as f64)
    }

    /// [`Position::from_m`] for an f64 in metres.
    pub fn from_m_f64(m: f64) -> Option<Self> {
        let nm = m * 1.0e9;
        if !nm.is_finite() || nm.abs() > i32::MAX as f64 {
            return None;
        }
        Some(Position(round_half_away(nm) as i32))
    }

    /// Nanometres.
    pub const fn nm(self) -> i32 {
        self.0
    }

    /// This position in metres (f32: relative precision 6e-8 of the value).
    pub fn m(self) -> f32 {
        self.0 as f32 * 1.0e-9
    }

    /// `self - other` in metres, computed in integers first, so a small
    /// difference of two large positions keeps full f32 precision (exact
    /// below 2^24 nm = 16.7 mm, one rounding beyond).
    #[inline]
    pub fn minus_m(self, other: Position) -> f32 {
        (self - other) as f32 * 1.0e-9
    }

    /// `self - from` in nanometres as an `R`, rounded once: the exact
    /// difference converted. On a 64-bit machine the difference of two
    /// `i32`s is exact in an `i64` and converts in one instruction; on a
    /// 32-bit core it saturates to `i32` first (one `qsub`), which changes
    /// nothing closer than 2.147 m. The tick's position differences (the
    /// velocity estimate, the springs' stretches) all go through here.
    #[inline]
    pub fn nm_from<R: Real>(self, from: Position) -> R {
        #[cfg(target_pointer_width = "64")]
        let d = R::from_i64(self.0 as i64 - from.0 as i64);
        #[cfg(not(target_pointer_width = "64"))]
        let d = R::from_i32(self - from);
        d
    }

    /// This position moved by `delta_nm` nanometres, saturating at the ends
    /// of the range instead of wrapping.
    #[inline]
    pub const fn offset_nm(self, delta_nm: i32) -> Self {
        Position(self.0.saturating_add(delta_nm))
    }
}

impl Sub for Position {
    /// The difference in nanometres (saturating).
    type Output = i32;
    #[inline]
    fn sub(self, rhs: Position) -> i32 {
        self.0.saturating_sub(rhs.0)
    }
}

impl Add<i32> for Position {
    type Output = Position;
    fn add(self, rhs_nm: i32) -> Position {
        self.offset_nm(rhs_nm)
    }
}

/// Round half away from zero (configuration only; `f64::round` is not in
/// `core`). The caller has checked that `x` is finite and in range.
fn round_half_away(x: f64) -> f64 {
    let t = x as i64 as f64; // toward zero, exact below 2^53
    let frac = x - t;
    if frac >= 0.5 {
        t + 1.0
    } else if frac <= -0.5 {
        t - 1.0
    } else {
        t
    }
}

/// The discrete integrator `T / (1 - z^-1)`: `x[k] = x[k-1] + T v[k]`, kept as
/// an integer [`Position`] with the sub-nanometre remainder carried to the
/// next tick, so the sum of any number of increments is exact to 1 nm plus
/// the f32 rounding of each `v T` product itself.
///
/// This is the velocity-to-position step of the admittance display's position
/// command and of every VE point (the impedance coupling's spring acts on
/// the VE's).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Integrator<R = f32> {
    position: Position,
    /// Remainder below one nanometre, in nanometres, |r| < 1.
    remainder_nm: R,
    /// `T` in nanometres per (m/s): `v [m/s] * nm_per_mps` is the step in nm.
    nm_per_mps: R,
    period_s: f32,
}

impl Integrator {
    /// An integrator at `start` for sample period `period_s` (s).
    pub fn new(period_s: f32, start: Position) -> Self {
        Self::new_in(period_s, start)
    }
}

impl<R: Real> Integrator<R> {
    /// [`Integrator::new`] computing in `R`.
    pub fn new_in(period_s: f32, start: Position) -> Self {
        Integrator {
            position: start,
            remainder_nm: R::ZERO,
            nm_per_mps: R::of(period_s) * R::NM_PER_M,
            period_s,
        }
    }

    /// Move to `x` and forget the remainder.
    pub fn reset(&mut self, x: Position) {
        self.position = x;
        self.remainder_nm = R::ZERO;
    }

    /// `x[k] = x[k-1] + T v[k]`; returns `x[k]`. A non-finite `v` (or a step
    /// beyond the whole range) is ignored, the position holds, so that state
    /// can never become poisoned; the safety layer reports the fault that
    /// produced it.
    #[inline]
    pub fn step(&mut self, velocity_mps: R) -> Position {
        self.step_unsplit(velocity_mps);
        self.position
    }

    /// [`step`](Self::step), answering with the new state before it is
    /// split into whole and sub-nanometre parts: the position before this
    /// step and the step plus the carried remainder (nm), whose sum is
    /// `x[k]`. A law that reads `x[k]` in the same tick can start from it
    /// at once instead of waiting for the split (the admittance display's
    /// regulator). An ignored step answers with [`exact`](Self::exact).
    #[inline]
    pub fn step_unsplit(&mut self, velocity_mps: R) -> (Position, R) {
        let start = self.position;
        let d = velocity_mps * self.nm_per_mps + self.remainder_nm;
        // One comparison rejects NaN, infinities and steps beyond i32.
        if d.abs() < R::of(2.0e9) {
            let whole = d.trunc_i32(); // toward zero: one `vcvt`
            self.remainder_nm = d - R::from_i32(whole);
            self.position = self.position.offset_nm(whole);
            (start, d)
        } else {
            self.exact()
        }
    }

    /// The current position `x[k]`, to the nanometre below the exact sum
    /// (the remainder is not in it).
    pub fn position(&self) -> Position {
        self.position
    }

    /// The exact state: the position and the remainder (nm, |r| < 1) that
    /// the integer position leaves out.
    #[inline]
    pub fn exact(&self) -> (Position, R) {
        (self.position, self.remainder_nm)
    }

    /// `x[k] - from` in metres, with the sub-nanometre remainder: the exact
    /// integrator state, for laws whose force depends on it (a 5e6 N/m spring
    /// would otherwise see the 1 nm steps as 5 mN of force ripple).
    #[inline]
    pub fn offset_m(&self, from: Position) -> R {
        (self.position.nm_from::<R>(from) + self.remainder_nm) * R::M_PER_NM
    }

    /// The sample period `T` (s).
    pub fn period_s(&self) -> f32 {
        self.period_s
    }

    /// `X(z)/V(z) = T / (1 - z^-1)` (m per m/s), with the `T` this
    /// integrator really adds per (m/s) (the f32 product `T * 1e9`).
    pub fn tf(&self) -> crate::ZTransfer {
        let t = self.nm_per_mps.to_f64() * 1.0e-9;
        crate::ZTransfer::first_order([t, 0.0], -1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn from_m_rounds_and_rejects_non_finite_and_out_of_range() {
        assert_eq!(Position::from_m(1.0e-6).unwrap().nm(), 1_000);
        assert_eq!(Position::from_m(-0.25).unwrap().nm(), -250_000_000);
        assert_eq!(Position::from_m_f64(2.5e-9).unwrap().nm(), 3);
        assert_eq!(Position::from_m_f64(-2.5e-9).unwrap().nm(), -3);
        assert!(Position::from_m(f32::NAN).is_none());
        assert!(Position::from_m(f32::INFINITY).is_none());
        assert!(Position::from_m(2.2).is_none());
        assert!(Position::from_m(-2.2).is_none());
        assert_eq!(Position::from_m_f64(2.147483647), Some(Position::MAX));
    }

    #[test]
    fn arithmetic_saturates_at_the_ends_of_the_range() {
        assert_eq!(Position::MAX + 1, Position::MAX);
        assert_eq!(Position::MIN + -1, Position::MIN);
        assert_eq!(Position::MAX - Position::MIN, i32::MAX);
        assert_eq!(Position::MIN.minus_m(Position::MAX), i32::MIN as f32 * 1e-9);
    }

    #[test]
    fn nm_from_is_the_difference_rounded_once() {
        let (a, b) = (Position::from_nm(1_234_567_891), Position::from_nm(-7));
        assert_eq!(a.nm_from::<f64>(b), 1_234_567_898.0);
        assert_eq!(a.nm_from::<f32>(b), 1_234_567_898.0f64 as f32);
        assert_eq!(b.nm_from::<f32>(a), -1_234_567_898.0f64 as f32);
        // Beyond i32: exact on a 64-bit host, saturated on a 32-bit core.
        let far = Position::MAX.nm_from::<f64>(Position::MIN);
        #[cfg(target_pointer_width = "64")]
        assert_eq!(far, 4_294_967_295.0);
        #[cfg(not(target_pointer_width = "64"))]
        assert_eq!(far, i32::MAX as f64);
    }

    #[test]
    fn difference_of_large_positions_keeps_precision() {
        // 2 m from the origin, 1 nm apart from each other.
        let a = Position::from_nm(2_000_000_000);
        let b = a + 1;
        assert_eq!(b.minus_m(a), 1.0e-9);
        assert_eq!(a.minus_m(b), -1.0e-9);
    }

    #[test]
    fn integrator_sum_is_exact_over_many_small_steps() {
        // 0.3 nm per tick never moves an integer-only integrator; with the
        // carried remainder 10^6 ticks move it by 300,000 nm (±1).
        let mut x = Integrator::new(1.0e-3, Position::ZERO);
        for _ in 0..1_000_000 {
            x.step(0.3e-6);
        }
        assert!(
            (x.position().nm() - 300_000).abs() <= 1,
            "{:?}",
            x.position()
        );
    }

    /// The unsplit answer is the same point as the split state: the start
    /// plus the step equals the new position plus its remainder, in f64,
    /// to the f32 rounding of the step; an ignored step answers with the
    /// state it kept.
    #[test]
    fn unsplit_step_is_the_same_point_as_the_split_state() {
        let mut x = Integrator::new(1.0e-3, Position::from_nm(-7));
        for k in 0..10_000 {
            let v = 0.37 * ((k as f32) * 0.01).sin() + 1e-7;
            let (start, d) = x.step_unsplit(v);
            let (p, r) = x.exact();
            let (a, b) = (start.nm() as f64 + d as f64, p.nm() as f64 + r as f64);
            assert!(
                (a - b).abs() <= d.abs() as f64 * 1.2e-7 + 1e-9,
                "{a} vs {b}"
            );
            assert!(r.abs() < 1.0);
        }
        let kept = x.exact();
        assert_eq!(x.step_unsplit(f32::NAN), kept);
        assert_eq!(x.exact(), kept);
    }

    #[test]
    fn integrator_ignores_non_finite_velocity_and_saturates() {
        let mut x = Integrator::new(1.0e-3, Position::from_nm(5));
        x.step(f32::NAN);
        x.step(f32::INFINITY);
        x.step(-1.0e7); // 1e10 nm in one tick: beyond the range, ignored
        assert_eq!(x.position(), Position::from_nm(5));
        x.step(1.0);
        // T = 1 ms in f32 is 1.0000000475e-3 s; in nm per (m/s) it rounds
        // to the f32 nearest 1.0000000475e6.
        assert_eq!(x.position().nm(), 5 + (1.0e-3f32 * NM_PER_M) as i32);
        // 1000 m/s for 3 ticks runs into the end of the range and stays.
        for _ in 0..3 {
            x.step(1000.0);
        }
        assert_eq!(x.position(), Position::MAX);
    }
}
