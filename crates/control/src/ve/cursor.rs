//! Free bodies: the cursor (or a grabbed block) as a mass. One type,
//! [`Cursor`], holds the body; its [`Scheme`] says how the force is
//! integrated: backward Euler ([`CursorMass`]), the trapezoidal rule
//! ([`LosslessCursor`]) or the paper's explicit integrator
//! ([`ExplicitCursor`]).

use core::fmt::Debug;

use super::{Causality, Port, VeOutput, VeTransfer, VirtualEnvironment};
use crate::{param, Integrator, ParamError, Position, Real, ZTransfer};

/// The smallest cursor mass the paper's experiments ran stably (kg).
pub const PAPER_MIN_CURSOR_MASS_KG: f32 = 0.25;

/// How a [`Cursor`] integrates the force it meets into its velocity.
pub trait Scheme<R: Real>: Copy + Debug {
    /// The scheme for a body with `T / m` = `t_over_m` (s/kg).
    fn new(t_over_m: R) -> Self;

    /// One tick from last tick's velocity `v_mps` (m/s) and force `f_n`
    /// (N): the port's answer, and what the body commits, `(v[k], f[k],
    /// the velocity its position integrates)`, or `None` when that is not
    /// finite (the body then stays as it was).
    fn step(&mut self, v_mps: R, f_n: R, port: Port<R>) -> (VeOutput<R>, Option<[R; 3]>);

    /// The admittance `V/F` the coupling sees.
    fn tf(&self) -> VeTransfer;
}

/// A free cursor (or grabbed block) of mass `m`, at rest at first,
/// integrated by the scheme `S`. Admittance causality.
#[derive(Clone, Copy, Debug)]
pub struct Cursor<R, S> {
    mass_kg: f32,
    velocity_mps: R,
    /// Last tick's force (N).
    force_n: R,
    x: Integrator<R>,
    scheme: S,
}

/// `v[k] = v[k-1] + T f[k] / m`, backward Euler, which is discrete-time
/// passive for every `m > 0`. The paper's VBB needed `m >= 0.25 kg` with
/// its explicit integrator ([`PAPER_MIN_CURSOR_MASS_KG`]).
pub type CursorMass<R = f32> = Cursor<R, Implicit<R>>;

/// A lossless mass: its velocity integrates the force by the trapezoidal
/// rule, `v[k] = v[k-1] + T (f[k] + f[k-1]) / (2 m)`. Its admittance
/// `(T/2m)(1 + z^-1)/(1 - z^-1)` is imaginary on the unit circle: it
/// stores and returns energy and dissipates none, the edge of the passive
/// masses (backward Euler's [`CursorMass`] dissipates). The designer's
/// `verify` terminates a loop with it; a scene may run it.
pub type LosslessCursor<R = f32> = Cursor<R, Lossless<R>>;

/// A free cursor integrated explicitly, as the paper's building blocks
/// were: the velocity by forward Euler on last tick's force,
/// `v[k] = v[k-1] + T f[k-1] / m`, the position by the trapezoidal rule,
/// `x[k] = x[k-1] + T (v[k] + v[k-1]) / 2`. The coupling sees the mean of
/// the two velocities, so that its spring acts on that position. Unlike
/// [`CursorMass`] this is not passive: with a stiff coupling a light
/// cursor gives energy out and the loop rings, which is why the paper's
/// cursor could not go below [`PAPER_MIN_CURSOR_MASS_KG`]. It is here to
/// study that, and what the passivity layer makes of it.
pub type ExplicitCursor<R = f32> = Cursor<R, Explicit<R>>;

impl<S: Scheme<f32>> Cursor<f32, S> {
    /// A mass of `mass_kg` (kg) at rest at `x`, period `period_s` (s).
    pub fn new(mass_kg: f32, period_s: f32, x: Position) -> Result<Self, ParamError> {
        Self::new_in(mass_kg, period_s, x)
    }
}

