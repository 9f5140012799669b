//! Springs: the spring-damper to an anchor, its lossless trapezoidal
//! form, and the one-sided wall that is a spring that only pushes.

use super::{Causality, Port, VeOutput, VeParam, VeTransfer, VirtualEnvironment};
use crate::{param, Integrator, ParamError, Position, Real, ZTransfer};

/// Which side of the wall surface is solid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Deserialize),
    serde(rename_all = "snake_case")
)]
pub enum Solid {
    /// Positions above the surface are inside the wall.
    Above,
    /// Positions below the surface are inside the wall.
    Below,
}

/// A spring-damper to a fixed anchor, pulling as well as pushing: the
/// simplest linear passive impedance VE, and the law of a wall in contact.
/// The probe's position is summed from velocities like the coupling's
/// spring (`x[k] = x[k-1] + T v[k]`), so `f = k (x - anchor) + b v` is
/// exactly `Z_e(z) = b + kT/(1 - z^-1)`.
#[derive(Clone, Copy, Debug)]
pub struct Spring<R = f32> {
    k: R,
    b: R,
    kt: R,
    period: R,
    anchor: Position,
    probe: Integrator<R>,
}

impl Spring {
    /// A spring of `k_npm` (N/m) and damper `b_nspm` (N s/m) to `anchor`;
    /// the probe starts at rest at `probe`.
    pub fn new(
        k_npm: f32,
        b_nspm: f32,
        anchor: Position,
        period_s: f32,
        probe: Position,
    ) -> Result<Self, ParamError> {
        Self::new_in(k_npm, b_nspm, anchor, period_s, probe)
    }
}

impl<R: Real> Spring<R> {
    /// [`Spring::new`] computing in `R`.
    pub fn new_in(
        k_npm: f32,
        b_nspm: f32,
        anchor: Position,
        period_s: f32,
        probe: Position,
    ) -> Result<Self, ParamError> {
        let t = param::positive("T (s)", period_s)?;
        let mut s = Spring {
            k: R::ZERO,
            b: R::ZERO,
            kt: R::ZERO,
            period: R::of(t),
            anchor,
            probe: Integrator::new_in(t, probe),
        };
        s.set_spring(k_npm, b_nspm)?;
        Ok(s)
    }

    /// Change stiffness (N/m) and damping (N s/m).
    pub fn set_spring(&mut self, k_npm: f32, b_nspm: f32) -> Result<(), ParamError> {
        let k = param::non_negative("stiffness (N/m)", k_npm)?;
        let b = param::non_negative("damping (N s/m)", b_nspm)?;
        let (k, b) = (R::of(k), R::of(b));
        (self.k, self.b, self.kt) = (k, b, k * self.period);
        Ok(())
    }

    /// Stiffness (N/m) and damping (N s/m).
    pub fn spring(&self) -> (f32, f32) {
        (self.k.to_f32(), self.b.to_f32())
    }

    /// Move the anchor (the probe stays where it is).
    pub fn set_anchor(&mut self, anchor: Position) {
        self.anchor = anchor;
    }

    /// The anchor, stiffness or damping; [`VirtualEnvironment::set_param`].
    fn set(&mut self, p: VeParam) -> Result<(), ParamError> {
        let (k, b) = self.spring();
        match p {
            VeParam::Surface(x) => {
                self.set_anchor(x);
                Ok(())
            }
            VeParam::Stiffness(k) => self.set_spring(k, b),
            VeParam::Damping(b) => self.set_spring(k, b),
        }
    }

    /// The probe's offset from the anchor now (m).
    fn stretch_m(&self) -> R {
        self.probe.offset_m(self.anchor)
    }

    /// This tick's law `f = g + h v` for the probe velocity `v`, given its
    /// offset `d_m` from the anchor: `g = k d`, `h = kT + b`.
    fn affine(&self, d_m: R) -> (R, R) {
        (self.k * d_m, self.kt + self.b)
    }

    /// Move the probe at `v` for this tick (the integrator ignores a
    /// non-finite `v`).
    fn commit(&mut self, v_mps: R) {
        self.probe.step(v_mps);
    }
}

impl<R: Real> VirtualEnvironment<R> for Spring<R> {
    fn causality(&self) -> Causality {
        Causality::Impedance
    }

    fn step(&mut self, port: Port<R>) -> VeOutput<R> {
        let (g, h) = self.affine(self.stretch_m());
        let out = port.solve_impedance(g, h);
        self.commit(out.velocity_mps);
        out
    }

