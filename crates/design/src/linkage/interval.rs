//! Closed intervals of reals with outward rounding: every operation's
//! result contains the exact result of the operation on any reals in its
//! operands. The workspace proof bounds the kinematics over a box of joint
//! angles with them.

use std::ops::{Add, Div, Mul, Neg, Sub};

/// `[lo, hi]`, possibly unbounded (`±∞` ends); `lo <= hi` unless a NaN got
/// in, which [`Interval::is_finite`] reports.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interval {
    /// The least value (may be `-∞`).
    pub lo: f64,
    /// The greatest value (may be `+∞`).
    pub hi: f64,
}

/// One unit in the last place down, unless the value is an exact result
/// (`exact`), or infinite.
fn down(x: f64, exact: bool) -> f64 {
    if exact {
        x
    } else {
        x.next_down()
    }
}

fn up(x: f64, exact: bool) -> f64 {
    if exact {
        x
    } else {
        x.next_up()
    }
}

/// A product of interval ends, with `0 · ∞ = 0` (an unbounded end stands
/// for large finite values, and zero times any of them is zero).
fn end_product(a: f64, b: f64) -> f64 {
    if a == 0.0 || b == 0.0 {
        0.0
    } else {
        a * b
    }
}

impl Interval {
    /// `[0, 0]`.
    pub const ZERO: Interval = Interval { lo: 0.0, hi: 0.0 };
    /// Every real.
    pub const ENTIRE: Interval = Interval {
        lo: f64::NEG_INFINITY,
        hi: f64::INFINITY,
    };

    /// The point `x` (exact).
    pub const fn point(x: f64) -> Self {
        Interval { lo: x, hi: x }
    }

    /// `[lo, hi]`.
    pub fn new(lo: f64, hi: f64) -> Self {
        Interval { lo, hi }
    }

    /// The midpoint (for choices, not bounds).
    pub fn mid(self) -> f64 {
        if self.lo.is_finite() && self.hi.is_finite() {
            0.5 * self.lo + 0.5 * self.hi
        } else if self.lo.is_finite() {
            self.lo
        } else {
            self.hi
        }
    }

    /// `max |x|` over the interval.
    pub fn mag(self) -> f64 {
        self.lo.abs().max(self.hi.abs())
    }

    /// Both ends finite and ordered.
    pub fn is_finite(self) -> bool {
        self.lo.is_finite() && self.hi.is_finite() && self.lo <= self.hi
    }

    /// The intersection with another enclosure of the same quantity:
    /// `self` where either has a NaN (an undefined value stays so) or
    /// where rounding leaves them apart.
    pub fn meet(self, o: Interval) -> Interval {
        let nan = |i: Interval| i.lo.is_nan() || i.hi.is_nan();
        if nan(self) || nan(o) {
            return self;
        }
        let (lo, hi) = (self.lo.max(o.lo), self.hi.min(o.hi));
        if lo <= hi {
            Interval { lo, hi }
        } else {
            self
        }
    }

    /// `[-d, d]`.
    pub fn span(d: f64) -> Interval {
        Interval { lo: -d, hi: d }
    }

    /// Whether 0 is inside.
    pub fn contains_zero(self) -> bool {
        self.lo <= 0.0 && self.hi >= 0.0
    }

    /// The interval widened by `ulps` units in the last place at each end:
    /// the bound on a library function's rounding.
    fn widen(self, ulps: u32) -> Self {
        let (mut lo, mut hi) = (self.lo, self.hi);
        for _ in 0..ulps {
            lo = lo.next_down();
            hi = hi.next_up();
        }
        Interval { lo, hi }
    }

    /// `1/x`.
    pub fn recip(self) -> Self {
        if self.contains_zero() || self.lo.is_nan() || self.hi.is_nan() {
            return Interval::ENTIRE;
        }
        Interval {
            lo: (1.0 / self.hi).next_down(),
            hi: (1.0 / self.lo).next_up(),
        }
    }

    /// `√x` over the non-negative part (the caller's check decides what a
    /// negative part means); NaN ends where all of it is negative.
    pub fn sqrt(self) -> Self {
        if self.hi < 0.0 || self.lo.is_nan() || self.hi.is_nan() {
            return Interval {
                lo: f64::NAN,
                hi: f64::NAN,
            };
        }
        let lo = self.lo.max(0.0);
        let s = lo.sqrt();
        Interval {
            lo: down(s, s * s == lo).max(0.0),
            hi: up(self.hi.sqrt(), false),
        }
    }

    /// `|x|`.
    pub fn abs(self) -> Self {
        if self.lo >= 0.0 {
            self
        } else if self.hi <= 0.0 {
            -self
        } else {
            Interval {
                lo: 0.0,
                hi: self.mag(),
            }
        }
    }

