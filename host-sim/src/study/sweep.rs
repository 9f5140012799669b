//! The boundary of stability along one scene parameter, by bisection.

use crate::Error;
use crate::{Scene, Simulation};
use std::path::Path;

/// Whether the scene at `path` (with `sets` overrides) is stable with
/// `param = value`.
pub fn stable_at(path: &Path, sets: &[String], param: &str, value: f64) -> Result<bool, Error> {
    let mut s = sets.to_vec();
    s.push(format!("{param}={value}"));
    let scene = Scene::load(path, &s)?;
    Ok(Simulation::new(scene)?.run(|_| {}).stable)
}

/// Bisect between `from` and `to` (geometric when both are positive) for
/// the value where stability changes, to the relative tolerance `tol`;
/// returns the last stable value. `step` is called after every bisection
/// step (a progress bar). An error where both ends agree.
pub fn marginal(
    path: &Path,
    sets: &[String],
    param: &str,
    (from, to): (f64, f64),
    tol: f64,
    step: &mut dyn FnMut(),
) -> Result<f64, Error> {
    if !(tol > 0.0 && tol < 1.0) {
        return Err(sim_err!("tolerance {tol}: must be between 0 and 1"));
    }
    let (s_from, s_to) = (
        stable_at(path, sets, param, from)?,
        stable_at(path, sets, param, to)?,
    );
    if s_from == s_to {
        return Err(sim_err!(
            "{param}: {} at both {from} and {to}; widen the range",
            if s_from { "stable" } else { "unstable" }
        ));
    }
    let (mut good, mut bad) = if s_from { (from, to) } else { (to, from) };
    let geometric = good > 0.0 && bad > 0.0;
    while (good - bad).abs() > tol * good.abs().max(bad.abs()) {
        let mid = if geometric {
            (good * bad).sqrt()
        } else {
            0.5 * (good + bad)
        };
        if stable_at(path, sets, param, mid)? {
            good = mid;
        } else {
            bad = mid;
        }
        step();
    }
    Ok(good)
}

/// How many bisection steps [`marginal`] takes from `from` to `to` at
/// `tol` (for a progress bar).
pub fn steps(from: f64, to: f64, tol: f64) -> u64 {
    let span = if from > 0.0 && to > 0.0 {
        (to / from).ln().abs()
    } else {
        1.0 / tol
    };
    (span / tol).log2().ceil().max(1.0) as u64
}
