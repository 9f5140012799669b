//! The bilateral constraint: a VE point that does not move.

use super::{Causality, Port, VeOutput, VeTransfer, VirtualEnvironment};
use crate::{Position, Real, ZTransfer};

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