    /// Moves the probe; the anchor stays.
    fn reset(&mut self, x: Position) {
        self.probe.reset(x);
    }

    fn position(&self) -> Position {
        self.probe.position()
    }

    #[inline]
    fn offset_m(&self, from: Position) -> R {
        self.probe.offset_m(from)
    }

    /// `F/V = b + kT/(1 - z^-1)`.
    fn tf(&self) -> VeTransfer {
        let (b, kt) = (self.b.to_f64(), self.kt.to_f64());
        VeTransfer::Impedance(ZTransfer::first_order([b + kt, -b], -1.0))
    }

    fn set_param(&mut self, p: VeParam) -> Result<(), ParamError> {
        self.set(p)
    }
}

/// A spring-damper to an anchor discretised by the trapezoidal rule: the
/// probe moves `x[k] = x[k-1] + T (v[k] + v[k-1]) / 2` and the VE needs the
/// force `k (x[k] - anchor) + b v[k]`, so
/// `F/V = b + (kT/2) (1 + z^-1) / (1 - z^-1)`.
///
/// Its spring part is lossless on the unit circle (real part exactly 0 at
/// every frequency), where the backward-Euler [`Spring`]'s has real part
/// `kT/2`: at 82 Hz and 1 kHz that hidden damping is 17 N s/m for a
/// 34,000 N/m spring. Use it when a VE must add no damping of its own (an
/// energy-conserving spring), and to meet the designer's bound exactly: it
/// is the passive termination that shows the bound is not conservative.
#[derive(Clone, Copy, Debug)]
pub struct TrapezoidalSpring<R = f32> {
    /// Gains, anchor and the probe's integer position.
    spring: Spring<R>,
    /// Last tick's probe velocity (m/s).
    v_prev: R,
    /// The probe's velocities summed by the rectangle rule: the point the
    /// coupling holds (its spring integrates that way, see
    /// [`VirtualEnvironment::position`]).
    held: Integrator<R>,
}

impl<R: Real> From<Spring<R>> for TrapezoidalSpring<R> {
    /// `spring`'s gains, anchor and probe, discretised by the trapezoidal
    /// rule.
    fn from(spring: Spring<R>) -> Self {
        TrapezoidalSpring {
            held: spring.probe,
            spring,
            v_prev: R::ZERO,
        }
    }
}

impl<R: Real> TrapezoidalSpring<R> {
    /// Change stiffness (N/m) and damping (N s/m).
    pub fn set_spring(&mut self, k_npm: f32, b_nspm: f32) -> Result<(), ParamError> {
        self.spring.set_spring(k_npm, b_nspm)
    }
}

impl<R: Real> VirtualEnvironment<R> for TrapezoidalSpring<R> {
    fn causality(&self) -> Causality {
        Causality::Impedance
    }

    fn step(&mut self, port: Port<R>) -> VeOutput<R> {
        // f = k (x[k-1] - a + T/2 v[k-1]) + (k T/2 + b) v[k]
        let s = &self.spring;
        let half_kt = R::HALF * s.kt;
        let g = s.k * s.stretch_m() + half_kt * self.v_prev;
        let out = port.solve_impedance(g, half_kt + s.b);
        if out.velocity_mps.is_finite() {
            self.spring
                .commit(R::HALF * (out.velocity_mps + self.v_prev));
            self.v_prev = out.velocity_mps;
            self.held.step(out.velocity_mps);
        }
        out
    }

    fn reset(&mut self, x: Position) {
        self.spring.reset(x);
        self.v_prev = R::ZERO;
        self.held.reset(x);
    }

    fn position(&self) -> Position {
        self.held.position()
    }

    fn offset_m(&self, from: Position) -> R {
        self.held.offset_m(from)
    }

    /// `F/V = ((b + kT/2) + (kT/2 - b) z^-1) / (1 - z^-1)`.
    fn tf(&self) -> VeTransfer {
        let (b, hkt) = (self.spring.b.to_f64(), 0.5 * self.spring.kt.to_f64());
        VeTransfer::Impedance(ZTransfer::first_order([b + hkt, hkt - b], -1.0))
    }
}

/// A one-sided wall touched by a massless probe: a [`Spring`] anchored at
/// the surface that only pushes. Impedance causality: in contact the force
/// needed to hold the probe at penetration `p` moving inward at `p'` is
/// `k p + b p'`, never pulling (`>= 0`); out of contact it is zero. In
/// contact the law is exactly the spring's, `Z_e(z) = b + kT/(1 - z^-1)`.
#[derive(Clone, Copy, Debug)]
pub struct UnilateralWall<R = f32> {
    spring: Spring<R>,
    /// +1 when solid above, -1 when below: kept as a number, not read from
    /// a `Solid` each tick (a load, compare and select on the board).
    sign: R,
}

