//! Nelder-Mead, maximising a score: the searches' local refinement.

/// Nelder-Mead from `start` for `iters` iterations, each vertex first
/// stepped by `step(i)` along coordinate `i`. `eval` may move a point (to
/// clamp it into bounds) and answers with a result whose `score` is
/// maximised. Returns the best point and its result.
pub(crate) fn maximise<S: Clone>(
    start: &[f64],
    step: impl Fn(usize) -> f64,
    iters: usize,
    mut eval: impl FnMut(&mut Vec<f64>) -> S,
    score: impl Fn(&S) -> f64,
) -> (Vec<f64>, S) {
    let dim = start.len();
    let key = |r: &S| -score(r);
    let mut simplex: Vec<(Vec<f64>, S)> = Vec::with_capacity(dim + 1);
    let mut s0 = start.to_vec();
    let r0 = eval(&mut s0);
    simplex.push((s0, r0));
    for i in 0..dim {
        let mut p = start.to_vec();
        p[i] += step(i);
        let r = eval(&mut p);
        simplex.push((p, r));
    }
    for _ in 0..iters {
        simplex.sort_by(|a, b| key(&a.1).total_cmp(&key(&b.1)));
        let worst = simplex[dim].clone();
        let centroid: Vec<f64> = (0..dim)
            .map(|j| simplex[..dim].iter().map(|s| s.0[j]).sum::<f64>() / dim as f64)
            .collect();
        let at = |c: f64| -> Vec<f64> {
            (0..dim)
                .map(|j| centroid[j] + c * (worst.0[j] - centroid[j]))
                .collect()
        };
        let mut xr = at(-1.0);
        let rr = eval(&mut xr);
        if key(&rr) < key(&simplex[0].1) {
            let mut xe = at(-2.0);
            let re = eval(&mut xe);
            simplex[dim] = if key(&re) < key(&rr) {
                (xe, re)
            } else {
                (xr, rr)
            };
        } else if key(&rr) < key(&simplex[dim - 1].1) {
            simplex[dim] = (xr, rr);
        } else {
            let mut xc = at(0.5);
            let rc = eval(&mut xc);
            if key(&rc) < key(&worst.1) {
                simplex[dim] = (xc, rc);
            } else {
                let best = simplex[0].0.clone();
                for s in simplex.iter_mut().skip(1) {
                    let mut p: Vec<f64> =
                        s.0.iter().zip(&best).map(|(x, b)| 0.5 * (x + b)).collect();
                    let r = eval(&mut p);
                    *s = (p, r);
                }
            }
        }
    }
    simplex.sort_by(|a, b| key(&a.1).total_cmp(&key(&b.1)));
    simplex.swap_remove(0)
}
