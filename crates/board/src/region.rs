//! The gains the designer proved absolutely stable, shipped with the
//! firmware so that the board can refuse anything else.

/// What a region bounds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Bound {
    /// Impedance display: the greatest coupling stiffness `k` (N/m) for each
    /// coupling damping `b`.
    MaxStiffness,
    /// Admittance display (for one regulator): the least coupling mass `m`
    /// (kg) for each coupling damping `b`.
    MinMass,
}

/// A proven region: a limit for each damping on an increasing grid.
/// Between grid points the more conservative neighbour counts, less a
/// margin, since the true limit need not be monotone or convex between
/// samples; outside the grid nothing is proven.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Region<const N: usize> {
    bound: Bound,
    damping_nspm: [f32; N],
    limit: [f32; N],
    /// For `MinMass`: the regulator `(k_p, b_p)` the limits were proven for.
    regulator: Option<(f32, f32)>,
    /// Relative margin taken off (or added to) interpolated limits.
    margin: f32,
}

/// Why a region could not be built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RegionError {
    /// The damping grid is not strictly increasing and positive.
    Grid,
    /// A limit is not finite and positive.
    Limit,
}

impl<const N: usize> Region<N> {
    /// A region; `regulator` is required for [`Bound::MinMass`].
    pub fn new(
        bound: Bound,
        damping_nspm: [f32; N],
        limit: [f32; N],
        regulator: Option<(f32, f32)>,
    ) -> Result<Self, RegionError> {
        let increasing = damping_nspm.windows(2).all(|w| w[0] < w[1]);
        if N == 0
            || !increasing
            || damping_nspm[0].partial_cmp(&0.0) != Some(core::cmp::Ordering::Greater)
        {
            return Err(RegionError::Grid);
        }
        if limit.iter().any(|l| !(l.is_finite() && *l > 0.0)) {
            return Err(RegionError::Limit);
        }
        Ok(Region {
            bound,
            damping_nspm,
            limit,
            regulator,
            margin: 0.01,
        })
    }

    /// What it bounds.
    pub fn bound(&self) -> Bound {
        self.bound
    }

    /// The regulator a `MinMass` region was proven for.
    pub fn regulator(&self) -> Option<(f32, f32)> {
        self.regulator
    }

    /// The proven limit at damping `b`, or `None` off the grid.
    pub fn limit_at(&self, b_nspm: f32) -> Option<f32> {
        let g = &self.damping_nspm;
        let on_grid = b_nspm >= g[0] && b_nspm <= g[N - 1];
        if !on_grid {
            return None;
        }
        if let Some(i) = g.iter().position(|x| *x == b_nspm) {
            return Some(self.limit[i]);
        }
        let i = g.iter().position(|x| *x > b_nspm)?;
        let (a, c) = (self.limit[i - 1], self.limit[i]);
        Some(match self.bound {
            Bound::MaxStiffness => a.min(c) * (1.0 - self.margin),
            Bound::MinMass => a.max(c) * (1.0 + self.margin),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolation_is_conservative_and_off_grid_is_unproven() {
        let r = Region::new(
            Bound::MaxStiffness,
            [30.0, 60.0, 90.0],
            [46_000.0, 51_400.0, 51_000.0],
            None,
        )
        .unwrap();
        assert_eq!(r.limit_at(60.0), Some(51_400.0));
        assert_eq!(r.limit_at(75.0), Some(51_000.0 * 0.99));
        assert_eq!(r.limit_at(29.0), None);
        assert_eq!(r.limit_at(f32::NAN), None);
        let m = Region::new(
            Bound::MinMass,
            [300.0, 500.0],
            [6.0, 5.0],
            Some((51_000.0, 90.0)),
        )
        .unwrap();
        assert_eq!(m.limit_at(400.0), Some(6.0 * 1.01));
        assert_eq!(
            Region::new(Bound::MinMass, [1.0, 1.0], [1.0, 1.0], None),
            Err(RegionError::Grid)
        );
        assert_eq!(
            Region::new(Bound::MinMass, [1.0, 2.0], [1.0, f32::NAN], None),
            Err(RegionError::Limit)
        );
    }
}
