//! From a measured frequency response to a physical model whose exact
//! sampled response, the one `twoport design` analyses, matches the
//! measurement at every excited harmonic: a rigid mass-damper, or one to
//! four lightly damped modes.
//!
//! The model's form follows what was measured:
//!
//! - **the encoder alone** ([`chain`]): a chain of masses from the
//!   actuator to the handle. The handle's motion is not observed, so the
//!   chain's end is where it is taken to be; Cauer's ladder ([`ladder`])
//!   gives the one chain with the resonances and antiresonances seen at
//!   the encoder, and the fit starts there.
//! - **the encoder and a load cell** ([`modal`]): the device's modes as
//!   the actuator and the load cell see them, the handle hung on the load
//!   cell. Nothing is assumed of where the handle sits along the
//!   structure. The fit starts from each mode's pole, searched, and its
//!   residues by linear least squares ([`start`]).
//!
//! Then:
//!
//! 1. **Fit** every parameter by Levenberg-Marquardt ([`lm`]) to both
//!    channels, each harmonic weighted by its measured variance (with a
//!    floor of 0.2% of the response, for what no model of a few modes
//!    captures).
//! 2. **Choose the order** by the Bayesian information criterion,
//!    `χ² + p ln(N)` over the orders that could be started: a mode is kept
//!    only if it explains more than noise would. The orders are climbed
//!    from a rigid body, and the climb stops at the first that explains
//!    the data to their noise ([`Fit::at_noise`]).
//! 3. **Bound** the fit: the parameters' covariance from the Jacobian,
//!    inflated by the misfit (`χ²/ν` where above one).

mod body;
pub mod chain;
mod chain_fit;
pub mod cogging;
mod features;
pub mod friction;
pub mod ladder;
pub mod lm;
mod loaded;
pub(crate) mod measured;
pub mod modal;
pub mod start;
pub mod uncertainty;

use chain::{Chain, ModelBase};
use modal::Modal;
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64;
use std::f64::consts::TAU;
use twoport_design::{DeviceModel, Plant};

pub(crate) use body::body_band_hz;
use body::{ground_shown, rigid_estimate};
pub use chain_fit::fit_chain;
use features::features;
pub use measured::{Loaded, Measured, LEAST_BAND_SHARE};

/// The physical form of a fitted model.
#[derive(Clone, Debug, PartialEq)]
pub enum Form {
    /// A chain of masses (the encoder alone measured).
    Chain(Chain),
    /// Modes with the handle on a load cell.
    Modal(Modal),
}

impl Form {
    /// Flexible modes in the band.
    pub fn modes(&self) -> usize {
        match self {
            Form::Chain(c) => c.modes(),
            Form::Modal(m) => m.modes.len(),
        }
    }

    /// The model-file form.
    pub fn model(&self, base: &ModelBase) -> Option<DeviceModel> {
        match self {
            Form::Chain(c) => c.model(base),
            Form::Modal(m) => m.model(base),
        }
    }
}

/// One order's fit.
#[derive(Clone, Debug)]
pub struct Fit {
    /// The model found, in its physical form.
    pub form: Form,
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
    /// The parameters found, in the form's own order
    /// ([`Chain::to_log`], [`Modal::to_params`]); the covariance's first
    /// rows and columns are theirs, and its last, where the record showed
    /// friction or cogging, their amounts'.
    pub params: DVector<f64>,
    /// What the model was built on.
    pub base: ModelBase,
    /// Whether a loaded record was fitted too (the handle's side seen).
    pub loaded: bool,
    /// The cogging found beside the model, if the record showed any.
    pub cogging: Option<cogging::Found>,
}

impl Fit {
    /// The model at other parameters of the same form (the order of
    /// [`params`](Self::params)), with the fit's friction and encoder
    /// quantum; `None` where they make no valid model.
    pub fn model_at(&self, p: &DVector<f64>) -> Option<DeviceModel> {
        let mut m = match &self.form {
            Form::Chain(c) => Chain::from_log(
                c.masses_kg.len(),
                c.ground.map(|g| g.at),
                p,
                c.load_cell_sign,
            )
            .model(&self.base),
            Form::Modal(m) => Modal::from_params(
                p,
                m.load_cell_sign,
                self.base.period_s,
                m.bypass_npm.is_some(),
            )
            .model(&self.base),
        }?;
        m.coulomb_friction_n = self.model.coulomb_friction_n;
        m.encoder_quantum_m = self.model.encoder_quantum_m;
        Some(m)
    }

