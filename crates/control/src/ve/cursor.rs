//! Free bodies: the cursor (or a grabbed block) as a mass, integrated
//! passively, and the paper's explicit integrator beside it.

use super::{Causality, Port, VeOutput, VeTransfer, VirtualEnvironment};
use crate::{param, Integrator, ParamError, Position, Real, ZTransfer};

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

/// A lossless mass `m`: its velocity integrates the force by the
/// trapezoidal rule, `v[k] = v[k-1] + T (f[k] + f[k-1]) / (2 m)`. Its
/// admittance `(T/2m)(1 + z^-1)/(1 - z^-1)` is imaginary on the unit
/// circle: it stores and returns energy and dissipates none, the edge of
/// the passive masses (backward Euler's [`CursorMass`] dissipates). The
/// designer's `verify` terminates a loop with it; a scene may run it.
/// Admittance causality.
#[derive(Clone, Copy, Debug)]
pub struct LosslessCursor<R = f32> {
    mass_kg: f32,
    /// `T / (2 m)`.
    h: R,
    velocity_mps: R,
    /// Last tick's force (N).
    force_n: R,
    x: Integrator<R>,
}

impl LosslessCursor {
    /// A lossless mass of `mass_kg` (kg) at rest at `x`, period
    /// `period_s` (s).
    pub fn new(mass_kg: f32, period_s: f32, x: Position) -> Result<Self, ParamError> {
        Self::new_in(mass_kg, period_s, x)
    }
}

impl<R: Real> LosslessCursor<R> {
    /// [`LosslessCursor::new`] computing in `R`.
    pub fn new_in(mass_kg: f32, period_s: f32, x: Position) -> Result<Self, ParamError> {
        let m = param::positive("cursor mass (kg)", mass_kg)?;
        let t = param::positive("T (s)", period_s)?;
        Ok(LosslessCursor {
            mass_kg: m,
            h: R::HALF * R::of(t) / R::of(m),
            velocity_mps: R::ZERO,
            force_n: R::ZERO,
            x: Integrator::new_in(t, x),
        })
    }

    /// The mass (kg).
    pub fn mass_kg(&self) -> f32 {
        self.mass_kg
    }
}

impl<R: Real> VirtualEnvironment<R> for LosslessCursor<R> {
    fn causality(&self) -> Causality {
        Causality::Admittance
    }

    fn step(&mut self, port: Port<R>) -> VeOutput<R> {
        // v = (v[k-1] + h f[k-1]) + h f[k], met with the port's f = f0 - z v.
        let out = port.solve_admittance(self.velocity_mps + self.h * self.force_n, self.h);
        if out.velocity_mps.is_finite() && out.force_n.is_finite() {
            self.velocity_mps = out.velocity_mps;
            self.force_n = out.force_n;
            self.x.step(out.velocity_mps);
        }
        out
    }

    fn reset(&mut self, x: Position) {
        self.velocity_mps = R::ZERO;
        self.force_n = R::ZERO;
        self.x.reset(x);
    }

    fn position(&self) -> Position {
        self.x.position()
    }

    #[inline]
    fn offset_m(&self, from: Position) -> R {
        self.x.offset_m(from)
    }

    /// `V/F = (T/2m)(1 + z^-1)/(1 - z^-1)`.
    fn tf(&self) -> VeTransfer {
        let h = self.h.to_f64();
        VeTransfer::Admittance(ZTransfer {
            num: [h, h, 0.0],
            den: [1.0, -1.0, 0.0],
        })
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
