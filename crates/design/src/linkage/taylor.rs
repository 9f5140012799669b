//! A quantity's value, gradient and Hessian with respect to the joint
//! angles, each enclosed over a box of angles: second-order forward-mode
//! differentiation in interval arithmetic.
//!
//! It implements the control crate's [`Real`], so the workspace proof runs
//! the board's own kinematics over a box and gets enclosures of the
//! Jacobian and of its first and second derivatives there, with no second
//! copy of the kinematics to drift from the first. A comparison (`<`,
//! `>=` ...) is true where it holds for some point of the operands: the
//! kinematics write each check as a clearance (`if !clear { fault }`), so a
//! box that may be clear goes on (its bound then covers some refused poses
//! too, which only loosens it), and a box that faults is refused at every
//! pose in it.
//!
//! Each quantity also carries its value and gradient at the box's centre.
//! After every operation the box's enclosures are cut by Taylor's theorem
//! about the centre (the gradient by the Hessian's enclosure, the value
//! by the gradient's and the Hessian's): interval arithmetic alone loses
//! the dependence between operands at every step, and along a long chain
//! (the delta's closed-form kinematics) the loss compounds; the centred
//! forms lose only second-order terms, so a small box stays tight.

use super::interval::Interval;
use std::cmp::Ordering;
use std::ops::{Add, AddAssign, Div, Mul, Neg, Sub};
use twoport_control::Real;

/// Value, gradient and Hessian over a box of `N` joint angles.
#[derive(Clone, Copy, Debug)]
pub struct Taylor<const N: usize> {
    /// The value.
    pub v: Interval,
    /// `∂/∂q_k`.
    pub g: [Interval; N],
    /// `∂²/∂q_k ∂q_l` (symmetric).
    pub h: [[Interval; N]; N],
    /// The value at the box's centre.
    pub vc: Interval,
    /// The gradient at the box's centre.
    pub gc: [Interval; N],
    /// The box's half-widths (rad) in the joints the quantity depends on,
    /// `0` in the others.
    half: [f64; N],
}

impl<const N: usize> Taylor<N> {
    /// A constant.
    pub const fn constant(x: Interval) -> Self {
        Taylor {
            v: x,
            g: [Interval::ZERO; N],
            h: [[Interval::ZERO; N]; N],
            vc: x,
            gc: [Interval::ZERO; N],
            half: [0.0; N],
        }
    }

    /// Joint `k` over `[centre - half, centre + half]` (rad): its gradient
    /// is the unit vector `e_k`.
    pub fn variable(k: usize, centre: f64, half: f64) -> Self {
        let mut t = Self::constant(Interval::new(centre - half, centre + half));
        // (The ends rounded outward: the box holds the exact interval.)
        if half > 0.0 {
            t.v = Interval::new((centre - half).next_down(), (centre + half).next_up());
        }
        t.vc = Interval::point(centre);
        t.g[k] = Interval::point(1.0);
        t.gc[k] = Interval::point(1.0);
        t.half[k] = half;
        t
    }

    /// The half-widths of a result of `self` and `o`.
    fn halves(&self, o: &Self) -> [f64; N] {
        core::array::from_fn(|k| self.half[k].max(o.half[k]))
    }

    /// Cut the box's gradient and value by the centred forms
    /// `g(c + Δ) = g(c) + H(ξ) Δ` and `f(c + Δ) = f(c) + g(c)·Δ +
    /// ½ Δ^T H(ξ) Δ` (and `f(c) + g(ξ)·Δ`), `ξ` in the box. A product with
    /// `Δ_k ∈ [-d_k, d_k]` is symmetric, so each form is the centre's
    /// enclosure plus `[-ρ, ρ]` for a radius `ρ` summed in scalars (and a
    /// one-signed part from the Hessian's diagonal, `Δ_k² ≥ 0`).
    fn tighten(mut self) -> Self {
        let d = self.half;
        // (A NaN anywhere cuts nothing: `min` and `max` would pass it over.)
        let nan = |i: &Interval| i.lo.is_nan() || i.hi.is_nan();
        if d.iter().all(|&x| x == 0.0)
            || nan(&self.vc)
            || self.gc.iter().chain(&self.g).any(nan)
            || self.h.iter().flatten().any(nan)
        {
            return self;
        }
        // A sum of n non-negative products rounded to nearest is within
        // (n + 1) ε of the exact one: 1e-12 covers it many times over.
        let up = |x: f64| (x * (1.0 + 1e-12)).next_up();
        for k in 0..N {
            let rho: f64 = (0..N).map(|l| self.h[k][l].mag() * d[l]).sum();
            self.g[k] = self.g[k].meet(self.gc[k] + Interval::span(up(rho)));
        }
        let (mut first, mut second) = (0.0, 0.0);
        let (mut below, mut above) = (0.0, 0.0);
        for k in 0..N {
            first += self.g[k].mag() * d[k];
            second += self.gc[k].mag() * d[k];
            let dk2 = 0.5 * d[k] * d[k];
            below += self.h[k][k].lo.min(0.0) * dk2;
            above += self.h[k][k].hi.max(0.0) * dk2;
            for l in 0..N {
                if l != k {
                    second += 0.5 * self.h[k][l].mag() * d[k] * d[l];
                }
            }
        }
        let diagonal = Interval::new(-up(-below), up(above));
        let first = self.vc + Interval::span(up(first));
        let second = self.vc + Interval::span(up(second)) + diagonal;
        self.v = self.v.meet(first).meet(second);
        self
    }

