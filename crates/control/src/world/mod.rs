//! Virtual environments of `N` Cartesian axes, for the
//! [`Servo`](crate::servo::Servo). On one axis, every
//! [`VirtualEnvironment`] is a world.
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

mod held;
pub mod vbb;

pub use held::{Contact, Held};

use crate::ve::{Port, VeOutput, VeParam, VeTransfer, VirtualEnvironment};
use crate::{ParamError, Position, Real};

/// A virtual environment of `N` Cartesian axes stepped once per tick
/// against one coupling [`Port`] per axis. `step` must not allocate, panic
/// or loop without bound, and must leave its state unchanged when a port
/// holds a non-finite number.
pub trait World<R: Real, const N: usize> {
    /// Solve this tick exactly against every axis's coupling and commit.
    fn step_axes(&mut self, ports: &[Port<R>; N]) -> [VeOutput<R>; N];
    /// Put the coupled point at rest at `x`.
    fn reset_axes(&mut self, x: &[Position; N]);
    /// The point each axis's coupling holds, per axis (see
    /// [`VirtualEnvironment::position`]).
    fn positions(&self) -> [Position; N];
    /// [`positions`](Self::positions) minus `from`, per axis, in metres,
    /// with any sub-nanometre part the world carries.
    #[inline]
    fn offsets_m(&self, from: &[Position; N]) -> [R; N] {
        let x = self.positions();
        core::array::from_fn(|i| x[i].nm_from::<R>(from[i]) * R::M_PER_NM)
    }
    /// Axis `axis`'s law in the z-domain, the others held still (for a
    /// piecewise law, the piece its documentation names).
    fn axis_tf(&self, axis: usize) -> VeTransfer;
    /// Set a parameter of axis `axis`'s VE; a world without it refuses,
    /// naming it (see [`VirtualEnvironment::set_param`]).
    fn set_axis_param(&mut self, axis: usize, p: VeParam) -> Result<(), ParamError> {
        let _ = axis;
        Err(p.unsupported())
    }
}

/// One axis's world is a one-axis VE.
impl<R: Real, V: VirtualEnvironment<R>> World<R, 1> for V {
    #[inline(always)]
    fn step_axes(&mut self, [port]: &[Port<R>; 1]) -> [VeOutput<R>; 1] {
        [self.step(*port)]
    }

    #[inline(always)]
    fn reset_axes(&mut self, [x]: &[Position; 1]) {
        self.reset(*x);
    }

    #[inline(always)]
    fn positions(&self) -> [Position; 1] {
        [self.position()]
    }

    #[inline(always)]
    fn offsets_m(&self, [from]: &[Position; 1]) -> [R; 1] {
        [self.offset_m(*from)]
    }

    fn axis_tf(&self, axis: usize) -> VeTransfer {
        match axis {
            0 => self.tf(),
            _ => VeTransfer::Impedance(crate::ZTransfer::gain(0.0)),
        }
    }

    fn set_axis_param(&mut self, axis: usize, p: VeParam) -> Result<(), ParamError> {
        match axis {
            0 => self.set_param(p),
            _ => Err(p.unsupported()),
        }
    }
}

/// `N` one-axis VEs (2 to 8), one per axis, that do not interact: a wall along z and
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
/// let out = w.step_axes(&ports);
/// // Each axis answers as its wall alone would.
/// for (o, p) in out.iter().zip(ports) {
///     assert_eq!(*o, wall.clone().step(p));
/// }
/// # Ok::<(), twoport_control::ParamError>(())
/// ```
#[derive(Clone, Copy, Debug)]
pub struct PerAxis<V, const N: usize>(pub [V; N]);

// (Two axes and more: on one axis the VE is the world itself, and a
// blanket impl for every `N` would overlap that one.)
macro_rules! per_axis {
    ($($n:literal)*) => {$(
        impl<R: Real, V: VirtualEnvironment<R>> World<R, $n> for PerAxis<V, $n> {
            #[inline(always)]
            fn step_axes(&mut self, ports: &[Port<R>; $n]) -> [VeOutput<R>; $n] {
                let mut out = [VeOutput {
                    velocity_mps: R::ZERO,
                    force_n: R::ZERO,
                }; $n];
                for ((o, ve), port) in out.iter_mut().zip(&mut self.0).zip(ports) {
                    *o = ve.step(*port);
                }
                out
            }

            fn reset_axes(&mut self, x: &[Position; $n]) {
                for (ve, x) in self.0.iter_mut().zip(x) {
                    ve.reset(*x);
                }
            }

            #[inline(always)]
            fn positions(&self) -> [Position; $n] {
                core::array::from_fn(|i| self.0[i].position())
            }

            #[inline(always)]
            fn offsets_m(&self, from: &[Position; $n]) -> [R; $n] {
                core::array::from_fn(|i| self.0[i].offset_m(from[i]))
            }

            fn axis_tf(&self, axis: usize) -> VeTransfer {
                match self.0.get(axis) {
                    Some(ve) => ve.tf(),
                    None => VeTransfer::Impedance(crate::ZTransfer::gain(0.0)),
                }
            }

            fn set_axis_param(&mut self, axis: usize, p: VeParam) -> Result<(), ParamError> {
                match self.0.get_mut(axis) {
                    Some(ve) => ve.set_param(p),
                    None => Err(p.unsupported()),
                }
            }
        }
    )*};
}

per_axis!(2 3 4 5 6 7 8);
