//! Levenberg-Marquardt on nalgebra: the least squares of a few dozen
//! parameters against a few thousand residuals, with a forward-difference
//! Jacobian (the residuals come from a model's exact sampled response,
//! which has no convenient derivative).

use nalgebra::{DMatrix, DVector};

/// A step that lowers the cost by less than this share of it ends the
/// search: far below what the noise of a measurement moves it by.
pub const TOLERANCE: f64 = 1e-7;

/// Where a least-squares search ended.
#[derive(Clone, Debug)]
pub struct Solution {
    /// The parameters.
    pub p: DVector<f64>,
    /// The sum of squared residuals there.
    pub cost: f64,
    /// The Jacobian of the residuals there (rows: residuals).
    pub jacobian: DMatrix<f64>,
    /// Iterations taken.
    pub iterations: usize,
}

/// Minimise `|r(p)|²` from `p0`; `r` gives `None` where the parameters
/// make no model (the step is then refused, as if it cost more).
pub fn minimise(
    r: impl Fn(&DVector<f64>) -> Option<DVector<f64>> + Sync,
    p0: DVector<f64>,
    max_iterations: usize,
) -> Option<Solution> {
    // Forward differences, the columns shared among the machine's cores:
    // each is a whole model's response, and they are independent.
    let jac = |p: &DVector<f64>, r0: &DVector<f64>| -> Option<DMatrix<f64>> {
        let column = |c: usize| -> Option<DVector<f64>> {
            let h = 1e-6 * p[c].abs().max(1.0);
            let mut q = p.clone();
            q[c] += h;
            Some((r(&q)? - r0) / h)
        };
        let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
        let columns: Vec<Option<DVector<f64>>> = std::thread::scope(|s| {
            let handles: Vec<_> = (0..threads)
                .map(|t| {
                    let column = &column;
                    s.spawn(move || {
                        (t..p.len())
                            .step_by(threads)
                            .map(|c| (c, column(c)))
                            .collect::<Vec<_>>()
                    })
                })
                .collect();
            let mut all = vec![None; p.len()];
            for h in handles {
                for (c, v) in h.join().unwrap_or_default() {
                    all[c] = v;
                }
            }
            all
        });
        let mut j = DMatrix::zeros(r0.len(), p.len());
        for (c, v) in columns.into_iter().enumerate() {
            j.set_column(c, &v?);
        }
        Some(j)
    };
    let mut p = p0;
    let mut res = r(&p)?;
    let mut cost = res.norm_squared();
    let mut j = jac(&p, &res)?;
    let mut lambda = 1e-3;
    let mut iterations = 0;
    // Steps since the Jacobian was last differenced: between, Broyden's
    // rank-one update keeps it, at no cost in model evaluations. An end
    // (no step helps, or one helps too little) is believed only on a
    // fresh Jacobian.
    let mut stale = 0;
    while iterations < max_iterations {
        iterations += 1;
        let jtj = j.transpose() * &j;
        let g = j.transpose() * &res;
        let mut accepted = None;
        for _ in 0..12 {
            let mut a = jtj.clone();
            for i in 0..a.nrows() {
                a[(i, i)] += lambda * jtj[(i, i)].max(1e-12);
            }
            let Some(step) = a.cholesky().map(|c| c.solve(&(-&g))) else {
                lambda *= 10.0;
                continue;
            };
            let q = &p + &step;
            match r(&q) {
                Some(rq) if rq.norm_squared() < cost => {
                    accepted = Some((step, q, rq));
                    lambda = (lambda / 3.0).max(1e-12);
                    break;
                }
                _ => lambda *= 8.0,
            }
        }
        let Some((step, q, rq)) = accepted else {
            if stale == 0 {
                break;
            }
            j = jac(&p, &res)?;
            stale = 0;
            lambda = 1e-3;
            continue;
        };
        let small = step.norm() < 1e-10 * (p.norm() + 1e-10);
        let gain = (cost - rq.norm_squared()) / cost;
        let change = &rq - &res;
        p = q;
        res = rq;
        cost = res.norm_squared();
        if small || gain < TOLERANCE {
            if stale == 0 {
                return Some(Solution {
                    jacobian: jac(&p, &res)?,
                    p,
                    cost,
                    iterations,
                });
            }
            j = jac(&p, &res)?;
            stale = 0;
        } else if stale >= REFRESH {
            j = jac(&p, &res)?;
            stale = 0;
        } else {
            let miss = change - &j * &step;
            j += miss * step.transpose() / step.norm_squared();
            stale += 1;
        }
    }
    Some(Solution {
        jacobian: if stale == 0 { j } else { jac(&p, &res)? },
        p,
        cost,
        iterations,
    })
}

/// Broyden updates between differenced Jacobians.
const REFRESH: usize = 4;

#[cfg(test)]
mod tests {
    use super::*;

    /// Rosenbrock's valley as residuals, from the usual start.
    #[test]
    fn it_finds_the_bottom_of_a_curved_valley() {
        let r = |p: &DVector<f64>| {
            Some(DVector::from_vec(vec![
                10.0 * (p[1] - p[0] * p[0]),
                1.0 - p[0],
            ]))
        };
        let s = minimise(r, DVector::from_vec(vec![-1.2, 1.0]), 200).unwrap();
        assert!(
            (s.p[0] - 1.0).abs() < 1e-6 && (s.p[1] - 1.0).abs() < 1e-6,
            "{:?}",
            s.p
        );
    }
}
