//! The gains the designer proved absolutely stable, shipped with the
//! firmware so that the board can refuse anything else: one region, or one
//! per axis of a board of several ([`check_axes`]).

use twoport_control::servo::{Display, Gains};

/// A region file the designer wrote (`twoport region ... --rust`) as the
/// invoking module's `region`, with its `REGION_POINTS` and its
/// `proven_region()`: one image's region, declared in one line.
macro_rules! shipped_region {
    ($(#[$doc:meta])* $file:literal) => {
        $(#[$doc])*
        // (A log grid may step by √2: a damping, not the constant.)
        #[allow(clippy::approx_constant)]
        pub mod region {
            use $crate::region::Bound;
            include!($file);
        }

        /// Grid points of [`region`].
        pub const REGION_POINTS: usize = region::DAMPING_NSPM.len();

        /// The region as a `Region`, proven for its latency.
        pub fn proven_region(
        ) -> Result<$crate::region::Region<REGION_POINTS>, $crate::region::RegionError> {
            $crate::region::Region::new(
                region::BOUND,
                region::DAMPING_NSPM,
                region::LIMIT,
                region::REGULATOR,
            )?
            .with_latency(region::LATENCY_S)
        }
    };
}
pub(crate) use shipped_region;
use twoport_link::{AxisRefusal, ProvenRegion, Refusal};

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
    /// The latency from sampling to the force (s) the limits are proven
    /// for: a board whose force comes later than this is outside them.
    latency_s: f32,
}

/// Why a region could not be built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum RegionError {
    /// The damping grid is not strictly increasing and positive.
    Grid,
    /// A limit is not finite and positive.
    Limit,
    /// The latency is not finite and at least zero.
    Latency,
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
            latency_s: 0.0,
        })
    }

    /// The same region, its limits proven for a latency of `latency_s`
    /// (s) from sampling to the force (default: none).
    pub fn with_latency(mut self, latency_s: f32) -> Result<Self, RegionError> {
        if !(latency_s.is_finite() && latency_s >= 0.0) {
            return Err(RegionError::Latency);
        }
        self.latency_s = latency_s;
        Ok(self)
    }

    /// The latency from sampling to the force (s) its limits are proven
    /// for.
    pub fn latency_s(&self) -> f32 {
        self.latency_s
    }

    /// What it bounds.
    pub fn bound(&self) -> Bound {
        self.bound
    }

    /// The regulator a `MinMass` region was proven for.
    pub fn regulator(&self) -> Option<(f32, f32)> {
        self.regulator
    }

    /// Whether `g` is inside this region, for a servo running `display`;
    /// the reason when not.
    pub fn check(&self, display: Display, g: &Gains) -> Result<(), Refusal> {
        if !g.all_finite() {
            return Err(Refusal::NotFinite);
        }
        if g.display() != display {
            return Err(Refusal::WrongDisplay);
        }
        let (limit, within) = match *g {
            Gains::Impedance(g) if self.bound() == Bound::MaxStiffness => {
                if g.k_npm < 0.0 || g.b_nspm < 0.0 {
                    return Err(Refusal::OutOfRange);
                }
                let limit = self.limit_at(g.b_nspm);
                (limit, limit.is_some_and(|kmax| g.k_npm <= kmax))
            }
            Gains::Admittance(g) if self.bound() == Bound::MinMass => {
                if g.m_kg <= 0.0 || g.b_nspm <= 0.0 || g.kp_npm < 0.0 || g.bp_nspm < 0.0 {
                    return Err(Refusal::OutOfRange);
                }
                // The region holds for the regulator it was proven with.
                match self.regulator() {
                    Some((kp, bp)) if kp == g.kp_npm && bp == g.bp_nspm => {}
                    Some((kp, _)) => return Err(Refusal::NotProvenStable { limit: kp }),
                    None => return Err(Refusal::NotProvenStable { limit: 0.0 }),
                }
                let limit = self.limit_at(g.b_nspm);
                (limit, limit.is_some_and(|mmin| g.m_kg >= mmin))
            }
            _ => return Err(Refusal::WrongDisplay),
        };
        match (within, limit) {
            (true, _) => Ok(()),
            (false, limit) => Err(Refusal::NotProvenStable {
                limit: limit.unwrap_or(0.0),
            }),
        }
    }

    /// The region's envelope as the link's specification gives it: its
    /// damping range and its extreme limit (the stiffest spring, or the
    /// lightest mass) with the damping it is proven at.
    pub fn envelope(&self) -> ProvenRegion {
        let g = &self.damping_nspm;
        let (b_min_nspm, b_max_nspm) = (g[0], g[N - 1]);
        let better = |a: f32, c: f32| match self.bound {
            Bound::MaxStiffness => c > a,
            Bound::MinMass => c < a,
        };
        let best = (1..N).fold(0, |i, j| {
            if better(self.limit[i], self.limit[j]) {
                j
            } else {
                i
            }
        });
        let (limit, at) = (self.limit[best], g[best]);
        match (self.bound, self.regulator) {
            (Bound::MinMass, Some((kp_npm, bp_nspm))) => ProvenRegion::MinMass {
                kp_npm,
                bp_nspm,
                b_min_nspm,
                b_max_nspm,
                m_min_kg: limit,
                b_at_m_min_nspm: at,
            },
            // A mass region built without its regulator accepts no gains
            // (`check` refuses every one); a zero regulator says so.
            (Bound::MinMass, None) => ProvenRegion::MinMass {
                kp_npm: 0.0,
                bp_nspm: 0.0,
                b_min_nspm,
                b_max_nspm,
                m_min_kg: limit,
                b_at_m_min_nspm: at,
            },
            (Bound::MaxStiffness, _) => ProvenRegion::MaxStiffness {
                b_min_nspm,
                b_max_nspm,
                k_max_npm: limit,
                b_at_k_max_nspm: at,
            },
        }
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

/// Whether each axis's gains are inside its axis's region, for a servo of
/// `N` axes running `display`; the first axis that is not, and why.
///
/// # Examples
///
/// ```
/// use twoport_board::{check_axes, Bound, Region};
/// use twoport_control::servo::{Display, Gains, ImpedanceGains};
/// use twoport_link::Refusal;
/// let r = Region::new(Bound::MaxStiffness, [10.0, 90.0], [36_385.0, 51_074.0], None).unwrap();
/// let g = |k| Gains::from(ImpedanceGains::new(k, 90.0));
/// assert!(check_axes(&[r; 3], Display::Impedance, &[g(50_000.0); 3]).is_ok());
/// let e = check_axes(&[r; 3], Display::Impedance, &[g(50_000.0), g(50_000.0), g(60_000.0)]);
/// let e = e.unwrap_err();
/// assert_eq!(e.axis, 2);
/// assert!(matches!(e.why, Refusal::NotProvenStable { .. }));
/// ```
pub fn check_axes<const G: usize, const N: usize>(
    regions: &[Region<G>; N],
    display: Display,
    gains: &[Gains; N],
) -> Result<(), AxisRefusal> {
    for (axis, (r, g)) in regions.iter().zip(gains).enumerate() {
        r.check(display, g).map_err(|why| AxisRefusal {
            axis: axis as u8,
            why,
        })?;
    }
    Ok(())
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
            r.envelope(),
            ProvenRegion::MaxStiffness {
                b_min_nspm: 30.0,
                b_max_nspm: 90.0,
                k_max_npm: 51_400.0,
                b_at_k_max_nspm: 60.0,
            }
        );
        let e = r.envelope();
        assert_eq!((e.is_impedance(), e.b_range_nspm()), (true, (30.0, 90.0)));
        assert_eq!((e.limit(), e.regulator()), ((51_400.0, 60.0), None));
        let e = m.envelope();
        assert_eq!((e.is_impedance(), e.limit()), (false, (5.0, 500.0)));
        assert_eq!(e.regulator(), Some((51_000.0, 90.0)));
        assert_eq!(
            m.envelope(),
            ProvenRegion::MinMass {
                kp_npm: 51_000.0,
                bp_nspm: 90.0,
                b_min_nspm: 300.0,
                b_max_nspm: 500.0,
                m_min_kg: 5.0,
                b_at_m_min_nspm: 500.0,
            }
        );
        assert_eq!(
            Region::new(Bound::MinMass, [1.0, 1.0], [1.0, 1.0], None),
            Err(RegionError::Grid)
        );
        assert_eq!(
            Region::new(Bound::MinMass, [1.0, 2.0], [1.0, f32::NAN], None),
            Err(RegionError::Limit)
        );
        assert_eq!(r.latency_s(), 0.0);
        assert_eq!(r.with_latency(25e-6).map(|r| r.latency_s()), Ok(25e-6));
        for bad in [-1e-6, f32::NAN, f32::INFINITY] {
            assert_eq!(r.with_latency(bad), Err(RegionError::Latency));
        }
    }
}
