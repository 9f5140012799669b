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

pub mod chain;
pub mod cogging;
pub mod friction;
pub mod ladder;
pub mod lm;
pub mod modal;
pub mod start;
pub mod uncertainty;

use crate::frf::Frf;
use chain::{Chain, ModelBase};
use modal::Modal;
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
    /// The forces the device adds that depend on its motion (friction,
    /// cogging), each known up to its amount ([`friction`]); none where
    /// the record could not give their shapes.
    pub forces: Vec<friction::Regressor>,
    /// The encoder's quantum (m), where the record shows it: the least
    /// step between the positions it read.
    pub encoder_quantum_m: Option<f64>,
    /// The record's mean motion, where it gave one: cogging's shapes at
    /// any period come from it.
    pub motion: Option<cogging::Motion>,
    /// The same experiment with a known mass clamped on the handle, if it
    /// was played: fitted together with this one, it shows the handle's
    /// side of the device, which the actuator's push alone barely moves.
    pub loaded: Option<Box<Loaded>>,
}

/// An experiment played with a known mass on the handle.
#[derive(Clone, Debug)]
pub struct Loaded {
    /// The mass added (kg).
    pub added_kg: f64,
    /// What it measured (its own `loaded` is `None`).
    pub data: Measured,
}

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

impl Measured {
    /// The responses an experiment's record shows at the harmonics it
    /// played, averaged over its whole periods after the first `skip` (the
    /// transient). Refused, with the reason: a record that does not name
    /// its excitation, or one [`frf::periodic`](crate::frf::periodic)
    /// refuses.
    pub fn from_log(log: &crate::log::Log, skip: usize) -> Result<Measured, crate::IdentifyError> {
        let e = log.excitation.ok_or(crate::IdentifyError::Log {
            place: "the record".into(),
            why: "it does not name its excitation (the `# twoport experiment:` line)".into(),
        })?;
        clipped(&log.force_n, log.period_s)?;
        let harmonics: Vec<usize> = (e.first..=e.last).collect();
        let at = |signal: &[f64]| {
            crate::frf::periodic(
                &log.force_n,
                signal,
                log.period_s,
                e.period_ticks,
                &harmonics,
                skip,
            )
        };
        let spectrum = |x: &[f64]| crate::frf::mean_spectrum(x, e.period_ticks, &harmonics, skip);
        let force = spectrum(&log.force_n);
        // A quantised reading's error repeats with the motion, period after
        // period, so no averaging removes it: its share of each harmonic,
        // `N q²/12` (`q` the least step the record shows), is a floor on
        // that harmonic's variance. Where the response is far below a
        // count, the harmonic then counts for what it is worth.
        let floored = |mut f: Frf, signal: &[f64]| {
            let q = quantum(signal);
            if let Some(q) = q {
                let floor = e.period_ticks as f64 * q * q / 12.0;
                for (v, fm) in f.variance.iter_mut().zip(&force) {
                    *v += floor / fm.norm_sqr().max(f64::MIN_POSITIVE);
                }
            }
            (f, q)
        };
        let (position, encoder) = floored(at(&log.position_m)?, &log.position_m);
        let load_cell = match log.load_cell_n.as_deref() {
            Some(lc) => Some(floored(at(lc)?, lc).0),
            None => None,
        };
        let sign = friction::tick_sign(&log.position_m, e.period_ticks, e.last, skip);
        let mut forces: Vec<friction::Regressor> = sign
            .map(|sign| friction::Regressor {
                shape: friction::Shape::Coulomb,
                per_force: crate::frf::mean_spectrum(&sign, e.period_ticks, &harmonics, 0)
                    .iter()
                    .zip(&force)
                    .map(|(s, f)| s / f)
                    .collect(),
                taken_n: 0.0,
            })
            .into_iter()
            .collect();
        let motion = cogging::Motion::new(&log.position_m, e.period_ticks, &harmonics, force, skip);
        let mut data = Measured {
            position,
            load_cell,
            forces: Vec::new(),
            encoder_quantum_m: encoder,
            motion,
            loaded: None,
        };
        if let (Some(motion), false) = (&data.motion, forces.is_empty()) {
            data.forces = forces.clone();
            let below = rigid_band_hz(&data.position);
            if let Some(c) = cogging::find(&data, motion, log.period_s, below) {
                forces.extend(c);
            }
        }
        data.forces = forces;
        Ok(data)
    }

