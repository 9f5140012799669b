//! From a measured frequency response to a physical model: a chain of
//! masses (a rigid mass-damper, or one to four lightly damped modes) whose
//! exact sampled response, the one `twoport design` analyses, matches the
//! measurement at every excited harmonic.
//!
//! 1. **Start** from the measurement itself: the total mass and damping
//!    from the lowest harmonics; the resonances and antiresonances from
//!    the peaks and dips of `|X/F| ω²`; and from them, by Cauer's ladder
//!    ([`ladder`]), the one chain with those frequencies.
//! 2. **Fit** every mass, spring and damper (their logarithms) by
//!    Levenberg-Marquardt ([`lm`]) to the encoder's response, and the load
//!    cell's where there is one, each harmonic weighted by its measured
//!    variance (with a floor of 0.2% of the response, for what no model
//!    of a few modes captures).
//! 3. **Choose the order** by the Bayesian information criterion,
//!    `χ² + p ln(N)` over the orders that could be started: a mode is kept
//!    only if it explains more than noise would.
//! 4. **Bound** the fit: the parameters' covariance from the Jacobian,
//!    inflated by the misfit (`χ²/ν` where above one).

pub mod chain;
pub mod ladder;
pub mod lm;

use crate::frf::Frf;
use chain::{Chain, ModelBase};
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64;
use std::f64::consts::TAU;
use twoport_design::{DeviceModel, Plant};

/// What an experiment measured: the encoder's response to the actuator's
/// force (m/N) and, where the device has one, the load cell's (N/N), at
/// the same harmonics.
#[derive(Clone, Debug)]
pub struct Measured {
    /// Actuator force (pushing the actuator toward +x) to encoder.
    pub position: Frf,
    /// Actuator force to load cell.
    pub load_cell: Option<Frf>,
}

/// One order's fit.
#[derive(Clone, Debug)]
pub struct ChainFit {
    /// The chain found.
    pub chain: Chain,
    /// Its model file.
    pub model: DeviceModel,
    /// The weighted sum of squared residuals.
    pub chi2: f64,
    /// Residuals (two per harmonic and channel).
    pub residuals: usize,
    /// Parameters fitted.
    pub parameters: usize,
    /// The covariance of the parameters' logarithms, inflated by the
    /// misfit where `χ²/ν > 1`.
    pub covariance: DMatrix<f64>,
    /// The information criterion the order is chosen by.
    pub bic: f64,
}

impl ChainFit {
    /// `χ²` per degree of freedom.
    pub fn reduced_chi2(&self) -> f64 {
        self.chi2 / (self.residuals - self.parameters).max(1) as f64
    }
}

/// Relative floor on each harmonic's standard deviation.
pub const MODEL_FLOOR: f64 = 2e-3;

/// The most modes a fit tries.
pub const MAX_MODES: usize = 4;

/// The model's sampled responses at `freq_hz`: force to encoder (m/N)
/// and force to load cell (N/N), the designer's own `X_aa^d`, `F_ma^d`.
pub fn sampled_response(
    model: &DeviceModel,
    freq_hz: &[f64],
) -> Option<Vec<(Complex64, Complex64)>> {
    let plant = Plant::new(model, model.period_s).ok()?;
    let mut work = plant.scratch();
    freq_hz
        .iter()
        .map(|f| {
            let p = plant.at(TAU * f, &mut work);
            // X_aa^d is -x_a per f_a, and f_a pushes the actuator toward
            // -x: so it is x per push. F_ma^d is per f_a: negate.
            let v = (p.xaa_d, -p.fma_d);
            (v.0.is_finite() && v.1.is_finite()).then_some(v)
        })
        .collect()
}

/// One harmonic's residual: the log of the model's response over the
/// measured one (its real part the log of the magnitudes' ratio, its
/// imaginary part the phase difference), over the measurement's relative
/// standard deviation. Near a relative error this is the relative error;
/// far from one (a sharp resonance a little off) it grows only as a log,
/// so a start near the truth is not thrown far by a peak it misses.
fn residual(model: Complex64, measured: Complex64, var: f64) -> Complex64 {
    let rel = (var / measured.norm_sqr().max(f64::MIN_POSITIVE) + MODEL_FLOOR * MODEL_FLOOR).sqrt();
    let l = (model / measured).ln();
    l / rel
}