impl UnilateralWall {
    /// A wall of stiffness `k_npm` (N/m) and damping `b_nspm` (N s/m) whose
    /// surface is at `surface`, solid on the `solid` side; the probe starts
    /// at rest at `probe`.
    pub fn new(
        k_npm: f32,
        b_nspm: f32,
        surface: Position,
        solid: Solid,
        period_s: f32,
        probe: Position,
    ) -> Result<Self, ParamError> {
        Self::new_in(k_npm, b_nspm, surface, solid, period_s, probe)
    }
}

impl<R: Real> UnilateralWall<R> {
    /// [`UnilateralWall::new`] computing in `R`.
    pub fn new_in(
        k_npm: f32,
        b_nspm: f32,
        surface: Position,
        solid: Solid,
        period_s: f32,
        probe: Position,
    ) -> Result<Self, ParamError> {
        Ok(UnilateralWall {
            spring: Spring::new_in(k_npm, b_nspm, surface, period_s, probe)?,
            sign: match solid {
                Solid::Above => R::ONE,
                Solid::Below => -R::ONE,
            },
        })
    }

    /// Move the surface (the probe stays where it is).
    pub fn set_surface(&mut self, surface: Position) {
        self.spring.set_anchor(surface);
    }

    /// Change stiffness and damping.
    pub fn set_spring(&mut self, k_npm: f32, b_nspm: f32) -> Result<(), ParamError> {
        self.spring.set_spring(k_npm, b_nspm)
    }

    /// Stiffness (N/m) and damping (N s/m).
    pub fn spring(&self) -> (f32, f32) {
        self.spring.spring()
    }

    #[inline]
    fn sign(&self) -> R {
        self.sign
    }

    /// Penetration (> 0 inside) and inward push (before clamping) of the
    /// probe if it moves at `v = n / m` (m/s) this tick, both multiplied by
    /// `m > 0`: the signs decide contact, and multiplying through lets the
    /// tests run beside the division instead of after it.
    fn contact(&self, d_m: R, n: R, m: R) -> (R, R) {
        let s = self.sign();
        let pen = s * (d_m * m + self.spring.period * n);
        (pen, self.spring.k * pen + self.spring.b * s * n)
    }

    /// Whether the probe is in the wall.
    pub fn in_contact(&self) -> bool {
        self.sign() * self.spring.stretch_m() > R::ZERO
    }
}

impl<R: Real> VirtualEnvironment<R> for UnilateralWall<R> {
    fn causality(&self) -> Causality {
        Causality::Impedance
    }

    fn step(&mut self, port: Port<R>) -> VeOutput<R> {
        let d = self.spring.stretch_m();
        // The force needed is non-decreasing in v, so exactly one of three
        // cases holds: free, pushed by the wall, or stopped at the surface
        // (the damper's jump on first touch). Each case's velocity is a
        // quotient n / m, and only the chosen one is divided. A non-finite
        // port fails the first test and goes free with a non-finite
        // velocity, which `commit` ignores.
        let (f0, z) = (port.f0_n, port.z_nspm);
        let (pen, push) = self.contact(d, f0, z);
        let (n, m) = if !(pen > R::ZERO && push > R::ZERO) {
            (f0, z)
        } else {
            // In contact the spring's own law, the same for both sides.
            let (g, h) = self.spring.affine(d);
            let (n, m) = port.impedance_quotient(g, h);
            let (pen, push) = self.contact(d, n, m);
            if pen > R::ZERO && push >= R::ZERO {
                (n, m)
            } else {
                (-d, self.spring.period)
            }
        };
        let out = port.at(n / m);
        self.spring.commit(out.velocity_mps);
        out
    }

    fn reset(&mut self, x: Position) {
        self.spring.reset(x);
    }

    fn position(&self) -> Position {
        self.spring.position()
    }

    #[inline]
    fn offset_m(&self, from: Position) -> R {
        self.spring.offset_m(from)
    }

    /// In contact: the spring's `F/V = b + kT/(1 - z^-1)`.
    fn tf(&self) -> VeTransfer {
        self.spring.tf()
    }

    fn set_param(&mut self, p: VeParam) -> Result<(), ParamError> {
        self.spring.set(p)
    }
}