    /// These responses with `loaded`'s, measured with `added_kg` on the
    /// handle, to be fitted together. Refused where the mass is not
    /// finite and positive, or the two did not play the same harmonics or
    /// read the same sensors.
    pub fn with_loaded(
        self,
        added_kg: f64,
        loaded: Measured,
    ) -> Result<Measured, crate::IdentifyError> {
        let refuse = |why: String| crate::IdentifyError::Log {
            place: "the loaded record".into(),
            why,
        };
        if !(added_kg.is_finite() && added_kg > 0.0) {
            return Err(refuse(format!(
                "the mass on the handle, {added_kg} kg, must be finite and positive"
            )));
        }
        if loaded.position.freq_hz != self.position.freq_hz {
            return Err(refuse(
                "it played other harmonics than the bare record: play the same experiment".into(),
            ));
        }
        if loaded.load_cell.is_some() != self.load_cell.is_some() {
            return Err(refuse(
                "one record has a load cell and the other has not".into(),
            ));
        }
        // The same forces, each shape from the loaded record's own motion.
        let mut forces = Vec::new();
        for f in &self.forces {
            let own = match f.shape {
                friction::Shape::Coulomb => loaded
                    .forces
                    .iter()
                    .find(|g| g.shape == friction::Shape::Coulomb)
                    .cloned(),
                friction::Shape::CoggingSin { period_m } => loaded
                    .motion
                    .as_ref()
                    .map(|m| cogging::shapes(m, period_m)[0].clone()),
                friction::Shape::CoggingCos { period_m } => loaded
                    .motion
                    .as_ref()
                    .map(|m| cogging::shapes(m, period_m)[1].clone()),
            };
            forces.push(own.ok_or_else(|| {
                refuse(
                    "it does not show the motion the bare record's friction and cogging need"
                        .into(),
                )
            })?);
        }
        Ok(Measured {
            loaded: Some(Box::new(Loaded {
                added_kg,
                data: Measured {
                    loaded: None,
                    forces,
                    ..loaded
                },
            })),
            ..self
        })
    }
}

/// Refuse a force that sits at its largest magnitude for two samples
/// running or more: a multisine touches its peak once a period at most,
/// so a run there is a limit cutting it.
fn clipped(force_n: &[f64], period_s: f64) -> Result<(), crate::IdentifyError> {
    let peak = force_n.iter().fold(0.0_f64, |a, f| a.max(f.abs()));
    if peak == 0.0 {
        return Ok(());
    }
    let at_peak = |f: &f64| f.abs() >= peak * (1.0 - 1e-12);
    let first = force_n
        .windows(2)
        .position(|w| at_peak(&w[0]) && at_peak(&w[1]));
    match first {
        None => Ok(()),
        Some(i) => Err(crate::IdentifyError::Clipped {
            samples: force_n.iter().filter(|f| at_peak(f)).count(),
            force_n: force_n[i],
            at_s: i as f64 * period_s,
        }),
    }
}