    /// Whether the quantity is a constant: a product or sum with it loses
    /// no dependence.
    fn is_constant(&self) -> bool {
        self.half.iter().all(|&d| d == 0.0) && self.g.iter().all(|g| *g == Interval::ZERO)
    }

    /// `f(self)` given `f`, `f'` and `f''` enclosed over the value's range
    /// and `f`, `f'` at the centre's value.
    fn chain(self, over: [Interval; 3], at: [Interval; 2]) -> Self {
        let [f, d1, d2] = over;
        let mut out = Self::constant(f);
        out.vc = at[0];
        out.half = self.half;
        for k in 0..N {
            out.g[k] = d1 * self.g[k];
            out.gc[k] = at[1] * self.gc[k];
            let d2g = d2 * self.g[k];
            for l in k..N {
                out.h[k][l] = d2g * self.g[l] + d1 * self.h[k][l];
                out.h[l][k] = out.h[k][l];
            }
        }
        out.tighten()
    }

    fn recip(self) -> Self {
        let r = self.v.recip();
        let r2 = r * r;
        let rc = self.vc.recip();
        self.chain([r, -r2, Interval::point(2.0) * r2 * r], [rc, -(rc * rc)])
    }
}

impl<const N: usize> PartialEq for Taylor<N> {
    /// The same enclosures (the box's size aside: a constant equals the
    /// same constant made from a variable, as `x · 0` is `0`).
    fn eq(&self, o: &Self) -> bool {
        (self.v, self.g, self.h, self.vc, self.gc) == (o.v, o.g, o.h, o.vc, o.gc)
    }
}

impl<const N: usize> Default for Taylor<N> {
    fn default() -> Self {
        Self::constant(Interval::ZERO)
    }
}

impl<const N: usize> From<f64> for Taylor<N> {
    fn from(x: f64) -> Self {
        Self::constant(Interval::point(x))
    }
}

impl<const N: usize> Add for Taylor<N> {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        if o.is_constant() {
            let mut out = self;
            (out.v, out.vc) = (self.v + o.v, self.vc + o.v);
            return out;
        }
        if self.is_constant() {
            return o + self;
        }
        let mut out = self;
        out.v = self.v + o.v;
        out.vc = self.vc + o.vc;
        out.half = self.halves(&o);
        for k in 0..N {
            out.g[k] = self.g[k] + o.g[k];
            out.gc[k] = self.gc[k] + o.gc[k];
            for l in k..N {
                out.h[k][l] = self.h[k][l] + o.h[k][l];
                out.h[l][k] = out.h[k][l];
            }
        }
        out.tighten()
    }
}

impl<const N: usize> AddAssign for Taylor<N> {
    fn add_assign(&mut self, o: Self) {
        *self = *self + o;
    }
}

impl<const N: usize> Neg for Taylor<N> {
    type Output = Self;
    fn neg(self) -> Self {
        let mut out = self;
        out.v = -self.v;
        out.vc = -self.vc;
        for k in 0..N {
            out.g[k] = -self.g[k];
            out.gc[k] = -self.gc[k];
            for l in 0..N {
                out.h[k][l] = -self.h[k][l];
            }
        }
        out
    }
}

impl<const N: usize> Sub for Taylor<N> {
    type Output = Self;
    fn sub(self, o: Self) -> Self {
        self + (-o)
    }
}

impl<const N: usize> Mul for Taylor<N> {
    type Output = Self;
    fn mul(self, o: Self) -> Self {
        if o.is_constant() {
            // (Scaling keeps each enclosure as tight as it was.)
            let c = o.v;
            let mut out = self;
            (out.v, out.vc) = (self.v * c, self.vc * o.vc);
            for k in 0..N {
                out.g[k] = self.g[k] * c;
                out.gc[k] = self.gc[k] * c;
                for l in k..N {
                    out.h[k][l] = self.h[k][l] * c;
                    out.h[l][k] = out.h[k][l];
                }
            }
            return out;
        }
        if self.is_constant() {
            return o * self;
        }
        let mut out = Self::constant(self.v * o.v);
        out.vc = self.vc * o.vc;
        out.half = self.halves(&o);
        for k in 0..N {
            out.g[k] = self.g[k] * o.v + self.v * o.g[k];
            out.gc[k] = self.gc[k] * o.vc + self.vc * o.gc[k];
            for l in k..N {
                out.h[k][l] = self.h[k][l] * o.v
                    + self.g[k] * o.g[l]
                    + self.g[l] * o.g[k]
                    + self.v * o.h[k][l];
                out.h[l][k] = out.h[k][l];
            }
        }
        out.tighten()
    }
}