/// The weighted residuals of `chain` against `data`.
fn residuals(chain: &Chain, base: &ModelBase, data: &Measured) -> Option<DVector<f64>> {
    let model = chain.model(base)?;
    let h = sampled_response(&model, &data.position.freq_hz)?;
    let mut r = Vec::with_capacity(4 * h.len());
    for (i, (x, f)) in h.iter().enumerate() {
        let e = residual(*x, data.position.response[i], data.position.variance[i]);
        r.push(e.re);
        r.push(e.im);
        if let (Some(lc), true) = (&data.load_cell, model.force_sensor) {
            let e = residual(*f, lc.response[i], lc.variance[i]);
            r.push(e.re);
            r.push(e.im);
        }
    }
    Some(DVector::from_vec(r))
}

/// Total mass (kg) and damping (N s/m) from the lowest harmonics, where
/// the device moves as one body: `1/H ≈ -m ω² + j ω d` once the hold's
/// half-tick delay is taken out.
fn rigid_estimate(data: &Frf, period_s: f64) -> Option<(f64, f64)> {
    let take = data.freq_hz.len().clamp(1, 5);
    let (mut mm, mut dd) = (0.0, 0.0);
    for i in 0..take {
        let w = TAU * data.freq_hz[i];
        let z = 1.0 / (data.response[i] * Complex64::from_polar(1.0, w * period_s / 2.0));
        mm += -z.re / (w * w);
        dd += z.im / w;
    }
    let (m, d) = (mm / take as f64, dd / take as f64);
    (m > 0.0).then_some((m, d.max(1e-3 * m)))
}

/// The `modes` most prominent resonances of `|H| ω²` (indices into the
/// harmonics), in order, each with the deepest dip before it.
fn features(data: &Frf, modes: usize) -> Option<(Vec<usize>, Vec<usize>)> {
    let g: Vec<f64> = data
        .response
        .iter()
        .zip(&data.freq_hz)
        .map(|(h, f)| (h.norm() * f * f).ln())
        .collect();
    let n = g.len();
    let mut peaks: Vec<(f64, usize)> = (1..n.saturating_sub(1))
        .filter(|&i| g[i] > g[i - 1] && g[i] >= g[i + 1])
        .map(|i| {
            let side = |range: &mut dyn Iterator<Item = usize>| {
                let mut low = g[i];
                for j in range {
                    if g[j] > g[i] {
                        break;
                    }
                    low = low.min(g[j]);
                }
                low
            };
            let left = side(&mut (0..i).rev());
            let right = side(&mut (i + 1..n));
            (g[i] - left.max(right), i)
        })
        .collect();
    peaks.sort_by(|a, b| b.0.total_cmp(&a.0));
    if peaks.len() < modes {
        return None;
    }
    let mut res: Vec<usize> = peaks[..modes].iter().map(|p| p.1).collect();
    res.sort_unstable();
    let mut anti = Vec::with_capacity(modes);
    let mut from = 0;
    for &r in &res {
        let a = (from..r).min_by(|&a, &b| g[a].total_cmp(&g[b]))?;
        anti.push(a);
        from = r + 1;
    }
    Some((anti, res))
}

