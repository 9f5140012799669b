//! Virtual environments that run on the board, and the exact solution of the
//! algebraic loop between a coupling and a VE.
//!
//! Every virtual coupling in this crate has direct feedthrough: this tick's
//! VE velocity changes this tick's coupling force. The coupling therefore
//! hands the VE a [`Port`], its own law for this tick written as the affine
//! relation `f = f0 - z v` between the force `f` it applies to the VE and the
//! VE velocity `v`. The VE intersects that line with its own law and commits
//! the one consistent answer, so no one-tick delay is ever inserted (a delay
//! would change the two-port the designer proved stable).
//!
//! Sign convention: `f` is the force applied *to* the VE along +x (N), `v`
//! is the VE velocity along +x (m/s), and positions are [`Position`]s.

use crate::{param, Integrator, ParamError, Position, Real, ZTransfer};

/// The paper's Fig. 7 causality of a VE's own law.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Causality {
    /// Force from velocity, `f = Z_e v` (Fig. 7(a), 7(c)).
    Impedance,
    /// Velocity from force, `v = Y_e f` (Fig. 7(b), 7(d)).
    Admittance,
}

/// A coupling's law for this tick, as seen by the VE: it applies
/// `f0_n - z_nspm * v` (N) to the VE for a VE velocity `v` (m/s).
/// `z_nspm > 0` (N s/m) always: it is the coupling's direct feedthrough.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Port<R = f32> {
    /// Force at zero VE velocity (N).
    pub f0_n: R,
    /// Direct-feedthrough impedance (N s/m), > 0.
    pub z_nspm: R,
}

/// What a VE settled on this tick.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct VeOutput<R = f32> {
    /// VE velocity `v_e` (m/s).
    pub velocity_mps: R,
    /// Force applied to the VE along +x, `f_e` (N).
    pub force_n: R,
}

impl<R: Real> Port<R> {
    /// Intersect with an admittance law `v = v0 + y f` (y >= 0, m/(N s)).
    pub fn solve_admittance(self, v0_mps: R, y: R) -> VeOutput<R> {
        let (n, m) = self.admittance_quotient(v0_mps, y);
        self.at(n / m)
    }

    /// The intersection's velocity with `v = v0 + y f` as the quotient
    /// `n / m` (m >= 1), for a VE that keeps `1 / m` (it depends on the
    /// port's `z` alone) and multiplies.
    #[inline]
    pub fn admittance_quotient(self, v0_mps: R, y: R) -> (R, R) {
        (v0_mps + y * self.f0_n, R::ONE + y * self.z_nspm)
    }

    /// Intersect with an impedance law `f = g + h v` (h >= 0, N s/m).
    pub fn solve_impedance(self, g_n: R, h: R) -> VeOutput<R> {
        let (n, m) = self.impedance_quotient(g_n, h);
        self.at(n / m)
    }

    /// The intersection's velocity with `f = g + h v` as the quotient
    /// `n / m` (m > 0), for a VE that must test it before it divides.
    pub fn impedance_quotient(self, g_n: R, h: R) -> (R, R) {
        (self.f0_n - g_n, self.z_nspm + h)
    }

    /// The port's force at VE velocity `v`.
    pub fn at(self, v_mps: R) -> VeOutput<R> {
        VeOutput {
            velocity_mps: v_mps,
            force_n: self.f0_n - self.z_nspm * v_mps,
        }
    }
}

/// The linear(ised) law of a VE as a z-domain transfer function.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum VeTransfer {
    /// `F_e(z)/V_e(z)` (N s/m).
    Impedance(ZTransfer),
    /// `V_e(z)/F_e(z)` (m/(N s)).
    Admittance(ZTransfer),
}

