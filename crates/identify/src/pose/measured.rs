//! The response matrix at a pose, from one experiment per axis.

use crate::frf::{spectra, whole_periods};
use crate::log::{Excitation, Log};
use crate::IdentifyError;
use nalgebra::DMatrix;
use num_complex::Complex64;

/// The response matrix `H` (m/N) at each excited harmonic, `X = H F`,
/// with each entry's variance.
#[derive(Clone, Debug, PartialEq)]
pub struct PoseMeasured {
    /// The control period (s).
    pub period_s: f64,
    /// Each harmonic's frequency (Hz).
    pub freq_hz: Vec<f64>,
    /// The response matrix there: row the axis that moved, column the
    /// axis pushed (m/N).
    pub response: Vec<DMatrix<Complex64>>,
    /// Each entry's variance, `E|H - H_true|²` (m²/N²), from the spread
    /// of the periods.
    pub variance: Vec<DMatrix<f64>>,
    /// Whole periods averaged in each experiment.
    pub periods: usize,
}

fn bad(place: String, why: String) -> IdentifyError {
    IdentifyError::Log { place, why }
}

impl PoseMeasured {
    /// `experiments[j][i]` is axis `i`'s record in the experiment that
    /// pushed axis `j` (its force the excitation and the hold, the other
    /// axes' the hold alone), each averaged over its whole periods after
    /// the first `skip`. Refused, naming the record: a count of
    /// experiments or axes that is not square, records that did not play
    /// the same excitation at the same period or length, a sample that is
    /// not a number, a clipped excitation, or a harmonic where the forces
    /// of the experiments do not span every axis.
    pub fn from_logs(experiments: &[Vec<Log>], skip: usize) -> Result<Self, IdentifyError> {
        let n = experiments.len();
        let first = experiments
            .first()
            .and_then(|e| e.first())
            .ok_or_else(|| bad("the records".into(), "there are none".into()))?;
        let e = first.excitation.ok_or_else(|| {
            bad(
                "experiment 0, axis 0".into(),
                "it does not name its excitation (the `# twoport experiment:` line)".into(),
            )
        })?;
        let (period, first_h, last_h) = e.periodic().ok_or_else(|| {
            bad(
                "experiment 0, axis 0".into(),
                "a stepped sine: a pose's response matrix is read from periodic records".into(),
            )
        })?;
        let max = period.saturating_sub(1) / 2;
        if first_h > last_h {
            return Err(IdentifyError::Harmonic {
                harmonic: last_h,
                period,
                max,
            });
        }
        let harmonics: Vec<usize> = (first_h..=last_h).collect();
        let periods = checked(experiments, first, e, &harmonics, skip)?;
        let spec = |x: &[f64]| spectra(x, period, &harmonics, skip, periods);
        // The harmonics the multisine leaves out, past its band: what the
        // position shows there is noise that repeats period after period
        // (the encoders' quantisation, at a pose's Cartesian readings a
        // step that is no one number), which no averaging removes. Its
        // power per harmonic in each axis's mean spectrum is a floor on
        // the excited harmonics' variance.
        let quiet: Vec<usize> = (last_h + 1..=max).collect();
        let noise = repeating_noise(experiments, period, &quiet, skip);
        // [experiment][axis][period][harmonic]
        let (f, x): (Vec<Vec<_>>, Vec<Vec<_>>) = experiments
            .iter()
            .map(|axes| {
                axes.iter()
                    .map(|l| (spec(&l.force_n), spec(&l.position_m)))
                    .unzip()
            })
            .unzip();
        let hz = |h: usize| h as f64 / (period as f64 * first.period_s);
        let mut out = PoseMeasured {
            period_s: first.period_s,
            freq_hz: harmonics.iter().map(|&h| hz(h)).collect(),
            response: Vec::with_capacity(harmonics.len()),
            variance: Vec::with_capacity(harmonics.len()),
            periods,
        };
        let p = periods as f64;
        for (k, &h) in harmonics.iter().enumerate() {
            let at = |s: &Vec<Vec<Vec<Vec<Complex64>>>>, per: usize| {
                DMatrix::from_fn(n, n, |i, j| s[j][i][per][k])
            };
            let mean = |s: &Vec<Vec<Vec<Vec<Complex64>>>>| {
                (0..periods)
                    .map(|per| at(s, per))
                    .fold(DMatrix::zeros(n, n), |a, b| a + b)
                    / Complex64::new(p, 0.0)
            };
            let (fm, xm) = (mean(&f), mean(&x));
            let f_inv = fm.clone().try_inverse().filter(|_| {
                let sv = fm.singular_values();
                sv.min() > 1e-9 * sv.max()
            });
            let Some(f_inv) = f_inv else {
                return Err(IdentifyError::NoExcitation {
                    harmonic: h,
                    hz: hz(h),
                    force: fm.singular_values().min(),
                });
            };
            let resp = &xm * &f_inv;
            // First order: one period's error is (δX - H δF) F^-1.
            let mut var = DMatrix::zeros(n, n);
            for per in 0..periods {
                let dx = at(&x, per) - &xm;
                let df = at(&f, per) - &fm;
                let dh = (dx - &resp * df) * &f_inv;
                var += dh.map(|c| c.norm_sqr());
            }
            let floor = DMatrix::from_fn(n, n, |i, j| {
                (0..n)
                    .map(|l| noise[i] * f_inv[(l, j)].norm_sqr())
                    .sum::<f64>()
            });
            out.variance.push(var / (p * (p - 1.0)) + floor);
            out.response.push(resp);
        }
        Ok(out)
    }
}

