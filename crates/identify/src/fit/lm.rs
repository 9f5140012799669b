//! Levenberg-Marquardt on nalgebra: the least squares of a few dozen
//! parameters against a few thousand residuals, with a forward-difference
//! Jacobian (the residuals come from a model's exact sampled response,
//! which has no convenient derivative).

use nalgebra::{DMatrix, DVector};

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
    r: impl Fn(&DVector<f64>) -> Option<DVector<f64>>,
    p0: DVector<f64>,
    max_iterations: usize,
) -> Option<Solution> {
    let jac = |p: &DVector<f64>, r0: &DVector<f64>| -> Option<DMatrix<f64>> {
        let mut j = DMatrix::zeros(r0.len(), p.len());
        for c in 0..p.len() {
            let h = 1e-6 * p[c].abs().max(1.0);
            let mut q = p.clone();
            q[c] += h;
            let rq = r(&q)?;
            j.set_column(c, &((rq - r0) / h));
        }
        Some(j)
    };
    let mut p = p0;
    let mut res = r(&p)?;
    let mut cost = res.norm_squared();
    let mut j = jac(&p, &res)?;
    let mut lambda = 1e-3;
    let mut iterations = 0;
    while iterations < max_iterations {
        iterations += 1;
        let jtj = j.transpose() * &j;
        let g = j.transpose() * &res;
        let mut improved = false;
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
                    let small = step.norm() < 1e-10 * (p.norm() + 1e-10);
                    let gain = (cost - rq.norm_squared()) / cost;
                    p = q;
                    res = rq;
                    cost = res.norm_squared();
                    lambda = (lambda / 3.0).max(1e-12);
                    improved = true;
                    if small || gain < 1e-12 {
                        return Some(Solution {
                            jacobian: jac(&p, &res)?,
                            p,
                            cost,
                            iterations,
                        });
                    }
                    break;
                }
                _ => lambda *= 8.0,
            }
        }
        if !improved {
            break;
        }
        j = jac(&p, &res)?;
    }
    Some(Solution {
        p,
        cost,
        jacobian: j,
        iterations,
    })
}

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