impl<const N: usize> Div for Taylor<N> {
    type Output = Self;
    // (Division is the product with the reciprocal, whose derivatives are
    // closed-form.)
    #[allow(clippy::suspicious_arithmetic_impl)]
    fn div(self, o: Self) -> Self {
        self * o.recip()
    }
}

impl<const N: usize> PartialOrd for Taylor<N> {
    /// Ordered only where every point of one lies below every point of the
    /// other (or both are the same point); the operators below say what
    /// may hold.
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        if self.v.hi < o.v.lo {
            Some(Ordering::Less)
        } else if self.v.lo > o.v.hi {
            Some(Ordering::Greater)
        } else if self.v.lo == self.v.hi && self.v == o.v {
            Some(Ordering::Equal)
        } else {
            None
        }
    }
    fn lt(&self, o: &Self) -> bool {
        self.v.lo < o.v.hi
    }
    fn le(&self, o: &Self) -> bool {
        self.v.lo <= o.v.hi
    }
    fn gt(&self, o: &Self) -> bool {
        self.v.hi > o.v.lo
    }
    fn ge(&self, o: &Self) -> bool {
        self.v.hi >= o.v.lo
    }
}

impl<const N: usize> Real for Taylor<N> {
    const ZERO: Self = Self::constant(Interval::point(0.0));
    const ONE: Self = Self::constant(Interval::point(1.0));
    const HALF: Self = Self::constant(Interval::point(0.5));
    const M_PER_NM: Self = Self::constant(Interval::point(1.0e-9));
    const NM_PER_M: Self = Self::constant(Interval::point(1.0e9));

