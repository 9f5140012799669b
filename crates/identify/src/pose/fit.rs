//! The mass and damping matrices at a pose, fitted to the response matrix.

use super::response::sampled;
use super::PoseMeasured;
use crate::fit::lm;
use crate::fit::uncertainty::Doubt;
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64;

/// A share of each harmonic's response matrix (its norm) added to every
/// entry's standard deviation: what a linear model at one pose does not
/// capture (friction, the pose moving), so that no harmonic's tiny
/// variance lets it outweigh the rest.
const FLOOR: f64 = 2e-3;

/// The doubt a pose's set is spanned with: three standard deviations,
/// and none of the damping. What the fit finds of a linkage's viscous
/// damping at a pose is biased past its noise: on the simulated PHANToM
/// the least damping came out 0.0044 to 0.015 N s/m where the joints give
/// 0.0038 (the encoders' quantum and the pose moving under the push), and
/// the joints' friction, which this fit does not separate (the joints'
/// losses, [`losses`](super::losses), do), is larger still. The damping
/// the proof credits bounds the stiffness nearly in proportion, so a
/// robust design at a pose credits none: the grasp's least damping,
/// which the dead-man switch assures, carries it.
pub const POSE_DOUBT: Doubt = Doubt {
    sigmas: 3.0,
    damping: 1.0,
};

/// The fitted pose.
#[derive(Clone, Debug, PartialEq)]
pub struct PoseFit {
    /// `M_x` (kg), symmetric.
    pub mass_kg: DMatrix<f64>,
    /// `D_x` (N s/m), symmetric.
    pub damping_nspm: DMatrix<f64>,
    /// `χ²/ν`: 1 where the residuals are the measurement's noise alone.
    pub misfit: f64,
    /// The parameters' covariance, inflated by the misfit where it is
    /// above 1: the upper triangles of `M_x` then `D_x`, row by row.
    pub covariance: DMatrix<f64>,
}

/// The upper triangle's `(row, column)` pairs of an `n × n` matrix.
fn upper(n: usize) -> Vec<(usize, usize)> {
    (0..n).flat_map(|i| (i..n).map(move |j| (i, j))).collect()
}

/// The symmetric matrices `(M, D)` of a parameter vector.
fn matrices(n: usize, p: &DVector<f64>) -> (DMatrix<f64>, DMatrix<f64>) {
    let pairs = upper(n);
    let at = |off: usize| {
        let mut m = DMatrix::zeros(n, n);
        for (k, &(i, j)) in pairs.iter().enumerate() {
            m[(i, j)] = p[off + k];
            m[(j, i)] = p[off + k];
        }
        m
    };
    (at(0), at(pairs.len()))
}

/// The linear start: `Z = H^-1 ≈ M/A + D B/A²`, `A` and `B` the hold
/// equivalents of `1/s²` and `1/s³` (exact for `D = 0`, first order in
/// `D` otherwise), each harmonic's equations scaled by `1/|Z|`.
fn start(data: &PoseMeasured, n: usize) -> Option<DVector<f64>> {
    let pairs = upper(n);
    let np = 2 * pairs.len();
    let t = data.period_s;
    let mut rows: Vec<Vec<f64>> = Vec::new();
    let mut rhs: Vec<f64> = Vec::new();
    for (f, h) in data.freq_hz.iter().zip(&data.response) {
        let z_meas = h.clone().try_inverse()?;
        let w = 1.0 / z_meas.norm();
        let z = Complex64::from_polar(1.0, std::f64::consts::TAU * f * t);
        let a = t * t * (z + 1.0) / (2.0 * (z - 1.0).powi(2));
        let b = t.powi(3) * (z * z + 4.0 * z + 1.0) / (6.0 * (z - 1.0).powi(3));
        let (cm, cd) = (1.0 / a, b / (a * a));
        for i in 0..n {
            for j in 0..n {
                let mut re = vec![0.0; np];
                let mut im = vec![0.0; np];
                for (k, &(r, c)) in pairs.iter().enumerate() {
                    if (r, c) == (i, j) || (r, c) == (j, i) {
                        re[k] = cm.re * w;
                        im[k] = cm.im * w;
                        re[pairs.len() + k] = cd.re * w;
                        im[pairs.len() + k] = cd.im * w;
                    }
                }
                rows.push(re);
                rows.push(im);
                rhs.push(z_meas[(i, j)].re * w);
                rhs.push(z_meas[(i, j)].im * w);
            }
        }
    }
    let a = DMatrix::from_fn(rows.len(), np, |r, c| rows[r][c]);
    let b = DVector::from_vec(rhs);
    a.svd(true, true).solve(&b, 1e-12).ok()
}

