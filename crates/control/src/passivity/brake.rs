use super::PassivityLimits;
use crate::Real;

/// The damping a passivity controller adds to take back an energy
/// deficit over one tick, within its limits: `α = -E / (T v²)` (N s/m),
/// capped at the limits' most, and none below their velocity floor, where
/// the damping it would need grows as `1/v²` and the velocity is
/// quantisation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Brake<R> {
    /// `-1e-9 / T` (J per nJ per s): energies are booked in nJ.
    neg_j_per_nj_per_s: R,
    max_damping_nspm: R,
    /// The velocity floor, squared (m²/s²).
    min_velocity_sq: R,
}

impl<R: Real> Brake<R> {
    pub(crate) fn new(l: &PassivityLimits) -> Self {
        Brake {
            neg_j_per_nj_per_s: -R::M_PER_NM / R::of(l.period_s),
            max_damping_nspm: R::of(l.max_damping_nspm),
            min_velocity_sq: R::of(l.min_velocity_mps) * R::of(l.min_velocity_mps),
        }
    }

    /// The damping (N s/m) for the energy `energy_nj` (nJ, below zero: a
    /// deficit) at the velocity `v` (m/s).
    #[inline(always)]
    pub(crate) fn damping(&self, energy_nj: R, v: R) -> R {
        let v2 = v * v;
        let fast_enough = v2 >= self.min_velocity_sq;
        if !fast_enough {
            return R::ZERO;
        }
        (energy_nj * self.neg_j_per_nj_per_s / v2).at_most(self.max_damping_nspm)
    }
}