/// A virtual environment stepped once per tick against a coupling's [`Port`].
/// `step` must not allocate, panic or loop without bound, and must leave its
/// state unchanged when the port holds a non-finite number. `R` is the float
/// it computes in (see [`Real`]).
pub trait VirtualEnvironment<R: Real = f32> {
    /// The causality of this VE's own law.
    fn causality(&self) -> Causality;
    /// Solve this tick exactly against the coupling's law and commit.
    fn step(&mut self, port: Port<R>) -> VeOutput<R>;
    /// Put the VE at rest at `x`.
    fn reset(&mut self, x: Position);
    /// The VE point the coupling holds: where the velocities `step` returned
    /// have taken it, `x[k] = x[k-1] + T v[k]` (to the nanometre below; see
    /// [`offset_m`](Self::offset_m)). The impedance coupling's spring acts on
    /// it, so a VE whose own law integrates otherwise (the trapezoidal
    /// spring) keeps this sum apart; a body stopped by an obstacle reports
    /// where it stopped.
    fn position(&self) -> Position;
    /// [`position`](Self::position) minus `from`, in metres, with the
    /// sub-nanometre part the VE's integrator carries: a stiff coupling
    /// spring would otherwise see the 1 nm steps as force ripple. The
    /// default has no such part.
    #[inline]
    fn offset_m(&self, from: Position) -> R {
        self.position().nm_from::<R>(from) * R::M_PER_NM
    }
    /// The VE's law in the z-domain (for a piecewise law: the piece named in
    /// its documentation, e.g. a wall in contact).
    fn tf(&self) -> VeTransfer;
}

/// A free cursor (or grabbed block) of mass `m`: `v[k] = v[k-1] + T f[k] / m`,
/// backward Euler, which is discrete-time passive for every `m > 0`.
/// Admittance causality. The paper's VBB needed `m >= 0.25 kg` with its
/// explicit integrator ([`PAPER_MIN_CURSOR_MASS_KG`]).
#[derive(Clone, Copy, Debug)]
pub struct CursorMass<R = f32> {
    mass_kg: f32,
    t_over_m: R,
    velocity_mps: R,
    x: Integrator<R>,
    /// The port feedthrough `z` last met and `1 / (1 + (T/m) z)`: a
    /// coupling's `z` changes only with its gains, so the loop solve
    /// multiplies instead of dividing (the division's latency sat on the
    /// admittance display's sensor-to-force chain).
    port_z: R,
    inv_den: R,
}

/// The smallest cursor mass the paper's experiments ran stably (kg).
pub const PAPER_MIN_CURSOR_MASS_KG: f32 = 0.25;

impl CursorMass {
    /// A mass of `mass_kg` (kg) at rest at `x`, period `period_s` (s).
    pub fn new(mass_kg: f32, period_s: f32, x: Position) -> Result<Self, ParamError> {
        Self::new_in(mass_kg, period_s, x)
    }
}

impl<R: Real> CursorMass<R> {
    /// [`CursorMass::new`] computing in `R`.
    pub fn new_in(mass_kg: f32, period_s: f32, x: Position) -> Result<Self, ParamError> {
        let m = param::positive("cursor mass (kg)", mass_kg)?;
        let t = param::positive("T (s)", period_s)?;
        Ok(CursorMass {
            mass_kg: m,
            t_over_m: R::of(t) / R::of(m),
            velocity_mps: R::ZERO,
            x: Integrator::new_in(t, x),
            port_z: R::ZERO,
            inv_den: R::ONE,
        })
    }

    /// The mass (kg).
    pub fn mass_kg(&self) -> f32 {
        self.mass_kg
    }

    /// The current velocity (m/s).
    pub fn velocity_mps(&self) -> R {
        self.velocity_mps
    }
}

impl<R: Real> VirtualEnvironment<R> for CursorMass<R> {
    fn causality(&self) -> Causality {
        Causality::Admittance
    }

    fn step(&mut self, port: Port<R>) -> VeOutput<R> {
        // (A NaN z never equals the one kept, so it gives a NaN answer,
        // which is not committed, and the next good z recomputes.)
        let (n, m) = port.admittance_quotient(self.velocity_mps, self.t_over_m);
        if port.z_nspm != self.port_z {
            self.port_z = port.z_nspm;
            self.inv_den = R::ONE / m;
        }
        let out = port.at(n * self.inv_den);
        if out.velocity_mps.is_finite() {
            self.velocity_mps = out.velocity_mps;
            self.x.step(out.velocity_mps);
        }
        out
    }

    fn reset(&mut self, x: Position) {
        self.velocity_mps = R::ZERO;
        self.x.reset(x);
    }

    fn position(&self) -> Position {
        self.x.position()
    }

