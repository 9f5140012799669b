//! Virtual environments of `N` Cartesian axes, for the multi-axis servo
//! ([`AxesServo`](crate::servo::AxesServo)).
//!
//! Each axis has its own coupling, and each coupling hands the world its
//! law for this tick as a [`Port`] (`f = f0 - z v` along that axis). The
//! world answers all `N` ports at once, so a body that moves in 3-D (a
//! cursor that slides along a block's face, a block lifted off a stack) is
//! solved with every axis's coupling in the same tick, and the algebraic
//! loops stay exact, as they are on one axis.
//!
//! Sign convention: as for [`VirtualEnvironment`], per axis: `f` is the
//! force applied *to* the world along the axis (N), `v` its velocity along
//! the axis (m/s). Axis 0 is x, 1 is y, 2 is z.

pub mod vbb;

use crate::ve::{Port, VeOutput, VeTransfer, VirtualEnvironment};
use crate::{Position, Real};

/// A virtual environment of `N` Cartesian axes stepped once per tick
/// against one coupling [`Port`] per axis. `step` must not allocate, panic
/// or loop without bound, and must leave its state unchanged when a port
/// holds a non-finite number.
pub trait World<R: Real, const N: usize> {
    /// Solve this tick exactly against every axis's coupling and commit.
    fn step(&mut self, ports: &[Port<R>; N]) -> [VeOutput<R>; N];
    /// Put the coupled point at rest at `x`.
    fn reset(&mut self, x: &[Position; N]);
    /// The point each axis's coupling holds, per axis (see
    /// [`VirtualEnvironment::position`]).
    fn position(&self) -> [Position; N];
    /// [`position`](Self::position) minus `from`, per axis, in metres, with
    /// any sub-nanometre part the world carries.
    #[inline]
    fn offset_m(&self, from: &[Position; N]) -> [R; N] {
        let x = self.position();
        core::array::from_fn(|i| x[i].nm_from::<R>(from[i]) * R::M_PER_NM)
    }
    /// Axis `axis`'s law in the z-domain, the others held still (for a
    /// piecewise law, the piece its documentation names).
    fn tf(&self, axis: usize) -> VeTransfer;
}

/// `N` one-axis VEs, one per axis, that do not interact: a wall along z and
/// free space along x and y, or the same spring on every axis.
///
/// # Examples
///
/// ```
/// use twoport_control::ve::{Port, Solid, UnilateralWall, VirtualEnvironment};
/// use twoport_control::world::{PerAxis, World};
/// use twoport_control::Position;
/// let wall = UnilateralWall::new(20_000.0, 0.0, Position::ZERO, Solid::Above, 1e-3, Position::ZERO)?;
/// let mut w = PerAxis([wall; 3]);
/// // x pushed into its wall, y pulled away from its own, z left alone.
/// let ports = [5.0, -5.0, 0.0].map(|f0_n| Port { f0_n, z_nspm: 100.0 });
/// let out = w.step(&ports);
/// // Each axis answers as its wall alone would.
/// for (o, p) in out.iter().zip(ports) {
///     assert_eq!(*o, wall.clone().step(p));
/// }
/// # Ok::<(), twoport_control::ParamError>(())
/// ```
#[derive(Clone, Copy, Debug)]
pub struct PerAxis<V, const N: usize>(pub [V; N]);

impl<R: Real, V: VirtualEnvironment<R>, const N: usize> World<R, N> for PerAxis<V, N> {
    #[inline(always)]
    fn step(&mut self, ports: &[Port<R>; N]) -> [VeOutput<R>; N] {
        let mut out = [VeOutput {
            velocity_mps: R::ZERO,
            force_n: R::ZERO,
        }; N];
        for ((o, ve), port) in out.iter_mut().zip(&mut self.0).zip(ports) {
            *o = ve.step(*port);
        }
        out
    }

    fn reset(&mut self, x: &[Position; N]) {
        for (ve, x) in self.0.iter_mut().zip(x) {
            ve.reset(*x);
        }
    }

    fn position(&self) -> [Position; N] {
        core::array::from_fn(|i| self.0[i].position())
    }

    #[inline(always)]
    fn offset_m(&self, from: &[Position; N]) -> [R; N] {
        core::array::from_fn(|i| self.0[i].offset_m(from[i]))
    }

    fn tf(&self, axis: usize) -> VeTransfer {
        match self.0.get(axis) {
            Some(ve) => ve.tf(),
            None => VeTransfer::Impedance(crate::ZTransfer::gain(0.0)),
        }
    }
}