    /// `sin x` and `cos x` over the interval: libm's values at the ends,
    /// widened by two ulps and a hair for its rounding, and `±1` where an
    /// extremum lies inside (or within rounding of an end).
    pub fn sin_cos(self) -> (Self, Self) {
        use std::f64::consts::{FRAC_PI_2, PI, TAU};
        let unit = Interval::new(-1.0, 1.0);
        if !self.is_finite() || self.hi - self.lo >= TAU {
            return (unit, unit);
        }
        // An extremum of sin at π/2 + kπ, of cos at kπ: is one within the
        // interval, allowing for the rounding of kπ?
        let slack = 1e-12 * (1.0 + self.mag());
        let hits = |phase: f64| -> (bool, bool) {
            // Extrema at phase + kπ; k even a maximum, odd a minimum.
            let k0 = ((self.lo - slack - phase) / PI).ceil() as i64;
            let k1 = ((self.hi + slack - phase) / PI).floor() as i64;
            let (mut max, mut min) = (false, false);
            for k in k0..=k1.min(k0 + 2) {
                if k.rem_euclid(2) == 0 {
                    max = true;
                } else {
                    min = true;
                }
            }
            (max, min)
        };
        let range = |a: f64, b: f64, (max, min): (bool, bool)| {
            let e = 1e-300;
            let lo = if min { -1.0 } else { a.min(b) - e };
            let hi = if max { 1.0 } else { a.max(b) + e };
            let w = Interval::new(lo, hi).widen(2);
            Interval::new(w.lo.max(-1.0), w.hi.min(1.0))
        };
        let (s0, c0) = (self.lo.sin(), self.lo.cos());
        let (s1, c1) = (self.hi.sin(), self.hi.cos());
        (range(s0, s1, hits(FRAC_PI_2)), range(c0, c1, hits(0.0)))
    }
}

impl Add for Interval {
    type Output = Interval;
    fn add(self, o: Interval) -> Interval {
        // A sum that rounds to zero is exactly zero (subnormals).
        let (lo, hi) = (self.lo + o.lo, self.hi + o.hi);
        Interval {
            lo: down(lo, lo == 0.0),
            hi: up(hi, hi == 0.0),
        }
    }
}

impl Neg for Interval {
    type Output = Interval;
    fn neg(self) -> Interval {
        Interval {
            lo: -self.hi,
            hi: -self.lo,
        }
    }
}

impl Sub for Interval {
    type Output = Interval;
    fn sub(self, o: Interval) -> Interval {
        self + (-o)
    }
}

impl Mul for Interval {
    type Output = Interval;
    #[inline]
    fn mul(self, o: Interval) -> Interval {
        // Exact where an operand is the point zero (most partial
        // derivatives of a quantity of one joint are).
        if self == Interval::ZERO || o == Interval::ZERO {
            return Interval::ZERO;
        }
        let p = [
            end_product(self.lo, o.lo),
            end_product(self.lo, o.hi),
            end_product(self.hi, o.lo),
            end_product(self.hi, o.hi),
        ];
        if p.iter().any(|x| x.is_nan()) {
            return Interval {
                lo: f64::NAN,
                hi: f64::NAN,
            };
        }
        let lo = p.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = p.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        // One ulp out (which also covers a product that underflowed to
        // zero).
        Interval {
            lo: lo.next_down(),
            hi: hi.next_up(),
        }
    }
}

impl Div for Interval {
    type Output = Interval;
    fn div(self, o: Interval) -> Interval {
        if self == Interval::ZERO && !o.contains_zero() {
            return Interval::ZERO;
        }
        self * o.recip()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Sampled points of the operands land inside the result, for every
    /// operation, on intervals of both signs and straddling zero.
    #[test]
    fn operations_contain_every_sampled_result() {
        let boxes = [
            Interval::new(-2.0, -0.5),
            Interval::new(-0.3, 0.7),
            Interval::new(0.1, 3.0),
            Interval::new(1.0, 1.0),
            Interval::new(-7.0, 5.5),
        ];
        let pts = |i: Interval| (0..=20).map(move |k| i.lo + (i.hi - i.lo) * k as f64 / 20.0);
        let inside = |x: f64, i: Interval| x >= i.lo && x <= i.hi;
        for a in boxes {
            for x in pts(a) {
                let (s, c) = a.sin_cos();
                assert!(inside(x.sin(), s) && inside(x.cos(), c), "{a:?} at {x}");
                assert!(inside(x.abs(), a.abs()));
                if x >= 0.0 {
                    assert!(inside(x.sqrt(), a.sqrt()), "{a:?} at {x}");
                }
                for b in boxes {
                    for y in pts(b) {
                        assert!(inside(x + y, a + b));
                        assert!(inside(x - y, a - b));
                        assert!(inside(x * y, a * b));
                        if y != 0.0 {
                            assert!(inside(x / y, a / b), "{a:?}/{b:?} at {x}/{y}");
                        }
                    }
                }
            }
        }
    }

    /// Extrema inside an interval reach ±1; a narrow interval stays narrow.
    #[test]
    fn sine_and_cosine_find_their_extrema() {
        let (s, c) = Interval::new(1.0, 4.0).sin_cos();
        assert_eq!(s.hi, 1.0);
        assert_eq!(c.lo, -1.0);
        assert!(s.lo > -0.76 && s.lo < -0.75);
        let (s, _) = Interval::new(0.3, 0.3 + 1e-9).sin_cos();
        assert!(s.hi - s.lo < 2e-9);
        assert_eq!(Interval::new(-1.0, 1.0).recip(), Interval::ENTIRE);
    }
}
