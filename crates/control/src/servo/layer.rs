//! What runs between the device's port and the display's element (the
//! coupling with its VE): nothing by default, a passivity controller on
//! request.

use super::Display;
use crate::passivity::{ParallelDamper, SeriesDamper};
use crate::{Position, Real};

/// A stage between the device's port and the display's element. The servo
/// calls it each tick its laws run; every method defaults to passing its
/// input through, so a layer implements the display it serves and
/// [`Direct`], the default, costs nothing.
///
/// Forces are in the servo's sign: positive resists positive actuator
/// motion (the paper's `f_a`), except the admittance display's measured
/// force, which is the load cell's (on the handle along `+x`).
pub trait PortLayer<R: Real = f32> {
    /// Whether a board whose force comes later than its proof allows
    /// runs on with this layer [`engage`](Self::engage)d rather than
    /// fault: a passivity controller [`OnDemand`].
    const GUARDS_LATENCY: bool = false;

    /// Engage the layer, the port at `x` ([`OnDemand`]'s); any other is
    /// always on.
    #[inline(always)]
    fn engage(&mut self, x: Position) {
        let _ = x;
    }

    /// Let a layer [`OnDemand`] go idle again.
    #[inline(always)]
    fn disengage(&mut self) {}

    /// The display this layer serves; `None` for either.
    fn display(&self) -> Option<Display> {
        None
    }

    /// Impedance display: the position and velocity (m/s) the element is
    /// given for the device's `x` and `v_mps` (a study of latency gives it
    /// an older sample).
    #[inline(always)]
    fn element_motion(&mut self, x: Position, v_mps: R) -> (Position, R) {
        (x, v_mps)
    }

    /// Impedance display: the force (N) to command for the element's
    /// `force_n`, the device being at `x` moving at `v_mps` (m/s).
    #[inline(always)]
    fn impedance_force(&mut self, x: Position, v_mps: R, force_n: R) -> R {
        let _ = (x, v_mps);
        force_n
    }

    /// Admittance display: the velocity (m/s) to command for the element's
    /// `velocity_mps` answering the measured force `force_n` (N).
    #[inline(always)]
    fn admittance_velocity(&mut self, force_n: R, velocity_mps: R) -> R {
        let _ = force_n;
        velocity_mps
    }

    /// The force (N) the safety layer let through this tick, held until the
    /// next.
    #[inline(always)]
    fn held(&mut self, force_n: R) {
        let _ = force_n;
    }

    /// Forget the past: the servo re-aligns to the device, at `x`.
    #[inline(always)]
    fn reset(&mut self, x: Position) {
        let _ = x;
    }
}

/// No layer: the element's output is the servo's command.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Direct;

impl<R: Real> PortLayer<R> for Direct {}

/// The impedance display's passivity controller at the device's port: it
/// watches the element (coupling and VE) take the device's motion and put
/// out a force.
impl<R: Real> PortLayer<R> for SeriesDamper<R> {
    fn display(&self) -> Option<Display> {
        Some(Display::Impedance)
    }

    #[inline(always)]
    fn impedance_force(&mut self, x: Position, v_mps: R, force_n: R) -> R {
        // The safety layer limits the force, and `held` books what it let
        // through.
        self.correct(x, v_mps, force_n)
    }

    #[inline(always)]
    fn held(&mut self, force_n: R) {
        self.hold(force_n);
    }

    fn reset(&mut self, x: Position) {
        SeriesDamper::reset(self, x);
    }
}

/// The admittance display's passivity controller at the load cell: it
/// watches the element (coupling and VE) take the measured force and put
/// out the velocity the device is commanded to.
impl<R: Real> PortLayer<R> for ParallelDamper<R> {
    fn display(&self) -> Option<Display> {
        Some(Display::Admittance)
    }

    #[inline(always)]
    fn admittance_velocity(&mut self, force_n: R, velocity_mps: R) -> R {
        self.step(force_n, velocity_mps)
    }

    fn reset(&mut self, _: Position) {
        ParallelDamper::reset(self);
    }
}

/// A passivity controller `L` engaged on demand: idle (the element's
/// output passes through, bit for bit, and nothing is booked) until its
/// board engages it, on a force later than the board's proof allows;
/// then `L`, its element taken at rest from the port's position there,
/// until the board lets it go idle again.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OnDemand<L> {
    layer: L,
    engaged: bool,
}

impl<L> OnDemand<L> {
    /// `layer`, idle.
    pub fn new(layer: L) -> Self {
        OnDemand {
            layer,
            engaged: false,
        }
    }

    /// Whether it is engaged.
    pub fn engaged(&self) -> bool {
        self.engaged
    }

    /// The controller.
    pub fn layer(&self) -> &L {
        &self.layer
    }
}

impl<R: Real, L: PortLayer<R>> PortLayer<R> for OnDemand<L> {
    const GUARDS_LATENCY: bool = true;

    fn display(&self) -> Option<Display> {
        self.layer.display()
    }

    #[inline(always)]
    fn element_motion(&mut self, x: Position, v_mps: R) -> (Position, R) {
        if self.engaged {
            self.layer.element_motion(x, v_mps)
        } else {
            (x, v_mps)
        }
    }

    #[inline(always)]
    fn impedance_force(&mut self, x: Position, v_mps: R, force_n: R) -> R {
        if self.engaged {
            self.layer.impedance_force(x, v_mps, force_n)
        } else {
            force_n
        }
    }

    #[inline(always)]
    fn admittance_velocity(&mut self, force_n: R, velocity_mps: R) -> R {
        if self.engaged {
            self.layer.admittance_velocity(force_n, velocity_mps)
        } else {
            velocity_mps
        }
    }

    #[inline(always)]
    fn held(&mut self, force_n: R) {
        if self.engaged {
            self.layer.held(force_n);
        }
    }

    fn reset(&mut self, x: Position) {
        self.layer.reset(x);
    }

    fn engage(&mut self, x: Position) {
        if !self.engaged {
            self.engaged = true;
            self.layer.reset(x);
        }
    }

    fn disengage(&mut self) {
        self.engaged = false;
    }
}