impl<R: Real, S: Scheme<R>> Cursor<R, S> {
    /// [`Cursor::new`] computing in `R`.
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
        Ok(Cursor {
            mass_kg: m,
            velocity_mps: R::ZERO,
            force_n: R::ZERO,
            x: Integrator::new_in(t, x),
            scheme: S::new(R::of(t) / R::of(m)),
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

impl<R: Real, S: Scheme<R>> VirtualEnvironment<R> for Cursor<R, S> {
    fn causality(&self) -> Causality {
        Causality::Admittance
    }

    fn step(&mut self, port: Port<R>) -> VeOutput<R> {
        let (out, commit) = self.scheme.step(self.velocity_mps, self.force_n, port);
        if let Some([v, f, moved]) = commit {
            self.velocity_mps = v;
            self.force_n = f;
            self.x.step(moved);
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

    fn tf(&self) -> VeTransfer {
        self.scheme.tf()
    }
}

/// Backward Euler on this tick's force ([`CursorMass`]).
#[derive(Clone, Copy, Debug)]
pub struct Implicit<R> {
    t_over_m: R,
    /// The port feedthrough `z` last met and `1 / (1 + (T/m) z)`: a
    /// coupling's `z` changes only with its gains, so the loop solve
    /// multiplies instead of dividing (the division's latency sat on the
    /// admittance display's sensor-to-force chain).
    port_z: R,
    inv_den: R,
}

impl<R: Real> Scheme<R> for Implicit<R> {
    fn new(t_over_m: R) -> Self {
        Implicit {
            t_over_m,
            port_z: R::ZERO,
            inv_den: R::ONE,
        }
    }

    fn step(&mut self, v_mps: R, _f_n: R, port: Port<R>) -> (VeOutput<R>, Option<[R; 3]>) {
        // (A NaN z never equals the one kept, so it gives a NaN answer,
        // which is not committed, and the next good z recomputes.)
        let (n, m) = port.admittance_quotient(v_mps, self.t_over_m);
        if port.z_nspm != self.port_z {
            self.port_z = port.z_nspm;
            self.inv_den = R::ONE / m;
        }
        let out = port.at(n * self.inv_den);
        let v = out.velocity_mps;
        (out, v.is_finite().then_some([v, R::ZERO, v]))
    }

    /// `V/F = (T/m) / (1 - z^-1)`.
    fn tf(&self) -> VeTransfer {
        VeTransfer::Admittance(ZTransfer::first_order([self.t_over_m.to_f64(), 0.0], -1.0))
    }
}

/// The trapezoidal rule on the force ([`LosslessCursor`]).
#[derive(Clone, Copy, Debug)]
pub struct Lossless<R> {
    /// `T / (2 m)`.
    h: R,
}

impl<R: Real> Scheme<R> for Lossless<R> {
    fn new(t_over_m: R) -> Self {
        Lossless {
            h: R::HALF * t_over_m,
        }
    }

    fn step(&mut self, v_mps: R, f_n: R, port: Port<R>) -> (VeOutput<R>, Option<[R; 3]>) {
        // v = (v[k-1] + h f[k-1]) + h f[k], met with the port's f = f0 - z v.
        let out = port.solve_admittance(v_mps + self.h * f_n, self.h);
        let (v, f) = (out.velocity_mps, out.force_n);
        (out, (v.is_finite() && f.is_finite()).then_some([v, f, v]))
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

/// Forward Euler on last tick's force, the position by the trapezoidal
/// rule ([`ExplicitCursor`]).
#[derive(Clone, Copy, Debug)]
pub struct Explicit<R> {
    t_over_m: R,
}

impl<R: Real> Scheme<R> for Explicit<R> {
    fn new(t_over_m: R) -> Self {
        Explicit { t_over_m }
    }

    fn step(&mut self, v_mps: R, f_n: R, port: Port<R>) -> (VeOutput<R>, Option<[R; 3]>) {
        let v_new = v_mps + self.t_over_m * f_n;
        let mean = (v_mps + v_new) * R::of(0.5);
        let out = port.at(mean);
        let ok = out.force_n.is_finite() && v_new.is_finite();
        (out, ok.then_some([v_new, out.force_n, mean]))
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
