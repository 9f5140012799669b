//! Velocity from sampled positions.

use crate::{param, ParamError, Position, Real, ZTransfer};

/// First-difference velocity estimate `v[k] = (x[k] - x[k-1]) / T` (m/s),
/// computed from integer positions so that it has no cancellation error.
/// This is the estimator of the paper's impedance display (Fig. 5).
#[derive(Clone, Copy, Debug)]
pub struct FirstDifference<R = f32> {
    /// `1e-9 / T`: (m/s) per nanometre moved in one tick.
    mps_per_nm: R,
    prev: Position,
}

impl FirstDifference {
    /// An estimator for sample period `period_s` (s), at rest at `x`.
    ///
    /// # Examples
    ///
    /// ```
    /// use twoport_control::{FirstDifference, Position};
    /// let mut d = FirstDifference::new(1e-3, Position::ZERO)?;
    /// // 1 µm in one 1 ms tick is 1 mm/s.
    /// let v = d.step(Position::from_nm(1000));
    /// assert!((v - 1e-3).abs() < 1e-9);
    /// # Ok::<(), twoport_control::ParamError>(())
    /// ```
    pub fn new(period_s: f32, x: Position) -> Result<Self, ParamError> {
        Self::new_in(period_s, x)
    }
}

impl<R: Real> FirstDifference<R> {
    /// [`FirstDifference::new`] computing in `R`.
    pub fn new_in(period_s: f32, x: Position) -> Result<Self, ParamError> {
        let t = param::positive("T (s)", period_s)?;
        Ok(FirstDifference {
            // Divided in R: an f64 law's constant is the f64 quotient. One
            // constant, so the tick multiplies once between the encoder
            // and the coupling (the start of the tick's longest chain).
            mps_per_nm: R::M_PER_NM / R::of(t),
            prev: x,
        })
    }

    /// Forget the history: the next estimate is relative to `x`.
    pub fn reset(&mut self, x: Position) {
        self.prev = x;
    }

    /// The estimate for the new sample `x[k]` (m/s).
    pub fn step(&mut self, x: Position) -> R {
        let v = x.nm_from::<R>(self.prev) * self.mps_per_nm;
        self.prev = x;
        v
    }

    /// `V(z)/X(z) = (1 - z^-1) / T` ((m/s) per m).
    pub fn tf(&self) -> ZTransfer {
        let g = self.mps_per_nm.to_f64() * 1.0e9;
        ZTransfer::first_order([g, -g], 0.0)
    }
}