/// `M_x` alone, from the linear start: for records whose damping is not
/// a linear body's (the joints' friction, whose describing function at
/// a sine is damping, in quadrature with the mass), such as the sines
/// [`losses`](super::losses) takes the damping from. Refused where it is
/// not positive definite.
pub fn mass(data: &PoseMeasured) -> Result<DMatrix<f64>, crate::IdentifyError> {
    let n = data.response.first().map_or(0, |h| h.nrows());
    let p = start(data, n).ok_or(crate::IdentifyError::NoBody)?;
    let (m, _) = matrices(n, &p);
    m.clone()
        .cholesky()
        .map(|_| m)
        .ok_or(crate::IdentifyError::NoBody)
}

/// The most `χ²/ν` a pose fit is taken at. The records of a linear body
/// at one pose give about 1 (0.5 to 1.3 on the simulated PHANToM and
/// delta); with the joints' friction sticking under a small push, 18 to
/// 100 and models far from the truth, whose damping is the friction's.
pub const MOST_MISFIT: f64 = 4.0;

/// Fit `M_x` and `D_x` to `data`: the linear start, then
/// Levenberg-Marquardt on the exact sampled response, each entry of each
/// harmonic weighted by its standard deviation (with a floor of 0.2%
/// of the harmonic's response). Refused where no positive definite mass
/// fits, or the fit leaves more than [`MOST_MISFIT`] times the noise:
/// then the records are not a linear body's, and a model of one, its
/// damping above all, would claim what the device does not have.
pub fn fit(data: &PoseMeasured) -> Result<PoseFit, crate::IdentifyError> {
    let f = fit_any(data).ok_or(crate::IdentifyError::NoBody)?;
    if f.misfit > MOST_MISFIT {
        return Err(crate::IdentifyError::NotLinear {
            misfit: f.misfit,
            most: MOST_MISFIT,
        });
    }
    Ok(f)
}

fn fit_any(data: &PoseMeasured) -> Option<PoseFit> {
    let n = data.response.first()?.nrows();
    let sigma: Vec<DMatrix<f64>> = data
        .variance
        .iter()
        .zip(&data.response)
        .map(|(v, h)| {
            let floor = FLOOR * h.norm();
            v.map(|v| (v + floor * floor).sqrt())
        })
        .collect();
    let residuals = |p: &DVector<f64>| -> Option<DVector<f64>> {
        let (m, d) = matrices(n, p);
        let model = sampled(&m, &d, data.period_s, &data.freq_hz)?;
        let mut r = Vec::with_capacity(2 * n * n * model.len());
        for ((g, h), s) in model.iter().zip(&data.response).zip(&sigma) {
            for k in 0..n * n {
                let e = (g[k] - h[k]) / s[k];
                r.push(e.re);
                r.push(e.im);
            }
        }
        Some(DVector::from_vec(r))
    };
    let p0 = start(data, n)?;
    let sol = lm::minimise(residuals, p0, 100)?;
    let nu = (sol.jacobian.nrows() as f64 - sol.p.len() as f64).max(1.0);
    let misfit = sol.cost / nu;
    let jtj = sol.jacobian.transpose() * &sol.jacobian;
    let covariance = jtj.try_inverse()? * misfit.max(1.0);
    let (mass_kg, damping_nspm) = matrices(n, &sol.p);
    Some(PoseFit {
        mass_kg,
        damping_nspm,
        misfit,
        covariance,
    })
}

