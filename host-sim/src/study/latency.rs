//! The latency that explains a measured boundary: the fraction of a tick
//! between sampling and actuation at which a scene's swept boundary meets
//! a target (the paper's Table I measured 75,000 N/m and 4.3 kg where the
//! linear model without latency gives about 167,000 N/m and 2.66 kg).

use super::sweep::marginal;
use crate::Error;
use std::path::Path;

/// What the search found.
#[derive(Clone, Debug, PartialEq)]
pub enum LatencySearch {
    /// The boundary meets the target at `alpha` of a tick (within the
    /// search's tolerance), where it is `marginal`.
    Found {
        /// The latency (periods).
        alpha: f64,
        /// The boundary there (the parameter's unit).
        marginal: f64,
    },
    /// No latency in `[0, 1)` gives the target: the boundary runs from
    /// `at_zero` to `at_last` at `last` of a tick; past `last` the sweep
    /// finds no boundary in its range (the loop is unstable at both ends,
    /// or stable at both), or `last` is the end of the tick.
    NotReached {
        /// The boundary with no latency.
        at_zero: f64,
        /// The last latency (periods) with a boundary in the range.
        last: f64,
        /// The boundary there.
        at_last: f64,
    },
}

/// The boundary of `param` in the scene at `path` (with `sets`) with the
/// force `alpha` of a tick late, swept over `range` to `tol`; `None` where
/// the sweep finds none.
fn boundary(
    path: &Path,
    sets: &[String],
    (param, range, tol): (&str, (f64, f64), f64),
    alpha: f64,
) -> Option<f64> {
    let mut s = sets.to_vec();
    s.push(format!("effects.latency.periods={alpha}"));
    marginal(path, &s, param, range, tol, &mut || {}).ok()
}

/// The latency (periods, in `[0, 1)`) at which the boundary of `param`
/// (swept over `range` to the relative `tol`) is `target`, by bisection on
/// the latency to `tol` of a tick: the boundary moves one way as the
/// latency grows (a stiffness falls, a mass rises). `step` is called after
/// every sweep.
pub fn fit(
    path: &Path,
    sets: &[String],
    (param, range, tol): (&str, (f64, f64), f64),
    target: f64,
    step: &mut dyn FnMut(),
) -> Result<LatencySearch, Error> {
    if !(target.is_finite() && target > 0.0) {
        return Err(sim_err!("target {target}: must be finite and > 0"));
    }
    let sweep = (param, range, tol);
    let mut at = |alpha: f64| {
        let b = boundary(path, sets, sweep, alpha);
        step();
        b
    };
    let at_zero = at(0.0).ok_or_else(|| {
        sim_err!(
            "{param}: no boundary between {} and {} without a latency",
            range.0,
            range.1
        )
    })?;
    // Which side of the target the boundary starts, and the last latency
    // (of a coarse scan) before it crosses or the sweep finds none.
    let below = at_zero < target;
    let (mut good, mut last) = (0.0, at_zero);
    let mut crossed = None;
    for i in 1..20 {
        let alpha = f64::from(i) / 20.0;
        match at(alpha) {
            Some(b) if (b < target) == below => (good, last) = (alpha, b),
            Some(_) => {
                crossed = Some(alpha);
                break;
            }
            None => break,
        }
    }
    let Some(mut bad) = crossed else {
        return Ok(LatencySearch::NotReached {
            at_zero,
            last: good,
            at_last: last,
        });
    };
    let mut found = last;
    while bad - good > tol {
        let mid = 0.5 * (good + bad);
        match at(mid) {
            Some(b) if (b < target) == below => (good, found) = (mid, b),
            _ => bad = mid,
        }
    }
    // The side of the crossing nearer the target.
    if let Some(b) = at(bad) {
        if (b - target).abs() < (found - target).abs() {
            return Ok(LatencySearch::Found {
                alpha: bad,
                marginal: b,
            });
        }
    }
    Ok(LatencySearch::Found {
        alpha: good,
        marginal: found,
    })
}