    /// Whether the misfit is what the noise alone would leave: `χ²/ν`
    /// within three of its standard deviations (`√(2/ν)`) of one, or
    /// below.
    pub fn at_noise(&self) -> bool {
        self.reduced_chi2() <= 1.0 + 3.0 * (2.0 / self.dof()).sqrt()
    }

    /// Degrees of freedom `ν`: residuals less parameters (at least one).
    fn dof(&self) -> f64 {
        self.residuals.saturating_sub(self.parameters).max(1) as f64
    }

    /// `χ²` per degree of freedom.
    pub fn reduced_chi2(&self) -> f64 {
        self.chi2 / self.dof()
    }

    /// The fitted model's resonances below Nyquist, lowest first: each
    /// one's frequency (Hz) and damping ratio.
    pub fn resonances(&self) -> Vec<(f64, f64)> {
        let m = &self.model;
        Plant::new(m, m.period_s)
            .map(|p| {
                p.modes()
                    .iter()
                    .map(|x| (x.omega_n / TAU, x.zeta))
                    .filter(|(hz, _)| *hz < 0.5 / m.period_s)
                    .collect()
            })
            .unwrap_or_default()
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
            let (xaa_d, fma_d) = plant.sampled_at(TAU * f, &mut work);
            // X_aa^d is -x_a per f_a, and f_a pushes the actuator toward
            // -x: so it is x per push. F_ma^d is per f_a: negate.
            let v = (xaa_d, -fma_d);
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

/// The weighted residuals of `model` against `data`, with `amounts` (N)
/// more of each of its forces than `data` has had taken out (see
/// [`friction`]).
fn residuals(model: &DeviceModel, data: &Measured, amounts: &[f64]) -> Option<DVector<f64>> {
    let h = sampled_response(model, &data.position.freq_hz)?;
    let mut r = Vec::with_capacity(4 * h.len());
    for (i, (x, f)) in h.iter().enumerate() {
        // The device felt the push less its forces: X = H (F - Σ c_j R_j).
        let felt = 1.0
            - data
                .forces
                .iter()
                .zip(amounts)
                .map(|(g, c)| c * g.per_force[i])
                .sum::<Complex64>();
        let e = residual(
            *x * felt,
            data.position.response[i],
            data.position.variance[i],
        );
        r.push(e.re);
        r.push(e.im);
        if let (Some(lc), true) = (&data.load_cell, model.force_sensor) {
            let e = residual(*f * felt, lc.response[i], lc.variance[i]);
            r.push(e.re);
            r.push(e.im);
        }
    }
    if let Some(l) = &data.loaded {
        let loaded = model.with_handle_mass(l.added_kg).ok()?;
        r.extend(residuals(&loaded, &l.data, amounts)?.iter());
    }
    Some(DVector::from_vec(r))
}

/// Fit `modes` modes, with the handle on its load cell, to what the
/// encoder and the load cell measured; `None` where the measurement
/// shows fewer resonances or the search finds no model.
pub fn fit_modal(data: &Measured, base: &ModelBase, modes: usize) -> Option<Fit> {
    let x = &data.position;
    let pole = base.load_cell_pole_rad_s?;
    let rigid = rigid_estimate(x, base.period_s)?;
    let omegas: Vec<f64> = if modes == 0 {
        Vec::new()
    } else {
        features(x, modes)?
            .1
            .iter()
            .map(|i| TAU * x.freq_hz[*i])
            .collect()
    };
    let start = start::modal_start(data, base.period_s, pole, rigid, &omegas)?;
    let sign = start.load_cell_sign;
    let from = |p: &DVector<f64>| Modal::from_params(p, sign, base.period_s, false);
    // First with proportional damping, then with the modes' coupling: the
    // coupling is small, and fitting it from a start far off only slows
    // the search.
    let full = start.to_params();
    let coupled = start.coupling.len();
    let plain = full.rows(0, full.len() - coupled).into_owned();
    let widen = |p: &DVector<f64>| {
        DVector::from_iterator(
            full.len(),
            p.iter().copied().chain(std::iter::repeat_n(0.0, coupled)),
        )
    };
    let first = lm::minimise(
        |p| {
            from(&widen(p))
                .model(base)
                .and_then(|m| residuals(&m, data, &[]))
        },
        plain,
        200,
    )?;
    finish(
        data,
        base,
        widen(&first.p),
        |p| from(p).model(base),
        |p| Form::Modal(from(p)),
    )
}

/// Levenberg-Marquardt from `p0` on every parameter, and the fit's
/// statistics where it ends.
fn finish(
    data: &Measured,
    base: &ModelBase,
    p0: DVector<f64>,
    model: impl Fn(&DVector<f64>) -> Option<DeviceModel> + Sync,
    form: impl Fn(&DVector<f64>) -> Form,
) -> Option<Fit> {
    // Where the record shows friction or cogging, their amounts are
    // parameters too, the last: what is left of them once the start's
    // estimates were taken out.
    let extra = data.forces.len();
    let k = p0.len();
    let p0 = DVector::from_iterator(
        k + extra,
        p0.iter().copied().chain(std::iter::repeat_n(0.0, extra)),
    );
    let split = |p: &DVector<f64>| (p.rows(0, k).into_owned(), p.as_slice()[k..].to_vec());
    let sol = lm::minimise(
        |p| {
            let (q, amounts) = split(p);
            model(&q).and_then(|m| residuals(&m, data, &amounts))
        },
        p0,
        200,
    )?;
    let (q, more) = split(&sol.p);
    let mut found = model(&q)?;
    let total = |shape: fn(&friction::Shape) -> bool| {
        data.forces
            .iter()
            .zip(&more)
            .find(|(g, _)| shape(&g.shape))
            .map(|(g, c)| g.taken_n + c)
    };
    found.coulomb_friction_n = total(|s| *s == friction::Shape::Coulomb).map(|f| f.max(0.0));
    found.encoder_quantum_m = data.encoder_quantum_m;
    let cogging = data.forces.iter().find_map(|g| match g.shape {
        friction::Shape::CoggingSin { period_m } => {
            let a = total(|s| matches!(s, friction::Shape::CoggingSin { .. }))?;
            let b = total(|s| matches!(s, friction::Shape::CoggingCos { .. }))?;
            Some(cogging::Found {
                amplitude_n: a.hypot(b),
                period_m,
            })
        }
        _ => None,
    });
    let residuals = sol.jacobian.nrows();
    let parameters = sol.p.len();
    let nu = residuals.saturating_sub(parameters).max(1) as f64;
    let inflate = (sol.cost / nu).max(1.0);
    let jtj = sol.jacobian.transpose() * &sol.jacobian;
    let eps = 1e-12 * jtj.norm();
    let covariance = jtj.pseudo_inverse(eps).ok()? * inflate;
    Some(Fit {
        form: form(&q),
        model: found,
        chi2: sol.cost,
        residuals,
        parameters,
        covariance,
        bic: sol.cost + parameters as f64 * (residuals as f64).ln(),
        params: q,
        base: base.clone(),
        loaded: data.loaded.is_some(),
        cogging,
    })
}

/// The most `χ²/ν` an axis's fit is taken at. A record its model
/// explains leaves 1 or less (0.1 to 0.4 on the simulated Excalibur,
/// capstan and two-mass device, whose noise the periods' spread
/// overestimates); a clean record that stops short of a mode, about 9
/// (the Excalibur to 200 Hz at 0.5% noise). Up to this bound a fit is
/// taken, the set around it widened by its misfit. A record the fit's
/// class cannot hold leaves far more (the Excalibur's 4 ms late, 39,000;
/// a reversed sign, tens of thousands), or no order converges: past 25,
/// the misfit's RMS five times the noise's, a model would claim what the
/// device does not have.
pub const MOST_AXIS_MISFIT: f64 = 25.0;

/// The fit [`fit_orders`] chose, or why none is taken: no order
/// converged, the record gives no more values than the fit has
/// parameters (nothing is left to tell the fit from the noise), or the
/// best leaves more than [`MOST_AXIS_MISFIT`] times the record's noise.
pub fn chosen(fits: &[Fit], best: Option<usize>) -> Result<&Fit, crate::IdentifyError> {
    let f = best
        .and_then(|i| fits.get(i))
        .ok_or(crate::IdentifyError::NoFit { most: MAX_MODES })?;
    if f.residuals <= f.parameters {
        return Err(crate::IdentifyError::TooFewHarmonics {
            values: f.residuals,
            parameters: f.parameters,
        });
    }
    if f.reduced_chi2() > MOST_AXIS_MISFIT {
        return Err(crate::IdentifyError::Misfit {
            modes: f.form.modes(),
            misfit: f.reduced_chi2(),
            most: MOST_AXIS_MISFIT,
        });
    }
    Ok(f)
}

/// Every order from a rigid body to [`MAX_MODES`] that could be fitted,
/// in the form the measurement calls for, and the index of the one the
/// criterion chooses.
pub fn fit_orders(data: &Measured, base: &ModelBase) -> (Vec<Fit>, Option<usize>) {
    // Friction and cogging out first, where the record shows them:
    // estimated where the device moves as one body, a quarter of the way
    // to its lowest resonance. The start's estimate is refined by each
    // fit's last step.
    let linear;
    let data = if data.forces.is_empty() {
        data
    } else {
        let below = body_band_hz(&data.position, base.period_s);
        let mut amounts = friction::rigid_with(data, &[], 0, base.period_s, below)
            .map_or(vec![0.0; data.forces.len()], |r| r.2);
        // Friction opposes the motion: an estimate below zero is none.
        for (g, c) in data.forces.iter().zip(amounts.iter_mut()) {
            if g.shape == friction::Shape::Coulomb {
                *c = c.max(0.0);
            }
        }
        linear = friction::without(data, &amounts);
        &linear
    };
    fit_orders_linear(data, base)
}

/// [`fit_orders`] on a record with no friction in it.
fn fit_orders_linear(data: &Measured, base: &ModelBase) -> (Vec<Fit>, Option<usize>) {
    let Some(loaded) = &data.loaded else {
        return climb(data, base);
    };
    // The order is chosen on the bare record, the one the modes show in
    // best; the chosen fit is then refitted to both records, and is last.
    let bare = Measured {
        loaded: None,
        ..data.clone()
    };
    let (mut fits, best) = climb(&bare, base);
    match best.and_then(|i| loaded::refit_loaded(&fits[i], data, loaded)) {
        Some(joint) => {
            fits.push(joint);
            let last = fits.len() - 1;
            (fits, Some(last))
        }
        None => (fits, best),
    }
}

/// The orders climbed on one record.
fn climb(data: &Measured, base: &ModelBase) -> (Vec<Fit>, Option<usize>) {
    let sensor = data.load_cell.is_some() && base.load_cell_pole_rad_s.is_some();
    // With a load cell, the modes are the device's own and the handle
    // hangs on a stiff flexure; where the handle cannot be taken out of
    // the modes that way, its flexure is itself one of them, and the
    // chain with the load cell as its last spring is fitted instead.
    let encoder_only;
    let (data, base) = if sensor {
        (data, base)
    } else {
        encoder_only = (
            Measured {
                load_cell: None,
                ..data.clone()
            },
            ModelBase {
                load_cell_pole_rad_s: None,
                ..base.clone()
            },
        );
        (&encoder_only.0, &encoder_only.1)
    };
    // A record whose low harmonics show a spring to the frame is fitted
    // with the spring at each mass of the chain as well; each order keeps
    // its form of least criterion (they differ by the spring's one
    // parameter, which the criterion charges).
    let grounded = ground_shown(&data.position, base.period_s).is_some();
    let mut fits: Vec<Fit> = Vec::new();
    for m in 0..=MAX_MODES {
        let free = if sensor {
            fit_modal(data, base, m)
                .or_else(|| (m > 0).then(|| fit_chain(data, base, m, None)).flatten())
        } else {
            fit_chain(data, base, m, None)
        };
        let held = (0..=m)
            .filter(|_| grounded)
            .filter_map(|at| fit_chain(data, base, m, Some(at)));
        let Some(fit) = free
            .into_iter()
            .chain(held)
            .min_by(|a, b| a.bic.total_cmp(&b.bic))
        else {
            continue;
        };
        let done = fit.at_noise();
        fits.push(fit);
        // A model that explains the data to their noise leaves a further
        // mode only the noise to fit: p more parameters lower χ² by about
        // p, and the criterion charges p ln(N). The climb stops there.
        if done {
            break;
        }
    }
    let best = fits
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.bic.total_cmp(&b.1.bic))
        .map(|(i, _)| i);
    (fits, best)
}

#[cfg(test)]
mod bench_tests;
#[cfg(test)]
mod elsewhere_tests;
#[cfg(test)]
pub(crate) mod tests;
