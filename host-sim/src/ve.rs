//! The scene's VE: the control crate's VEs, or the building-block world.

use crate::blocks::Blocks;
use twoport_control::ve::{
    BilateralConstraint, Causality, CursorMass, Port, Spring, TrapezoidalSpring, UnilateralWall,
    VeOutput, VeTransfer, VirtualEnvironment,
};
use twoport_control::Position;

/// One of the VEs a scene can name.
#[derive(Clone, Debug)]
pub enum SceneVe {
    /// A free cursor mass.
    Cursor(CursorMass),
    /// A unilateral wall.
    Wall(UnilateralWall),
    /// A fixed point.
    Bilateral(BilateralConstraint),
    /// A spring-damper to an anchor.
    Spring(Spring),
    /// A lossless (trapezoidal) spring-damper to an anchor.
    TrapezoidalSpring(TrapezoidalSpring),
    /// The building-block world.
    Blocks(Box<Blocks>),
}

macro_rules! each {
    ($self:expr, $v:ident => $e:expr) => {
        match $self {
            SceneVe::Cursor($v) => $e,
            SceneVe::Wall($v) => $e,
            SceneVe::Bilateral($v) => $e,
            SceneVe::Spring($v) => $e,
            SceneVe::TrapezoidalSpring($v) => $e,
            SceneVe::Blocks($v) => $e,
        }
    };
}

impl VirtualEnvironment for SceneVe {
    fn causality(&self) -> Causality {
        each!(self, v => v.causality())
    }
    fn step(&mut self, port: Port) -> VeOutput {
        each!(self, v => v.step(port))
    }
    fn reset(&mut self, x: Position) {
        each!(self, v => v.reset(x))
    }
    fn position(&self) -> Position {
        each!(self, v => v.position())
    }
    fn tf(&self) -> VeTransfer {
        each!(self, v => v.tf())
    }
}
