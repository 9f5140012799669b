//! Cauer's ladder: the one chain of masses and springs whose driving-point
//! dynamic stiffness has the given resonances and antiresonances.
//!
//! A chain pushed at its first mass has, undamped, `F/X(λ) = m_t λ
//! Π(1 + λ/ω_r²) / Π(1 + λ/ω_a²)` with `λ = s²`, the antiresonances and
//! resonances interlacing (`ω_a1 < ω_r1 < ω_a2 < ...`). Its continued
//! fraction at `λ → ∞`, `m_1 λ + 1/(1/k_1 + 1/(m_2 λ + 1/(1/k_2 + ...)))`,
//! reads off the masses and springs in order from the pushed end: the
//! chain is the only one with that response, so a measured collocated
//! response fixes the whole chain, the far end (the handle) included.

/// A chain's masses (kg), first the one pushed, and the springs between
/// neighbours (N/m).
#[derive(Clone, Debug, PartialEq)]
pub struct Ladder {
    /// Masses from the pushed end (kg).
    pub masses_kg: Vec<f64>,
    /// Springs between mass `i` and `i + 1` (N/m).
    pub springs_npm: Vec<f64>,
}

/// The chain of total mass `m_t` (kg) with antiresonances `anti_rad_s`
/// and resonances `res_rad_s` (rad/s, as many of each, interlacing from an
/// antiresonance); `None` if they do not interlace or a step leaves a
/// mass or spring that is not positive.
pub fn synthesise(m_t: f64, anti_rad_s: &[f64], res_rad_s: &[f64]) -> Option<Ladder> {
    let n = res_rad_s.len();
    if anti_rad_s.len() != n || m_t.is_nan() || m_t <= 0.0 {
        return None;
    }
    for i in 0..n {
        let next_anti = anti_rad_s.get(i + 1).copied().unwrap_or(f64::INFINITY);
        if !(anti_rad_s[i] > 0.0 && anti_rad_s[i] < res_rad_s[i] && res_rad_s[i] < next_anti) {
            return None;
        }
    }
    // λ = scale u keeps the coefficients near one.
    let scale = res_rad_s.iter().fold(1.0f64, |a, w| a.max(w * w));
    let mut p = vec![0.0, m_t * scale];
    for w in res_rad_s {
        p = times_linear(&p, scale / (w * w));
    }
    let (ladder, _) = expand(p, anti_rad_s, scale)?;
    Some(ladder)
}

/// The chain held to the frame at its far end (the handle) whose
/// driving-point stiffness is `k_0` (N/m) at DC, with resonances
/// `res_rad_s` (one more than the antiresonances `anti_rad_s`, rad/s,
/// interlacing from a resonance): `F/X(λ) = k_0 Π(1 + λ/ω_r²) / Π(1 +
/// λ/ω_a²)`, whose continued fraction at `λ → ∞` ends in the spring to
/// the frame. The ladder and that spring (N/m), or `None` if the
/// frequencies do not interlace or a step leaves a value that is not
/// positive.
pub fn synthesise_held(k_0: f64, anti_rad_s: &[f64], res_rad_s: &[f64]) -> Option<(Ladder, f64)> {
    let n = anti_rad_s.len();
    if res_rad_s.len() != n + 1 || k_0.is_nan() || k_0 <= 0.0 {
        return None;
    }
    for i in 0..n {
        if !(res_rad_s[i] > 0.0 && res_rad_s[i] < anti_rad_s[i] && anti_rad_s[i] < res_rad_s[i + 1])
        {
            return None;
        }
    }
    let scale = res_rad_s.iter().fold(1.0f64, |a, w| a.max(w * w));
    let mut p = vec![k_0];
    for w in res_rad_s {
        p = times_linear(&p, scale / (w * w));
    }
    let (ladder, end) = expand(p, anti_rad_s, scale)?;
    (end > 0.0 && end.is_finite()).then_some((ladder, end))
}

/// The continued fraction of `P(u)/Q(u)` at `u → ∞` (`λ = scale u`,
/// `Q = Π(1 + u scale/ω_a²)`, `P` one degree higher): the masses and
/// springs from the pushed end, and the constant left at the far end (a
/// spring to the frame there; zero for a free chain).
fn expand(mut p: Vec<f64>, anti_rad_s: &[f64], scale: f64) -> Option<(Ladder, f64)> {
    let n = anti_rad_s.len();
    let mut q = vec![1.0];
    for w in anti_rad_s {
        q = times_linear(&q, scale / (w * w));
    }
    let mut ladder = Ladder {
        masses_kg: Vec::with_capacity(n + 1),
        springs_npm: Vec::with_capacity(n),
    };
    loop {
        let dq = q.len() - 1;
        let lead = p[dq + 1] / q[dq];
        let m = lead / scale;
        if !(m > 0.0 && m.is_finite()) {
            return None;
        }
        ladder.masses_kg.push(m);
        // R = P - lead u Q: its top term cancels.
        let mut r: Vec<f64> = p[..=dq].to_vec();
        for (i, qi) in q.iter().enumerate().take(dq) {
            r[i + 1] -= lead * qi;
        }
        if dq == 0 {
            return Some((ladder, r[0] / q[0]));
        }
        let k = r[dq] / q[dq];
        if !(k > 0.0 && k.is_finite()) {
            return None;
        }
        ladder.springs_npm.push(k);
        // Z' = R / (Q - R/k): the denominator's top term cancels.
        let next_q: Vec<f64> = (0..dq).map(|i| q[i] - r[i] / k).collect();
        p = r;
        q = next_q;
    }
}

