//! Branch and bound over a linkage's joint box: the least of a quantity
//! over every pose inside the joint limits and the relative ones, proven
//! from below by [`cell_bounds`](LinkageFile::cell_bounds) on each box and
//! found from above at poses, the boxes split until the two meet.

use super::cell::{CellBounds, Undecided};
use super::file::LinkageFile;
use super::pose::PoseDynamics;
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// The relative gap at which the search stops: the proven bound is within
/// this fraction of the least value found at a pose.
pub const TOLERANCE: f64 = 1e-4;

/// Boxes the search may bound before it stops with the gap it has.
pub const BUDGET: usize = 200_000;

/// The least of a quantity over the workspace.
#[derive(Clone, Debug, PartialEq)]
pub struct Least {
    /// The proven lower bound.
    pub bound: f64,
    /// The least value found at a pose (at or above `bound`).
    pub found: f64,
    /// Where it was found.
    pub pose: PoseDynamics,
    /// The box whose bound is `bound` (rad): where the certificate binds.
    pub binding_box_rad: Vec<[f64; 2]>,
    /// `(found - bound)/|found|`.
    pub gap: f64,
    /// Boxes bounded.
    pub boxes: usize,
}

/// A quantity the search minimises: its lower bound over a box and its
/// value at a pose.
pub trait Objective {
    /// Whether its bound needs the mass's.
    const MASS: bool;
    /// A lower bound over every pose the box's bounds allow.
    fn over(&self, cell: &CellBounds) -> f64;
    /// The value at one pose.
    fn at(&self, pose: &PoseDynamics) -> f64;
}

/// A box waiting to be split, ordered least bound first.
struct Open {
    bound: f64,
    lo: Vec<f64>,
    hi: Vec<f64>,
    split: usize,
}

impl PartialEq for Open {
    fn eq(&self, o: &Self) -> bool {
        self.bound.total_cmp(&o.bound) == Ordering::Equal
    }
}
impl Eq for Open {}
impl PartialOrd for Open {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Open {
    fn cmp(&self, o: &Self) -> Ordering {
        // BinaryHeap pops the greatest: the least bound is the greatest.
        o.bound.total_cmp(&self.bound)
    }
}

/// The search's state: the open boxes and the least value found.
struct Search<'a, O> {
    file: &'a LinkageFile,
    objective: &'a O,
    open: BinaryHeap<Open>,
    best: Option<(f64, PoseDynamics)>,
    boxes: usize,
}

/// Boxes split at once, their halves bounded in parallel.
const BATCH: usize = 32;

impl<O: Objective + Sync> Search<'_, O> {
    /// The bound a box must reach to need no split: the least value found,
    /// less the tolerance.
    fn cut(&self) -> f64 {
        self.best
            .as_ref()
            .map_or(f64::INFINITY, |(b, _)| b - TOLERANCE * b.abs())
    }

    /// Evaluate the objective at `q` if it is a pose the board drives.
    fn consider(&mut self, q: &[f64]) {
        if !self.file.within_limits(q) {
            return;
        }
        if let Ok(p) = self.file.pose(q) {
            let v = self.objective.at(&p);
            if self.best.as_ref().is_none_or(|(b, _)| v < *b) {
                self.best = Some((v, p));
            }
        }
    }

    /// Bound the boxes `[lo, hi]` (in parallel) and keep them open, but for
    /// those wholly outside the relative limits.
    fn push(&mut self, boxes: Vec<(Vec<f64>, Vec<f64>)>) {
        self.boxes += boxes.len();
        let (file, objective) = (self.file, self.objective);
        let bounded = crate::par::map_from(boxes.len(), 8, |i| {
            let (lo, hi) = &boxes[i];
            file.cell_bounds(lo, hi, O::MASS)
                .map(|cell| (objective.over(&cell), cell))
        });
        for ((lo, hi), b) in boxes.into_iter().zip(bounded) {
            let mid: Vec<f64> = lo.iter().zip(&hi).map(|(a, b)| 0.5 * (a + b)).collect();
            match b {
                Ok((bound, cell)) => {
                    // (A box proven past the cut holds no pose the
                    // certificate needs.)
                    if bound < self.cut() {
                        self.consider(&cell.least_damped_q_rad);
                        self.consider(&mid);
                    }
                    self.open.push(Open {
                        bound,
                        lo,
                        hi,
                        split: cell.split,
                    });
                }
                Err(Undecided::Infeasible | Undecided::Refused) => {}
            }
        }
    }
}

/// The halves of a box, split where its bound is loosest.
fn halves(cell: Open) -> [(Vec<f64>, Vec<f64>); 2] {
    let k = cell.split;
    let m = 0.5 * (cell.lo[k] + cell.hi[k]);
    let (mut left_hi, mut right_lo) = (cell.hi.clone(), cell.lo.clone());
    left_hi[k] = m;
    right_lo[k] = m;
    [(cell.lo, left_hi), (right_lo, cell.hi)]
}

/// The least of `objective` over `file`'s workspace, to [`TOLERANCE`] or
/// until [`BUDGET`] boxes; [`Error::NoReachablePose`](crate::Error) where
/// no pose inside the limits is one the kinematics drive.
pub fn least<O: Objective + Sync>(
    file: &LinkageFile,
    objective: &O,
) -> Result<Least, crate::Error> {
    // (A symmetric family of poses shares its eigenvalues: one of each.)
    let file = &file.fundamental_domain();
    let mut s = Search {
        file,
        objective,
        open: BinaryHeap::new(),
        best: None,
        boxes: 0,
    };
    let lo: Vec<f64> = file.joints.limits_rad.iter().map(|l| l[0]).collect();
    let hi: Vec<f64> = file.joints.limits_rad.iter().map(|l| l[1]).collect();
    s.push(vec![(lo, hi)]);
    loop {
        let Some(least) = s.open.peek() else {
            return Err(crate::Error::NoReachablePose(file.name.clone()));
        };
        if let Some((found, _)) = &s.best {
            let close = found - least.bound <= TOLERANCE * found.abs();
            if least.bound.is_finite() && (close || s.boxes >= BUDGET) {
                let cell = s.open.pop().expect("peeked");
                let (found, pose) = s.best.take().expect("a pose was found");
                return Ok(Least {
                    bound: cell.bound,
                    found,
                    pose,
                    binding_box_rad: cell
                        .lo
                        .iter()
                        .zip(&cell.hi)
                        .map(|(a, b)| [*a, *b])
                        .collect(),
                    gap: (found - cell.bound) / found.abs().max(f64::MIN_POSITIVE),
                    boxes: s.boxes,
                });
            }
        }
        // Split the least-bounded boxes that are still too far below the
        // best pose (at least the least of them).
        let cut = s.cut();
        let mut split = Vec::new();
        while split.len() < 2 * BATCH {
            match s.open.peek() {
                Some(c) if split.is_empty() || c.bound < cut => {
                    let c = s.open.pop().expect("peeked");
                    split.extend(halves(c));
                }
                _ => break,
            }
        }
        s.push(split);
    }
}
