//! The admittance display's analyses for one position regulator: each
//! pose's grid, and beside it the points around the regulated loop's
//! lightly damped poles. Those poles are narrow features of the bound
//! (its terms divide by `1 + K_p X_aa^d`, which vanishes at them), and
//! they move with the regulator, so the grid a designer is built with
//! cannot hold them.

use super::{Bound, Pose};
use crate::analysis::{feature_grid, Analysis, GridSpec};
use crate::network::HumanBound;
use twoport_control::ZTransfer;

/// One regulator's analyses and bounds.
#[derive(Debug)]
pub(super) struct Regulated {
    /// `(k_p, b_p)` (N/m, N s/m).
    pub(super) kp: (f64, f64),
    /// Each pose's analysis at its regulated poles (perhaps no points).
    extra: Vec<Analysis>,
    /// The sound and paper bounds on each pose's grid.
    bounds: [Vec<Vec<f64>>; 2],
    /// The same at each pose's regulated poles.
    extra_bounds: [Vec<Vec<f64>>; 2],
}

impl Regulated {
    /// The analyses of `poses` under the regulator `kp` (its transfer
    /// function `k`), with the human bound `human`.
    pub(super) fn new(
        poses: &[Pose],
        kp: (f64, f64),
        k: &ZTransfer,
        human: Option<HumanBound>,
    ) -> Self {
        let extra: Vec<Analysis> = poses
            .iter()
            .map(|p| {
                let features = p.plant.regulated_features(k);
                Analysis::on(
                    &p.plant,
                    &feature_grid(&p.plant, &features, GridSpec::DEFAULT),
                )
            })
            .collect();
        let bounds_on = |a: &Analysis, paper: bool| {
            if a.points.is_empty() {
                Vec::new()
            } else if paper {
                a.paper_admittance_bound(k, human)
            } else {
                a.admittance_bound(k, human)
            }
        };
        let each = |analyses: &[&Analysis], paper: bool| -> Vec<Vec<f64>> {
            analyses.iter().map(|a| bounds_on(a, paper)).collect()
        };
        let grid: Vec<&Analysis> = poses.iter().map(|p| &p.analysis).collect();
        let at: Vec<&Analysis> = extra.iter().collect();
        Regulated {
            kp,
            bounds: [each(&grid, false), each(&grid, true)],
            extra_bounds: [each(&at, false), each(&at, true)],
            extra,
        }
    }

    /// The bounds on the poses' own grids.
    pub(super) fn grid_bounds(&self, which: Bound) -> &[Vec<f64>] {
        &self.bounds[which as usize]
    }

    /// Every analysis beside its bound: the poses' grids, then the points
    /// at their regulated poles.
    pub(super) fn with<'a>(
        &'a self,
        poses: &'a [Pose],
        which: Bound,
    ) -> Vec<(&'a Analysis, &'a [f64])> {
        let grid = poses
            .iter()
            .zip(&self.bounds[which as usize])
            .map(|(p, b)| (&p.analysis, b.as_slice()));
        let extra = self
            .extra
            .iter()
            .zip(&self.extra_bounds[which as usize])
            .filter(|(a, _)| !a.points.is_empty())
            .map(|(a, b)| (a, b.as_slice()));
        grid.chain(extra).collect()
    }

    /// Every analysis with its pose: the grids, then the regulated poles'.
    pub(super) fn analyses<'a>(
        &'a self,
        poses: &'a [Pose],
    ) -> impl Iterator<Item = (&'a Pose, &'a Analysis)> + 'a {
        let grid = poses.iter().map(|p| (p, &p.analysis));
        let extra = poses
            .iter()
            .zip(&self.extra)
            .filter(|(_, a)| !a.points.is_empty());
        grid.chain(extra)
    }
}