    #[inline]
    fn offset_m(&self, from: Position) -> R {
        self.x.offset_m(from)
    }

    /// `V/F = (T/m) / (1 - z^-1)`.
    fn tf(&self) -> VeTransfer {
        VeTransfer::Admittance(ZTransfer::first_order([self.t_over_m.to_f64(), 0.0], -1.0))
    }
}

/// A free cursor integrated explicitly, as the paper's building blocks
/// were: the velocity by forward Euler on last tick's force,
/// `v[k] = v[k-1] + T f[k-1] / m`, the position by the trapezoidal rule,
/// `x[k] = x[k-1] + T (v[k] + v[k-1]) / 2`. The coupling sees the mean of
/// the two velocities, so that its spring acts on that position. Unlike
/// [`CursorMass`] this is not passive: with a stiff coupling a light
/// cursor gives energy out and the loop rings, which is why the paper's
/// cursor could not go below [`PAPER_MIN_CURSOR_MASS_KG`]. It is here to
/// study that, and what the passivity layer makes of it.
#[derive(Clone, Copy, Debug)]
pub struct ExplicitCursor<R = f32> {
    mass_kg: f32,
    t_over_m: R,
    /// `v[k-1]` (m/s).
    velocity_mps: R,
    /// `f[k-1]` (N).
    last_force_n: R,
    x: Integrator<R>,
}

impl<R: Real> ExplicitCursor<R> {
    /// A mass of `mass_kg` (kg) at rest at `x`, period `period_s` (s).
    ///
    /// # Examples
    ///
    /// ```
    /// use twoport_control::ve::{ExplicitCursor, Port, VirtualEnvironment};
    /// use twoport_control::Position;
    /// let mut c = ExplicitCursor::<f32>::new_in(0.5, 1e-3, Position::ZERO)?;
    /// // The first tick's force moves nothing yet: the velocity follows
    /// // last tick's force.
    /// let out = c.step(Port { f0_n: 1.0, z_nspm: 100.0 });
    /// assert_eq!((out.velocity_mps, out.force_n), (0.0, 1.0));
    /// let out = c.step(Port { f0_n: 1.0, z_nspm: 100.0 });
    /// assert!((out.velocity_mps - 1e-3).abs() < 1e-9); // half of T f / m
    /// # Ok::<(), twoport_control::ParamError>(())
    /// ```
    pub fn new_in(mass_kg: f32, period_s: f32, x: Position) -> Result<Self, ParamError> {
        let m = param::positive("cursor mass (kg)", mass_kg)?;
        let t = param::positive("T (s)", period_s)?;
        Ok(ExplicitCursor {
            mass_kg: m,
            t_over_m: R::of(t) / R::of(m),
            velocity_mps: R::ZERO,
            last_force_n: R::ZERO,
            x: Integrator::new_in(t, x),
        })
    }

    /// The mass (kg).
    pub fn mass_kg(&self) -> f32 {
        self.mass_kg
    }
}

impl<R: Real> VirtualEnvironment<R> for ExplicitCursor<R> {
    fn causality(&self) -> Causality {
        Causality::Admittance
    }

    fn step(&mut self, port: Port<R>) -> VeOutput<R> {
        let v_new = self.velocity_mps + self.t_over_m * self.last_force_n;
        let mean = (self.velocity_mps + v_new) * R::of(0.5);
        let out = port.at(mean);
        if out.force_n.is_finite() && v_new.is_finite() {
            self.velocity_mps = v_new;
            self.last_force_n = out.force_n;
            self.x.step(mean);
        }
        out
    }

    fn reset(&mut self, x: Position) {
        self.velocity_mps = R::ZERO;
        self.last_force_n = R::ZERO;
        self.x.reset(x);
    }

    fn position(&self) -> Position {
        self.x.position()
    }

    #[inline]
    fn offset_m(&self, from: Position) -> R {
        self.x.offset_m(from)
    }

    /// `V/F = (T/2m) (z^-1 + z^-2) / (1 - z^-1)`: the mean velocity the
    /// coupling sees, per force.
    fn tf(&self) -> VeTransfer {
        let h = 0.5 * self.t_over_m.to_f64();
        VeTransfer::Admittance(ZTransfer {
            num: [0.0, h, h],
            den: [1.0, -1.0, 0.0],
        })
    }
}