    fn of(x: f32) -> Self {
        Self::from(f64::from(x))
    }
    fn to_f32(self) -> f32 {
        self.v.mid() as f32
    }
    fn to_f64(self) -> f64 {
        self.v.mid()
    }
    fn from_i32(i: i32) -> Self {
        Self::from(f64::from(i))
    }
    fn from_i64(i: i64) -> Self {
        // (Only small integers reach the kinematics; one rounding is
        // covered by the ulp either side.)
        let x = i as f64;
        Self::constant(Interval::new(x.next_down(), x.next_up()))
    }
    fn trunc_i32(self) -> i32 {
        self.v.mid() as i32
    }
    fn abs(self) -> Self {
        if self.v.lo >= 0.0 {
            self
        } else if self.v.hi <= 0.0 {
            -self
        } else {
            // A kink inside: the slope is anywhere in [-1, 1] and the
            // curvature unbounded (at the centre too, unless its sign is
            // known).
            let mut out = Self::constant(self.v.abs());
            out.half = self.half;
            let slope = Interval::new(-1.0, 1.0);
            let (vc, at) = if self.vc.lo > 0.0 {
                (self.vc, Interval::point(1.0))
            } else if self.vc.hi < 0.0 {
                (-self.vc, Interval::point(-1.0))
            } else {
                (self.vc.abs(), slope)
            };
            out.vc = vc;
            for k in 0..N {
                out.g[k] = slope * self.g[k];
                out.gc[k] = at * self.gc[k];
                for l in 0..N {
                    out.h[k][l] = Interval::ENTIRE;
                }
            }
            out
        }
    }
    fn is_finite(self) -> bool {
        self.v.is_finite()
            && self.g.iter().all(|g| g.is_finite())
            && self.h.iter().flatten().all(|h| h.is_finite())
    }
    fn sin(self) -> Self {
        self.sin_cos().0
    }
    fn cos(self) -> Self {
        self.sin_cos().1
    }
    fn sin_cos(self) -> (Self, Self) {
        let (s, c) = self.v.sin_cos();
        let (sc, cc) = self.vc.sin_cos();
        (
            self.chain([s, c, -s], [sc, cc]),
            self.chain([c, -s, -c], [cc, -sc]),
        )
    }
    fn sqrt(self) -> Self {
        let r = self.v.sqrt();
        let d1 = Interval::point(0.5) * r.recip();
        let d2 = Interval::point(-0.25) * (r * self.v).recip();
        let rc = self.vc.sqrt();
        self.chain([r, d1, d2], [rc, Interval::point(0.5) * rc.recip()])
    }
    fn atan2(self, _x: Self) -> Self {
        // Not on the kinematics' path: every angle, and unknown slopes.
        let mut out = Self::constant(Interval::new(
            -std::f64::consts::PI.next_up(),
            std::f64::consts::PI.next_up(),
        ));
        out.half = self.half;
        for k in 0..N {
            out.g[k] = Interval::ENTIRE;
            out.gc[k] = Interval::ENTIRE;
            for l in 0..N {
                out.h[k][l] = Interval::ENTIRE;
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The enclosures hold the exact value, gradient and Hessian of a
    /// function of two angles that uses every operation the kinematics do,
    /// at sampled points of the box (derivatives by central differences).
    #[test]
    fn value_gradient_and_hessian_contain_the_function_s() {
        fn f<R: Real + From<f64>>(a: R, b: R) -> R {
            let (s, c) = a.sin_cos();
            let r = (R::from(2.0) + s * b).sqrt();
            (c * r - b * b) / (R::from(3.0) + a * a)
        }
        let (ra, rb) = (Interval::new(0.2, 0.5), Interval::new(-0.4, 0.1));
        let t = f(
            Taylor::<2>::variable(0, 0.35, 0.15),
            Taylor::<2>::variable(1, -0.15, 0.25),
        );
        let inside = |x: f64, i: Interval, slack: f64| x >= i.lo - slack && x <= i.hi + slack;
        let e = 1e-4;
        for i in 0..=6 {
            for j in 0..=6 {
                let a = ra.lo + (ra.hi - ra.lo) * i as f64 / 6.0;
                let b = rb.lo + (rb.hi - rb.lo) * j as f64 / 6.0;
                assert!(inside(f(a, b), t.v, 0.0));
                let ga = (f(a + e, b) - f(a - e, b)) / (2.0 * e);
                let gb = (f(a, b + e) - f(a, b - e)) / (2.0 * e);
                assert!(inside(ga, t.g[0], 1e-6) && inside(gb, t.g[1], 1e-6));
                let haa = (f(a + e, b) - 2.0 * f(a, b) + f(a - e, b)) / (e * e);
                let hab = (f(a + e, b + e) - f(a + e, b - e) - f(a - e, b + e) + f(a - e, b - e))
                    / (4.0 * e * e);
                assert!(inside(haa, t.h[0][0], 1e-4), "{haa} vs {:?}", t.h[0][0]);
                assert!(inside(hab, t.h[0][1], 1e-4) && inside(hab, t.h[1][0], 1e-4));
            }
        }
        // The centre's value and gradient are the function's there, to
        // rounding.
        let (a, b) = (0.35, -0.15);
        assert!(inside(f(a, b), t.vc, 0.0) && t.vc.hi - t.vc.lo < 1e-14);
        let ga = (f(a + e, b) - f(a - e, b)) / (2.0 * e);
        assert!(inside(ga, t.gc[0], 1e-6) && t.gc[0].hi - t.gc[0].lo < 1e-12);
        // At a point the enclosure is the value to rounding.
        let p = f(
            Taylor::<2>::variable(0, 0.3, 0.0),
            Taylor::<2>::variable(1, 0.0, 0.0),
        );
        assert!(p.v.hi - p.v.lo < 1e-14);
    }

    /// The centred forms recover the dependence interval arithmetic
    /// loses: `x·(1 - x) + x²` is `x`, which plain intervals over
    /// `[0.9, 1.1]` enclose in about `[0.6, 1.4]`.
    #[test]
    fn a_narrow_box_stays_narrow_along_a_chain() {
        let x = Taylor::<1>::variable(0, 1.0, 0.1);
        let one = Taylor::<1>::from(1.0);
        let y = x * (one - x) + x * x;
        assert!(y.v.lo >= 0.9 - 1e-12 && y.v.hi <= 1.1 + 1e-12, "{:?}", y.v);
        assert!((y.g[0].lo - 1.0).abs() < 1e-12 && (y.g[0].hi - 1.0).abs() < 1e-12);
    }

    /// A comparison holds where it may hold for some points; ordering
    /// is reported only where it holds for all.
    #[test]
    fn comparisons_say_what_may_hold() {
        let a = Taylor::<1>::constant(Interval::new(0.0, 1.0));
        let b = Taylor::<1>::constant(Interval::new(0.5, 2.0));
        let c = Taylor::<1>::constant(Interval::new(3.0, 4.0));
        // Overlapping: each of the four may hold.
        assert!(a.lt(&b) && a.ge(&b) && b.le(&a) && b.gt(&a));
        // Apart: only the true ones hold.
        assert!(a.lt(&c) && c.gt(&b));
        assert!(!a.ge(&c) && !c.lt(&a));
        assert_eq!(a.partial_cmp(&b), None);
        assert_eq!(a.partial_cmp(&c), Some(Ordering::Less));
    }
}