/// The least step between the values a quantised signal took, if it
/// took two.
fn quantum(signal: &[f64]) -> Option<f64> {
    let mut levels = signal.to_vec();
    levels.sort_by(f64::total_cmp);
    levels.dedup();
    let q = levels
        .windows(2)
        .map(|w| w[1] - w[0])
        .fold(f64::INFINITY, f64::min);
    q.is_finite().then_some(q)
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
            Form::Chain(c) => {
                Chain::from_log(c.masses_kg.len(), p, c.load_cell_sign).model(&self.base)
            }
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
        (self.residuals - self.parameters).max(1) as f64
    }

    /// `χ²` per degree of freedom.
    pub fn reduced_chi2(&self) -> f64 {
        self.chi2 / self.dof()
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

/// Every peak of `ln(|H| ω²)`: its prominence over the deeper of the
/// dips either side before a higher point, and its index.
fn peaks(data: &Frf) -> (Vec<f64>, Vec<(f64, usize)>) {
    let g: Vec<f64> = data
        .response
        .iter()
        .zip(&data.freq_hz)
        .map(|(h, f)| (h.norm() * f * f).ln())
        .collect();
    let n = g.len();
    let peaks = (1..n.saturating_sub(1))
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
    (g, peaks)
}

/// The `modes` most prominent resonances of `|H| ω²` (indices into the
/// harmonics), in order, each with the deepest dip before it.
fn features(data: &Frf, modes: usize) -> Option<(Vec<usize>, Vec<usize>)> {
    let (g, mut peaks) = peaks(data);
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

/// Fit a chain of `modes` modes, or `None` where the measurement shows
/// fewer resonances or the search finds no model. A load cell, if
/// measured, is the chain's last spring: a flexure in the band.
pub fn fit_chain(data: &Measured, base: &ModelBase, modes: usize) -> Option<Fit> {
    let x = &data.position;
    let (m_t, d_t) = rigid_estimate(x, base.period_s)?;
    // At low frequency the load cell reads the force that accelerates the
    // handle's mass, `-sign m_h/m_t` of the push (the acceleration per
    // push has a positive real part, whatever the damping).
    let sign = match &data.load_cell {
        Some(lc) if lc.response.iter().take(5).map(|h| h.re).sum::<f64>() > 0.0 => -1.0,
        _ => 1.0,
    };
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
        let l = ladder::synthesise(m_t, &anti, &res)?;
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
            // The damping to ground starts at the actuator: at the handle
            // it would show in a load cell at low frequency, where the
            // handle's mass alone does.
            actuator_nspm: d_t,
            handle_nspm: 1e-3 * d_t,
            load_cell_sign: sign,
        }
    };
    let masses = start.masses_kg.len();
    let model = |p: &DVector<f64>| Chain::from_log(masses, p, sign).model(base);
    // First the dampers alone, the frequencies held where the ladder put
    // them (a guessed damping is what a start gets most wrong), then all.
    let p0 = start.to_log();
    let fixed = masses + (masses - 1);
    let damped = lm::minimise(
        |d| {
            let mut p = p0.clone();
            p.rows_mut(fixed, d.len()).copy_from(d);
            model(&p).and_then(|m| residuals(&m, data, &[]))
        },
        p0.rows(fixed, p0.len() - fixed).into_owned(),
        50,
    )?;
    let mut p1 = p0.clone();
    p1.rows_mut(fixed, damped.p.len()).copy_from(&damped.p);
    finish(data, base, p1, model, |p| {
        Form::Chain(Chain::from_log(masses, p, sign))
    })
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

/// A bare record's fit `bare` refitted to both records, bare and loaded:
/// from its parameters, and in the modal form with a
/// [bypass](Modal::bypass_npm) beside the load cell, which only the loaded
/// record shows. The bypass starts from a few strengths, the handle's
/// mass from the bare fit's and from what the load cell weighed (the fit
/// is not convex in them), and the least misfit is kept.
fn refit_loaded(bare: &Fit, data: &Measured, loaded: &Loaded) -> Option<Fit> {
    let base = &bare.base;
    let encoder_only;
    let data = if bare.model.force_sensor {
        data
    } else {
        encoder_only = Measured {
            load_cell: None,
            loaded: Some(Box::new(Loaded {
                added_kg: loaded.added_kg,
                data: Measured {
                    load_cell: None,
                    ..loaded.data.clone()
                },
            })),
            ..data.clone()
        };
        &encoder_only
    };
    let m = match &bare.form {
        Form::Chain(c) => {
            let (masses, sign) = (c.masses_kg.len(), c.load_cell_sign);
            return finish(
                data,
                base,
                bare.params.clone(),
                |p| Chain::from_log(masses, p, sign).model(base),
                |p| Form::Chain(Chain::from_log(masses, p, sign)),
            );
        }
        Form::Modal(m) => m,
    };
    let sign = m.load_cell_sign;
    let from = |p: &DVector<f64>| Modal::from_params(p, sign, base.period_s, true);
    // The lowest mode the bare fit found, or the top of the band.
    let w = m
        .modes
        .iter()
        .map(|m| m.omega_rad_s)
        .fold(TAU * data.position.freq_hz.last().copied()?, f64::min);
    // The load cell weighs the handle: at the lowest harmonics it reads
    // `m_h` per unit of acceleration bare and `m_h + m` loaded, so the
    // ratio of the two readings per motion gives `m_h` (the bypass hardly
    // stretches there). The bare fit's is a start too.
    let weighed = weighed_handle(data, loaded).filter(|h| (0.2..5.0).contains(&(h / m.handle_kg)));
    // Every parameter from several starts: the misfit is not convex in
    // the handle's mass and the bypass, and the modes move with them.
    [Some(m.handle_kg), weighed]
        .into_iter()
        .flatten()
        .flat_map(|h| [1e-3, 1e-2, 1e-1, 1.0].map(|share| (h, share * h * w * w)))
        .filter_map(|(handle_kg, kb)| {
            let start = Modal {
                handle_kg,
                bypass_npm: Some(kb),
                ..m.clone()
            };
            finish(
                data,
                base,
                start.to_params(),
                |p| from(p).model(base),
                |p| Form::Modal(from(p)),
            )
        })
        .min_by(|a, b| a.chi2.total_cmp(&b.chi2))
}

/// The handle's mass past the load cell (kg) from the lowest harmonics of
/// a bare and a loaded record: the load cell's reading per encoder motion
/// is `m_h ω²` bare and `(m_h + m) ω²` loaded.
fn weighed_handle(bare: &Measured, loaded: &Loaded) -> Option<f64> {
    let per_motion = |d: &Measured| -> Option<Vec<Complex64>> {
        let lc = d.load_cell.as_ref()?;
        Some(
            lc.response
                .iter()
                .zip(&d.position.response)
                .take(5)
                .map(|(f, x)| f / x)
                .collect(),
        )
    };
    let (b, l) = (per_motion(bare)?, per_motion(&loaded.data)?);
    let ratio = b.iter().zip(&l).map(|(b, l)| (l / b).re).sum::<f64>() / b.len() as f64;
    let m = loaded.added_kg / (ratio - 1.0);
    (m.is_finite() && m > 0.0).then_some(m)
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
    let nu = (residuals - parameters).max(1) as f64;
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
        let below = rigid_band_hz(&data.position);
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

/// Below where the device moves as one body (Hz): a quarter of the way to
/// its lowest resonance, or of the band where it shows none.
fn rigid_band_hz(x: &Frf) -> f64 {
    lowest_resonance_hz(x)
        .or(x.freq_hz.last().copied())
        .unwrap_or(0.0)
        / 4.0
}

/// The lowest resonance seen at the encoder (Hz): a peak of `|H| ω²` at
/// least twice the lower of the least values either side within a factor
/// of 1.5 in frequency. A rigid body's is flat, and friction, cogging and
/// the band's ends bend it slowly, not in a peak.
fn lowest_resonance_hz(x: &Frf) -> Option<f64> {
    let (g, peaks) = peaks(x);
    let f = &x.freq_hz;
    let least = |range: std::ops::Range<usize>| range.map(|j| g[j]).fold(f64::INFINITY, f64::min);
    peaks
        .iter()
        .map(|(_, i)| *i)
        .filter(|&i| {
            let lo = f.partition_point(|v| *v < f[i] / 1.5);
            let hi = f.partition_point(|v| *v <= f[i] * 1.5);
            let dip = least(lo..i).max(least(i + 1..hi));
            g[i] - dip > std::f64::consts::LN_2
        })
        .map(|i| f[i])
        .reduce(f64::min)
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
    match best.and_then(|i| refit_loaded(&fits[i], data, loaded)) {
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
    let mut fits: Vec<Fit> = Vec::new();
    for m in 0..=MAX_MODES {
        let fit = if sensor {
            fit_modal(data, base, m).or_else(|| (m > 0).then(|| fit_chain(data, base, m)).flatten())
        } else {
            fit_chain(data, base, m)
        };
        let Some(fit) = fit else { continue };
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
mod tests;