/// Which side of the wall surface is solid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
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
        s.set_gains(k_npm, b_nspm)?;
        Ok(s)
    }

    /// Change stiffness (N/m) and damping (N s/m).
    pub fn set_gains(&mut self, k_npm: f32, b_nspm: f32) -> Result<(), ParamError> {
        let k = param::non_negative("stiffness (N/m)", k_npm)?;
        let b = param::non_negative("damping (N s/m)", b_nspm)?;
        let (k, b) = (R::of(k), R::of(b));
        (self.k, self.b, self.kt) = (k, b, k * self.period);
        Ok(())
    }

    /// Stiffness (N/m) and damping (N s/m).
    pub fn gains(&self) -> (f32, f32) {
        (self.k.to_f32(), self.b.to_f32())
    }

    /// Move the anchor (the probe stays where it is).
    pub fn set_anchor(&mut self, anchor: Position) {
        self.anchor = anchor;
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

impl TrapezoidalSpring {
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

impl<R: Real> TrapezoidalSpring<R> {
    /// [`TrapezoidalSpring::new`] computing in `R`.
    pub fn new_in(
        k_npm: f32,
        b_nspm: f32,
        anchor: Position,
        period_s: f32,
        probe: Position,
    ) -> Result<Self, ParamError> {
        let spring = Spring::new_in(k_npm, b_nspm, anchor, period_s, probe)?;
        Ok(TrapezoidalSpring {
            held: Integrator::new_in(period_s, probe),
            spring,
            v_prev: R::ZERO,
        })
    }

    /// Change stiffness (N/m) and damping (N s/m).
    pub fn set_gains(&mut self, k_npm: f32, b_nspm: f32) -> Result<(), ParamError> {
        self.spring.set_gains(k_npm, b_nspm)
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
    pub fn set_gains(&mut self, k_npm: f32, b_nspm: f32) -> Result<(), ParamError> {
        self.spring.set_gains(k_npm, b_nspm)
    }

    /// Stiffness (N/m) and damping (N s/m).
    pub fn gains(&self) -> (f32, f32) {
        self.spring.gains()
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
}

/// A bilateral constraint: the VE point is fixed, `v_e = 0`, whatever the
/// force (admittance zero). The paper's "bilaterally constrained block".
#[derive(Clone, Copy, Debug)]
pub struct BilateralConstraint {
    at: Position,
}

impl BilateralConstraint {
    /// A constraint holding the VE at `at`.
    pub fn new(at: Position) -> Self {
        BilateralConstraint { at }
    }
}

impl<R: Real> VirtualEnvironment<R> for BilateralConstraint {
    fn causality(&self) -> Causality {
        Causality::Admittance
    }

    fn step(&mut self, port: Port<R>) -> VeOutput<R> {
        port.at(R::ZERO)
    }

    fn reset(&mut self, x: Position) {
        self.at = x;
    }

    fn position(&self) -> Position {
        self.at
    }

    /// `V/F = 0`.
    fn tf(&self) -> VeTransfer {
        VeTransfer::Admittance(ZTransfer::gain(0.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const T: f32 = 1.0e-3;

    fn wall_at_zero(probe_m: f32) -> UnilateralWall {
        let probe = Position::from_m(probe_m).unwrap();
        UnilateralWall::new(10_000.0, 20.0, Position::ZERO, Solid::Above, T, probe).unwrap()
    }

    #[test]
    fn wall_is_free_outside_and_pushes_inside() {
        // Far outside, pulled gently: free, the port's force is zero.
        let mut w = wall_at_zero(-0.01);
        let out = w.step(Port {
            f0_n: 1.0,
            z_nspm: 100.0,
        });
        assert_eq!(out.force_n, 0.0);
        assert!((out.velocity_mps - 0.01).abs() < 1e-7);
        // Inside by 1 mm, held: force k d + (kT + b) v balances f0 - z v.
        let mut w = wall_at_zero(1e-3);
        let out = w.step(Port {
            f0_n: 10.0,
            z_nspm: 100.0,
        });
        let expect_v = (10.0 - 10_000.0 * 1e-3) / (100.0 + 10.0 + 20.0);
        assert!((out.velocity_mps - expect_v).abs() < 1e-6);
        assert!(out.force_n >= 0.0);
    }

    #[test]
    fn wall_stops_a_fast_probe_at_the_surface_and_never_pulls() {
        // 0.1 mm outside, driven hard inward: the damper's jump on touch
        // leaves the probe exactly on the surface this tick.
        let mut w = wall_at_zero(-1e-4);
        let out = w.step(Port {
            f0_n: 2.0,
            z_nspm: 10.0,
        });
        assert!((out.velocity_mps - 0.1).abs() < 1e-5, "{out:?}");
        assert!(out.force_n >= 0.0);
        assert!(w.position().nm().abs() <= 1, "{:?}", w.position());
        // Inside but pulled out fast: the wall lets go (force 0, not < 0).
        let mut w = wall_at_zero(1e-4);
        let out = w.step(Port {
            f0_n: -50.0,
            z_nspm: 10.0,
        });
        assert_eq!(out.force_n, 0.0);
        // A wall solid below mirrors it.
        let mut w = UnilateralWall::new(
            10_000.0,
            20.0,
            Position::ZERO,
            Solid::Below,
            T,
            Position::from_m(-1e-3).unwrap(),
        )
        .unwrap();
        assert!(w.in_contact());
        let out = w.step(Port {
            f0_n: -10.0,
            z_nspm: 100.0,
        });
        assert!(out.force_n <= 0.0, "pushes toward +x: {out:?}");
    }

    #[test]
    fn ve_state_survives_a_non_finite_port() {
        let mut m = CursorMass::new(0.25, T, Position::ZERO).unwrap();
        m.step(Port {
            f0_n: f32::NAN,
            z_nspm: 1.0,
        });
        assert_eq!(m.velocity_mps(), 0.0);
        assert_eq!(m.position(), Position::ZERO);
        // Outside, inside, solid on either side: no non-finite port moves
        // the probe (a NaN once reached the surface case and moved it there).
        for (probe_m, solid) in [
            (-1e-3, Solid::Above),
            (1e-3, Solid::Above),
            (1e-3, Solid::Below),
        ] {
            for f0_n in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
                let probe = Position::from_m(probe_m).unwrap();
                let mut w =
                    UnilateralWall::new(10_000.0, 20.0, Position::ZERO, solid, T, probe).unwrap();
                let out = w.step(Port { f0_n, z_nspm: 1.0 });
                assert_eq!(w.position(), probe, "{f0_n} at {probe_m} m, {solid:?}");
                assert!(!out.velocity_mps.is_finite() || !out.force_n.is_finite());
            }
        }
    }

    /// The cursor keeps `1/(1 + (T/m) z)` for the port's `z`: when a
    /// coupling's gains change `z` (or a NaN passes), its answer is still the
    /// loop solve's, to f32 rounding, tick after tick.
    #[test]
    fn cursor_follows_a_changing_port_feedthrough() {
        let mut m = CursorMass::new(0.25, T, Position::ZERO).unwrap();
        let mut twin_v = 0.0f32; // the same mass by the divided formula
        for (k, z) in [100.0, 100.0, 250.0, f32::NAN, 250.0, 40.0, 40.0]
            .into_iter()
            .enumerate()
        {
            let port = Port {
                f0_n: 3.0 - k as f32,
                z_nspm: z,
            };
            let want = port.solve_admittance(twin_v, T / 0.25);
            let got = m.step(port);
            if z.is_nan() {
                assert!(got.velocity_mps.is_nan());
                continue;
            }
            let tol = 3e-7 * want.velocity_mps.abs();
            assert!(
                (got.velocity_mps - want.velocity_mps).abs() <= tol,
                "tick {k}, z {z}: {got:?} vs {want:?}"
            );
            twin_v = want.velocity_mps;
            assert!((m.velocity_mps() - twin_v).abs() <= tol);
        }
    }

    #[test]
    fn constructors_refuse_bad_parameters() {
        assert_eq!(
            CursorMass::new(0.0, T, Position::ZERO).unwrap_err().name,
            "cursor mass (kg)"
        );
        assert!(
            UnilateralWall::new(-1.0, 0.0, Position::ZERO, Solid::Above, T, Position::ZERO)
                .is_err()
        );
    }
}
