//! Rational transfer functions in `z^-1` for building closed loops: the
//! few polynomial operations the designer needs and a state-space
//! realisation (transposed direct form II).

use nalgebra::DMatrix;
use twoport_control::ZTransfer;

/// Polynomials in `z^-1`: `c[0] + c[1] z^-1 + ...`.
pub type Poly = Vec<f64>;

/// A rational transfer function `(num, den)` in `z^-1`.
pub type Rational = (Poly, Poly);

/// `a b`.
pub fn mul(a: &[f64], b: &[f64]) -> Poly {
    let mut c = vec![0.0; a.len() + b.len() - 1];
    for (i, x) in a.iter().enumerate() {
        for (j, y) in b.iter().enumerate() {
            c[i + j] += x * y;
        }
    }
    c
}

/// `a + b`.
pub fn add(a: &[f64], b: &[f64]) -> Poly {
    (0..a.len().max(b.len()))
        .map(|i| a.get(i).unwrap_or(&0.0) + b.get(i).unwrap_or(&0.0))
        .collect()
}

/// `s a`.
pub fn scale(a: &[f64], s: f64) -> Poly {
    a.iter().map(|x| x * s).collect()
}

/// `z^-d a`.
pub fn delayed(a: &[f64], d: usize) -> Poly {
    let mut c = vec![0.0; d];
    c.extend_from_slice(a);
    c
}

/// A law's z-form as `(num, den)`.
pub fn from_tf(t: &ZTransfer) -> Rational {
    (t.num.to_vec(), t.den.to_vec())
}

/// Divide `p` by `(1 - z^-1)`, if `z = 1` is a root (to rounding).
fn without_unit_root(p: &[f64]) -> Option<Poly> {
    let scale = p.iter().map(|x| x.abs()).sum::<f64>();
    if p.iter().sum::<f64>().abs() > 1e-12 * scale || p.len() < 2 {
        return None;
    }
    // p = (1 - z^-1) q: q[0] = p[0], q[i] = p[i] + q[i-1].
    let mut q = Vec::with_capacity(p.len() - 1);
    let mut acc = 0.0;
    for x in &p[..p.len() - 1] {
        acc += x;
        q.push(acc);
    }
    Some(q)
}

/// `num/den` with common `(1 - z^-1)` factors removed, so no mode the
/// controller cannot see sits at `z = 1`.
pub fn reduced(mut num: Poly, mut den: Poly) -> Rational {
    while let (Some(n), Some(d)) = (without_unit_root(&num), without_unit_root(&den)) {
        (num, den) = (n, d);
    }
    (num, den)
}

/// A SISO discrete system in transposed direct form II.
pub struct Ss {
    /// State matrix.
    pub a: DMatrix<f64>,
    /// Input column.
    pub b: Vec<f64>,
    /// Output row.
    pub c: Vec<f64>,
    /// Direct feedthrough.
    pub d: f64,
}

/// `num/den` in transposed direct form II; an error where `den[0]` is 0.
pub fn realise(num: &[f64], den: &[f64]) -> Result<Ss, crate::Error> {
    let a0 = den.first().copied().unwrap_or(0.0);
    if a0 == 0.0 || !a0.is_finite() {
        return Err(crate::Error::NotCausal);
    }
    let n = num.len().max(den.len()) - 1;
    let at = |p: &[f64], i: usize| p.get(i).copied().unwrap_or(0.0) / a0;
    let b0 = at(num, 0);
    let mut a = DMatrix::zeros(n, n);
    let mut b = vec![0.0; n];
    for i in 0..n {
        a[(i, 0)] = -at(den, i + 1);
        if i + 1 < n {
            a[(i, i + 1)] = 1.0;
        }
        b[i] = at(num, i + 1) - at(den, i + 1) * b0;
    }
    let mut c = vec![0.0; n];
    if n > 0 {
        c[0] = 1.0;
    }
    Ok(Ss { a, b, c, d: b0 })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The realisation's impulse response is the rational function's.
    #[test]
    fn realisation_matches_the_division() {
        let (num, den) = (vec![0.5, -0.2, 0.1], vec![1.0, -0.9, 0.2]);
        let ss = realise(&num, &den).unwrap();
        let mut x = vec![0.0; ss.b.len()];
        let mut h = Vec::new();
        for k in 0..8 {
            let u = if k == 0 { 1.0 } else { 0.0 };
            let y: f64 = ss.c.iter().zip(&x).map(|(c, x)| c * x).sum::<f64>() + ss.d * u;
            h.push(y);
            let xn: Vec<f64> = (0..x.len())
                .map(|i| (0..x.len()).map(|j| ss.a[(i, j)] * x[j]).sum::<f64>() + ss.b[i] * u)
                .collect();
            x = xn;
        }
        // Long division of num by den.
        let mut r = num.clone();
        r.resize(8, 0.0);
        for k in 0..8 {
            let q = r[k];
            assert!((h[k] - q).abs() < 1e-12, "{k}: {} vs {q}", h[k]);
            for (i, d) in den.iter().enumerate().skip(1) {
                if k + i < 8 {
                    r[k + i] -= q * d;
                }
            }
        }
    }

    #[test]
    fn unit_roots_cancel() {
        let (n, d) = reduced(mul(&[2.0, 1.0], &[1.0, -1.0]), vec![1.0, -1.0]);
        assert_eq!((n, d), (vec![2.0, 1.0], vec![1.0]));
        let (n, d) = reduced(vec![1.0, 0.5], vec![1.0, -0.5]);
        assert_eq!((n, d), (vec![1.0, 0.5], vec![1.0, -0.5]));
    }
}
