//! The scene's VE: the control crate's VEs, or the building-block world.

pub(crate) mod from_scene;

use crate::engine::blocks::Blocks;
use twoport_control::passivity::PassiveVe;
use twoport_control::ve::{
    BilateralConstraint, Causality, CursorMass, ExplicitCursor, LosslessCursor, Port, Spring,
    TrapezoidalSpring, UnilateralWall, VeOutput, VeTransfer, VirtualEnvironment,
};
use twoport_control::{Position, Real};

/// One of the VEs a scene can name, computing in `R` (the controller's
/// float type).
#[derive(Clone, Debug)]
pub enum SceneVe<R: Real = f32> {
    /// A free cursor mass.
    Cursor(CursorMass<R>),
    /// A free cursor mass integrated explicitly (the paper's).
    ExplicitCursor(ExplicitCursor<R>),
    /// A lossless cursor mass (trapezoidal).
    LosslessCursor(LosslessCursor<R>),
    /// A unilateral wall.
    Wall(UnilateralWall<R>),
    /// A fixed point.
    Bilateral(BilateralConstraint),
    /// A spring-damper to an anchor.
    Spring(Spring<R>),
    /// A lossless (trapezoidal) spring-damper to an anchor.
    TrapezoidalSpring(TrapezoidalSpring<R>),
    /// The building-block world (host-only, computing in f32 whatever the
    /// controller's type: an f64 controller's port is rounded to it).
    Blocks(Box<Blocks>),
    /// A VE behind the passivity controller at its port.
    Passive(Box<PassiveVe<SceneVe<R>, R>>),
}

/// `$e` on the VE in any variant but the blocks, `$blocks` on those,
/// borrowed as the call says: `each!(&self, ...)` or
/// `each!(&mut self, ...)`.
macro_rules! each {
    (&mut $self:ident, $v:ident => $e:expr, $b:ident => $blocks:expr) => {
        each!(@on &mut *$self, $v => $e, $b => $blocks)
    };
    (&$self:ident, $v:ident => $e:expr, $b:ident => $blocks:expr) => {
        each!(@on &*$self, $v => $e, $b => $blocks)
    };
    (@on $borrowed:expr, $v:ident => $e:expr, $b:ident => $blocks:expr) => {
        match $borrowed {
            SceneVe::Cursor($v) => $e,
            SceneVe::ExplicitCursor($v) => $e,
            SceneVe::LosslessCursor($v) => $e,
            SceneVe::Wall($v) => $e,
            SceneVe::Bilateral($v) => $e,
            SceneVe::Spring($v) => $e,
            SceneVe::TrapezoidalSpring($v) => $e,
            SceneVe::Passive(p) => {
                let $v = p.unbox();
                $e
            }
            SceneVe::Blocks($b) => $blocks,
        }
    };
}

/// A boxed VE as a reference to it, shared or not, so that `each!` calls
/// the same code on it as on the others.
trait Unbox {
    type Out;
    fn unbox(self) -> Self::Out;
}

impl<'a, T> Unbox for &'a Box<T> {
    type Out = &'a T;
    fn unbox(self) -> &'a T {
        self
    }
}

impl<'a, T> Unbox for &'a mut Box<T> {
    type Out = &'a mut T;
    fn unbox(self) -> &'a mut T {
        self
    }
}

impl<R: Real> VirtualEnvironment<R> for SceneVe<R> {
    fn causality(&self) -> Causality {
        each!(&self, v => VirtualEnvironment::<R>::causality(v), b => b.causality())
    }
    fn step(&mut self, port: Port<R>) -> VeOutput<R> {
        each!(&mut self, v => v.step(port), b => {
            let o = b.step(Port {
                f0_n: port.f0_n.to_f32(),
                z_nspm: port.z_nspm.to_f32(),
            });
            VeOutput {
                velocity_mps: R::of(o.velocity_mps),
                force_n: R::of(o.force_n),
            }
        })
    }
    fn reset(&mut self, x: Position) {
        each!(&mut self, v => VirtualEnvironment::<R>::reset(v, x), b => b.reset(x))
    }
    fn position(&self) -> Position {
        each!(&self, v => VirtualEnvironment::<R>::position(v), b => b.position())
    }
    fn offset_m(&self, from: Position) -> R {
        each!(&self, v => VirtualEnvironment::<R>::offset_m(v, from), b => R::of(b.offset_m(from)))
    }
    fn tf(&self) -> VeTransfer {
        each!(&self, v => VirtualEnvironment::<R>::tf(v), b => b.tf())
    }
}