/// `a(u) (1 + c u)`, coefficients from the constant term.
fn times_linear(a: &[f64], c: f64) -> Vec<f64> {
    let mut out = vec![0.0; a.len() + 1];
    for (i, ai) in a.iter().enumerate() {
        out[i] += ai;
        out[i + 1] += c * ai;
    }
    out
}

/// The undamped chain's antiresonances and resonances (rad/s), for a
/// check: the eigenfrequencies of the chain free and with its first mass
/// held.
#[cfg(test)]
pub(crate) fn frequencies(l: &Ladder) -> (Vec<f64>, Vec<f64>) {
    use nalgebra::DMatrix;
    let n = l.masses_kg.len();
    let mut k = DMatrix::<f64>::zeros(n, n);
    for (i, s) in l.springs_npm.iter().enumerate() {
        k[(i, i)] += s;
        k[(i + 1, i + 1)] += s;
        k[(i, i + 1)] -= s;
        k[(i + 1, i)] -= s;
    }
    let omegas = |from: usize| -> Vec<f64> {
        let m = n - from;
        let a = DMatrix::from_fn(m, m, |i, j| {
            k[(i + from, j + from)] / (l.masses_kg[i + from] * l.masses_kg[j + from]).sqrt()
        });
        let mut w: Vec<f64> = a
            .symmetric_eigenvalues()
            .iter()
            .filter(|v| **v > 1e-9 * a.norm())
            .map(|v| v.sqrt())
            .collect();
        w.sort_by(f64::total_cmp);
        w
    };
    (omegas(1), omegas(0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_two_mass_device_comes_back_from_its_two_frequencies() {
        // 0.6 kg and 0.15 kg joined by 3e5 N/m.
        let (anti, res) = ((3e5f64 / 0.15).sqrt(), (3e5f64 * 0.75 / 0.09).sqrt());
        let l = synthesise(0.75, &[anti], &[res]).unwrap();
        assert!((l.masses_kg[0] - 0.6).abs() < 1e-12);
        assert!((l.masses_kg[1] - 0.15).abs() < 1e-12);
        assert!((l.springs_npm[0] - 3e5).abs() < 1e-6);
    }

    /// A chain of five masses: its own frequencies give it back (to 1e-4:
    /// a flexure 200 times stiffer than the rest spreads the polynomials'
    /// coefficients over many decades); frequencies that do not
    /// interlace give nothing.
    #[test]
    fn a_chain_round_trips_through_its_frequencies() {
        let chain = Ladder {
            masses_kg: vec![0.93, 0.39, 1.2, 0.33, 0.16],
            springs_npm: vec![2.4e5, 1.0e6, 5.3e7, 4.0e6],
        };
        let (anti, res) = frequencies(&chain);
        let back = synthesise(chain.masses_kg.iter().sum(), &anti, &res).unwrap();
        for (a, b) in back.masses_kg.iter().zip(&chain.masses_kg) {
            assert!((a / b - 1.0).abs() < 1e-4, "{a} {b}");
        }
        for (a, b) in back.springs_npm.iter().zip(&chain.springs_npm) {
            assert!((a / b - 1.0).abs() < 1e-4, "{a} {b}");
        }
        assert!(synthesise(1.0, &[100.0, 50.0], &[80.0, 120.0]).is_none());
        assert!(synthesise_held(1.0, &[100.0], &[120.0, 150.0]).is_none());
    }

    /// A motor's 0.2 kg pulling, through a 3e4 N/m cable, a 0.05 kg
    /// handle held to the frame by 1,500 N/m: its DC stiffness, two
    /// resonances and one antiresonance give it back, the spring to the
    /// frame last.
    #[test]
    fn a_chain_held_at_its_far_end_round_trips() {
        let (m1, m2, k1, kg): (f64, f64, f64, f64) = (0.2, 0.05, 3e4, 1500.0);
        let k_0 = k1 * kg / (k1 + kg);
        let anti = ((k1 + kg) / m2).sqrt();
        // m1 m2 λ² + (m1 (k1 + kg) + k1 m2) λ + k1 kg = 0.
        let (a, b, c) = (m1 * m2, m1 * (k1 + kg) + k1 * m2, k1 * kg);
        let root = (b * b - 4.0 * a * c).sqrt();
        let res = [
            ((b - root) / (2.0 * a)).sqrt(),
            ((b + root) / (2.0 * a)).sqrt(),
        ];
        let (l, end) = synthesise_held(k_0, &[anti], &res).unwrap();
        for (got, want) in l.masses_kg.iter().zip([m1, m2]) {
            assert!((got / want - 1.0).abs() < 1e-9, "{l:?}");
        }
        assert!((l.springs_npm[0] / k1 - 1.0).abs() < 1e-9, "{l:?}");
        assert!((end / kg - 1.0).abs() < 1e-9, "{end}");
        assert!(synthesise(1.0, &[100.0], &[90.0]).is_none());
    }
}