impl PoseFit {
    /// The models at `doubt.sigmas` standard deviations from the fit
    /// along each principal direction of the covariance, both ways, and
    /// the fit itself, each with its damping lowered by `doubt.damping`
    /// (a fraction from 0 to 1): the set a robust design proves. A model
    /// whose mass is not positive definite is left out (it is no body); a
    /// damping that the bound takes below zero is kept, the conservative
    /// side. Empty where the doubt is not a finite, non-negative number of
    /// standard deviations and a fraction.
    pub fn span(&self, doubt: Doubt) -> Vec<(DMatrix<f64>, DMatrix<f64>)> {
        let Doubt { sigmas, damping } = doubt;
        if !(sigmas.is_finite() && sigmas >= 0.0 && (0.0..=1.0).contains(&damping)) {
            return Vec::new();
        }
        let n = self.mass_kg.nrows();
        let pairs = upper(n);
        let p: DVector<f64> = pairs
            .iter()
            .map(|&(i, j)| self.mass_kg[(i, j)])
            .chain(pairs.iter().map(|&(i, j)| self.damping_nspm[(i, j)]))
            .collect::<Vec<_>>()
            .into();
        let eig = self.covariance.clone().symmetric_eigen();
        let mut out = vec![(self.mass_kg.clone(), self.damping_nspm.clone())];
        for (k, lam) in eig.eigenvalues.iter().enumerate() {
            let step = eig.eigenvectors.column(k) * (sigmas * lam.max(0.0).sqrt());
            for q in [&p + &step, &p - &step] {
                let (m, d) = matrices(n, &q);
                if m.clone().cholesky().is_some() {
                    out.push((m, d));
                }
            }
        }
        for (_, d) in &mut out {
            *d *= 1.0 - damping;
        }
        out
    }

    /// The standard deviation of `λ_min(D_x)` (N s/m), to first order:
    /// the covariance along the least damped direction's `u uᵀ`.
    pub fn least_damping_sd(&self) -> f64 {
        let n = self.mass_kg.nrows();
        let pairs = upper(n);
        let eig = self.damping_nspm.clone().symmetric_eigen();
        let u = eig.eigenvectors.column(eig.eigenvalues.imin()).into_owned();
        let off = pairs.len();
        let mut g = DVector::zeros(2 * off);
        for (k, &(i, j)) in pairs.iter().enumerate() {
            g[off + k] = if i == j {
                u[i] * u[i]
            } else {
                2.0 * u[i] * u[j]
            };
        }
        (g.transpose() * &self.covariance * &g)[(0, 0)]
            .max(0.0)
            .sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On a response computed exactly from a coupled body, with 0.1 %
    /// complex noise, the fit recovers `M` to 0.5 % and `D` to 2 % (in
    /// norm), from a start the linear fit gives.
    #[test]
    fn recovers_a_coupled_body() {
        let (m, d) = crate::pose::response::tests::coupled_body();
        let freq_hz: Vec<f64> = (1..=450).map(f64::from).collect();
        let exact = sampled(&m, &d, 1e-3, &freq_hz).unwrap();
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut rnd = move || crate::fit::tests::rng(&mut seed);
        let response: Vec<DMatrix<Complex64>> = exact
            .iter()
            .map(|h| {
                let s = 1e-3 * h.norm();
                h.map(|c| c + Complex64::new(rnd(), rnd()) * s)
            })
            .collect();
        let variance = response
            .iter()
            .map(|h| h.map(|_| (1e-3 * h.norm()).powi(2) / 6.0))
            .collect();
        let data = PoseMeasured {
            period_s: 1e-3,
            freq_hz,
            response,
            variance,
            periods: 28,
        };
        let f = fit(&data).unwrap();
        assert!((&f.mass_kg - &m).norm() / m.norm() < 5e-3, "{}", f.mass_kg);
        assert!(
            (&f.damping_nspm - &d).norm() / d.norm() < 2e-2,
            "{}",
            f.damping_nspm
        );
        assert!(f.misfit < 2.0, "{}", f.misfit);
        let set = f.span(Doubt {
            sigmas: 3.0,
            damping: 0.05,
        });
        assert_eq!(set.len(), 1 + 2 * 12);
        assert!((&set[0].1 - &f.damping_nspm * 0.95).norm() < 1e-12);
        assert!(f.span(POSE_DOUBT).iter().all(|(_, d)| d.norm() == 0.0));
        // Every other harmonic 5% off: no body fits to the noise, and
        // none is given.
        let mut bent = data.clone();
        for h in bent.response.iter_mut().step_by(2) {
            *h *= Complex64::new(1.05, 0.0);
        }
        match fit(&bent) {
            Err(crate::IdentifyError::NotLinear { misfit, .. }) => assert!(misfit > MOST_MISFIT),
            other => panic!("{other:?}"),
        }
    }
}