/// Fit a chain of `modes` modes to `data`, or `None` where the
/// measurement shows fewer resonances or the search finds no model.
/// With `stiff_load_cell`, the load cell is a flexure of its own past the
/// band, between the chain and a handle mass (the handle's share of the
/// mass read from the load cell at low frequency); without, it is the
/// chain's last spring.
pub fn fit_chain(
    data: &Measured,
    base: &ModelBase,
    modes: usize,
    stiff_load_cell: bool,
) -> Option<ChainFit> {
    let x = &data.position;
    let (m_t, d_t) = rigid_estimate(x, base.period_s)?;
    let start = if modes == 0 {
        Chain {
            masses_kg: vec![m_t],
            springs_npm: vec![],
            links_nspm: vec![],
            actuator_nspm: d_t,
            handle_nspm: 0.0,
            load_cell_sign: 1.0,
        }
    } else {
        let (anti, res) = features(x, modes)?;
        let w = |i: &usize| TAU * x.freq_hz[*i];
        let anti: Vec<f64> = anti.iter().map(w).collect();
        let res: Vec<f64> = res.iter().map(w).collect();
        let mut l = ladder::synthesise(m_t, &anti, &res)?;
        if stiff_load_cell {
            let lc = data.load_cell.as_ref()?;
            let share = lc.response[..lc.response.len().min(5)]
                .iter()
                .map(|h| h.norm())
                .sum::<f64>()
                / lc.response.len().clamp(1, 5) as f64;
            let last = l.masses_kg.last_mut()?;
            let handle = (share * m_t).clamp(1e-3 * *last, 0.9 * *last);
            *last -= handle;
            l.masses_kg.push(handle);
            // Well past the band: five times Nyquist.
            let w = TAU * 5.0 / (2.0 * base.period_s);
            l.springs_npm.push(handle * w * w);
        }
        let links = (0..l.springs_npm.len())
            .map(|i| {
                let (a, b) = (l.masses_kg[i], l.masses_kg[i + 1]);
                2.0 * 0.03 * (l.springs_npm[i] * a * b / (a + b)).sqrt()
            })
            .collect();
        Chain {
            masses_kg: l.masses_kg,
            springs_npm: l.springs_npm,
            links_nspm: links,
            actuator_nspm: 0.8 * d_t,
            handle_nspm: 0.2 * d_t,
            load_cell_sign: 1.0,
        }
    };
    // The load cell's sign is whichever fits the start better.
    let start = [1.0, -1.0]
        .into_iter()
        .map(|s| Chain {
            load_cell_sign: s,
            ..start.clone()
        })
        .filter_map(|c| residuals(&c, base, data).map(|r| (r.norm_squared(), c)))
        .min_by(|a, b| a.0.total_cmp(&b.0))?
        .1;
    let masses = start.masses_kg.len();
    let sign = start.load_cell_sign;
    // First the dampers alone, the frequencies held where the ladder put
    // them (a guessed damping is what a start gets most wrong), then all.
    let p0 = start.to_log();
    let fixed = masses + (masses - 1);
    let damped = lm::minimise(
        |d| {
            let mut p = p0.clone();
            p.rows_mut(fixed, d.len()).copy_from(d);
            residuals(&Chain::from_log(masses, &p, sign), base, data)
        },
        p0.rows(fixed, p0.len() - fixed).into_owned(),
        50,
    )?;
    let mut p1 = p0.clone();
    p1.rows_mut(fixed, damped.p.len()).copy_from(&damped.p);
    let sol = lm::minimise(
        |p| residuals(&Chain::from_log(masses, p, sign), base, data),
        p1,
        200,
    )?;
    let chain = Chain::from_log(masses, &sol.p, sign);
    let model = chain.model(base)?;
    let residuals = sol.jacobian.nrows();
    let parameters = sol.p.len();
    let nu = (residuals - parameters).max(1) as f64;
    let inflate = (sol.cost / nu).max(1.0);
    let jtj = sol.jacobian.transpose() * &sol.jacobian;
    let eps = 1e-12 * jtj.norm();
    let covariance = jtj.pseudo_inverse(eps).ok()? * inflate;
    Some(ChainFit {
        chain,
        model,
        chi2: sol.cost,
        residuals,
        parameters,
        covariance,
        bic: sol.cost + parameters as f64 * (residuals as f64).ln(),
    })
}

/// Every order from a rigid body to [`MAX_MODES`] that could be fitted,
/// and the index of the one the criterion chooses.
pub fn fit_orders(data: &Measured, base: &ModelBase) -> (Vec<ChainFit>, Option<usize>) {
    let sensor = data.load_cell.is_some() && base.load_cell_pole_rad_s.is_some();
    let fits: Vec<ChainFit> = (0..=MAX_MODES)
        .flat_map(|m| {
            let stiff = sensor.then(|| fit_chain(data, base, m, true)).flatten();
            let inband = (m > 0 || !sensor)
                .then(|| fit_chain(data, base, m, false))
                .flatten();
            stiff.into_iter().chain(inband)
        })
        .collect();
    let best = fits
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.bic.total_cmp(&b.1.bic))
        .map(|(i, _)| i);
    (fits, best)
}

#[cfg(test)]
mod tests;
