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

mod constraint;
mod cursor;
mod host_body;
mod spring;
#[cfg(test)]
mod tests;

pub use constraint::BilateralConstraint;
pub use cursor::{
    Cursor, CursorMass, Explicit, ExplicitCursor, Implicit, Lossless, LosslessCursor, Scheme,
    PAPER_MIN_CURSOR_MASS_KG,
};
pub use host_body::HostBody;
pub use spring::{Solid, Spring, TrapezoidalSpring, UnilateralWall};

use crate::{ParamError, Position, Real, ZTransfer};

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

/// One parameter of a VE a host may set on a disarmed board. Any value in
/// range keeps the VE passive (its laws are passive for every stiffness
/// and damping not negative), so the proven coupling holds.
///
/// It is the one type for the concept: the application builds it (from
/// SI, by [`surface_m`](Self::surface_m) and its siblings), the link
/// carries it as it is (protocol 10), and the board's VE takes it.
///
/// ```
/// use twoport_control::ve::VeParam;
/// assert!(VeParam::surface_m(0.005).is_ok());
/// let e = VeParam::stiffness_npm(-1.0).unwrap_err();
/// assert_eq!(e.to_string(), "VE stiffness (N/m) = -1 must be finite and >= 0");
/// assert!(VeParam::surface_m(3.0).is_err());
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum VeParam {
    /// Where its surface or anchor is.
    Surface(Position),
    /// Its stiffness (N/m, not negative).
    Stiffness(f32),
    /// Its damping (N s/m, not negative).
    Damping(f32),
}

impl VeParam {
    /// Its surface or anchor at `x_m` (m), within ±2.147 m.
    pub fn surface_m(x_m: f64) -> Result<Self, ParamError> {
        Position::from_m_f64(x_m)
            .map(VeParam::Surface)
            .ok_or(ParamError {
                name: "VE surface (m)",
                value: x_m as f32,
                problem: "must be finite and within +-2.147 m",
            })
    }

    /// Its stiffness `k_npm` (N/m), finite and not negative.
    pub fn stiffness_npm(k_npm: f64) -> Result<Self, ParamError> {
        VeParam::Stiffness(k_npm as f32).checked()
    }

    /// Its damping `b_nspm` (N s/m), finite and not negative.
    pub fn damping_nspm(b_nspm: f64) -> Result<Self, ParamError> {
        VeParam::Damping(b_nspm as f32).checked()
    }

    /// Itself, or why no passive VE takes it: a stiffness or damping
    /// that is negative or not finite.
    pub fn checked(self) -> Result<Self, ParamError> {
        match self {
            VeParam::Stiffness(v) | VeParam::Damping(v) if !(v.is_finite() && v >= 0.0) => {
                Err(ParamError {
                    problem: "must be finite and >= 0",
                    ..self.unsupported()
                })
            }
            _ => Ok(self),
        }
    }

    /// The refusal of a VE that has no such parameter.
    pub fn unsupported(self) -> ParamError {
        ParamError {
            name: match self {
                VeParam::Surface(_) => "VE surface",
                VeParam::Stiffness(_) => "VE stiffness (N/m)",
                VeParam::Damping(_) => "VE damping (N s/m)",
            },
            value: match self {
                VeParam::Surface(p) => p.m(),
                VeParam::Stiffness(v) | VeParam::Damping(v) => v,
            },
            problem: "is not a parameter of this VE",
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
    /// Set one of its parameters; a VE without it refuses, naming it, and
    /// a value out of range is refused by name, the VE unchanged.
    fn set_param(&mut self, p: VeParam) -> Result<(), ParamError> {
        Err(p.unsupported())
    }
}