/// Every record of `experiments` checked against `first` (the same
/// excitation, period and length, one record per axis, finite samples,
/// the pushed axis's force not clipped); the whole periods averaged.
fn checked(
    experiments: &[Vec<Log>],
    first: &Log,
    e: Excitation,
    harmonics: &[usize],
    skip: usize,
) -> Result<usize, IdentifyError> {
    let n = experiments.len();
    let period = e.periodic().map_or(0, |p| p.0);
    let mut periods = 0;
    for (j, axes) in experiments.iter().enumerate() {
        if axes.len() != n {
            return Err(bad(
                format!("experiment {j}"),
                format!(
                    "{} axes recorded, but there are {n} experiments: one is needed per axis",
                    axes.len()
                ),
            ));
        }
        for (i, log) in axes.iter().enumerate() {
            let place = format!("experiment {j}, axis {i}");
            if log.excitation != Some(e) || log.period_s != first.period_s {
                return Err(bad(
                    place,
                    "it played another excitation or period than experiment 0's".into(),
                ));
            }
            if log.force_n.len() != first.force_n.len() || log.position_m.len() != log.force_n.len()
            {
                return Err(bad(
                    place,
                    format!(
                        "{} force and {} position samples, but experiment 0 has {}",
                        log.force_n.len(),
                        log.position_m.len(),
                        first.force_n.len()
                    ),
                ));
            }
            // (The lengths are checked above; a sample that is not a
            // number is named with its place, the rest as they are.)
            periods = whole_periods(&log.force_n, &log.position_m, period, harmonics, skip)
                .map_err(|err| match err {
                    IdentifyError::NotFinite { .. } => bad(place.clone(), err.to_string()),
                    other => other,
                })?;
            if i == j {
                crate::fit::measured::clipped(&log.force_n, log.period_s)
                    .map_err(|err| bad(place, err.to_string()))?;
            }
        }
    }
    Ok(periods)
}

/// Each axis's power per harmonic at the `quiet` harmonics (m²), the
/// most over the experiments: noise that repeats period after period.
fn repeating_noise(
    experiments: &[Vec<Log>],
    period: usize,
    quiet: &[usize],
    skip: usize,
) -> Vec<f64> {
    (0..experiments.len())
        .map(|i| {
            if quiet.is_empty() {
                return 0.0;
            }
            let per_experiment = experiments.iter().map(|axes| {
                crate::frf::mean_spectrum(&axes[i].position_m, period, quiet, skip)
                    .iter()
                    .map(|c| c.norm_sqr())
                    .sum::<f64>()
                    / quiet.len() as f64
            });
            per_experiment.fold(0.0, f64::max)
        })
        .collect()
}
