//! A linkage's joint losses, viscous and Coulomb, from the energy its
//! periodic motions dissipate.
//!
//! Over one period of a periodic motion the inertial, Coriolis and
//! gravity forces and the hold's spring do no net work: whatever the
//! motors put in, `∮ f · dx`, the joints dissipate. A joint with viscous
//! damping `b` and Coulomb friction `c` dissipates `b q'² + c |q'|` on
//! average, so each experiment gives one equation, linear in every
//! joint's `b` and `c`:
//!
//! `P = Σ_j b_j <q_j'²> + c_j <|q_j'|>`
//!
//! exact for any periodic orbit, whatever the mass matrix does over it.
//! Friction's share falls with the speed and damping's grows with it, so
//! the same sine played at several levels tells the two apart. The force
//! is the one the board commanded, held for a tick (zero-order hold), so
//! a tick's work is `f_n · (x_{n+1} - x_n)` exactly; it is summed in the
//! harmonics the motion has, where the reading's quantisation does not
//! reach.

use crate::frf::{mean_of, spectra, whole_periods};
use crate::log::Log;
use crate::IdentifyError;
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64;

/// How many harmonics of the excitation's highest one give the joints'
/// rates: the sine's harmonics that friction's corners add, and not the
/// quantisation's steps past them (which averaging does not remove: a
/// periodic motion crosses the same steps each period).
pub const RATE_HARMONICS: usize = 8;

/// A singular value of the (column-scaled) equations below this share of
/// the largest is a combination of the losses the experiments do not
/// resolve: the least-norm solution is taken along it, and its standard
/// deviation is the one this threshold gives.
const RESOLVED: f64 = 1e-2;

/// What one experiment dissipated and how fast each joint moved.
#[derive(Clone, Debug, PartialEq)]
pub struct Dissipation {
    /// The mean power the motors put in (W), summed in the harmonics the
    /// rates are taken in.
    pub power_w: f64,
    /// Its standard deviation from the periods' spread (W).
    pub power_sd_w: f64,
    /// Each joint's mean squared rate, `<q'²>` (rad²/s²).
    pub rate_sq: Vec<f64>,
    /// Each joint's mean absolute rate, `<|q'|>` (rad/s).
    pub rate_abs: Vec<f64>,
}

/// The joints' losses fitted to every experiment's [`Dissipation`].
#[derive(Clone, Debug, PartialEq)]
pub struct JointLosses {
    /// Each joint's viscous damping (N m s/rad).
    pub damping_nmsprad: Vec<f64>,
    /// Each joint's Coulomb friction (N m).
    pub friction_nm: Vec<f64>,
    /// Their standard deviations, damping then friction, from the
    /// residuals (a combination the experiments do not resolve gets a
    /// large one).
    pub sd: Vec<f64>,
    /// The residuals' rms as a share of each experiment's power.
    pub misfit: f64,
    /// How many combinations of the losses the experiments do not
    /// resolve (joints that every experiment moves alike).
    pub unresolved: usize,
    /// Each experiment's measurement.
    pub experiments: Vec<Dissipation>,
}

fn bad(place: String, why: String) -> IdentifyError {
    IdentifyError::Log { place, why }
}

/// The Jacobian `J = ∂x/∂q` (m/rad) where the handle is at a position
/// (m): the linkage's kinematics along the orbit, or one pose's for all
/// of it; `None` where no pose puts the handle there.
pub type JacobianAt<'a> = &'a (dyn Fn(&[f64]) -> Option<DMatrix<f64>> + Sync);

/// Experiment `place`'s dissipation: `axes` every axis's record (force the
/// board commanded, N; position, m), `jacobian_at` the Jacobian along the
/// orbit (joint rates from handle velocities, tick by tick), averaged over
/// whole periods after the first `skip`.
pub fn dissipation(
    axes: &[Log],
    jacobian_at: JacobianAt,
    skip: usize,
    place: &str,
) -> Result<Dissipation, IdentifyError> {
    let n = axes.len();
    let (period, harmonics, periods) = orbit(axes, skip, place)?;
    let t = axes[0].period_s;
    // A period's work, `Σ f_n (x_{n+1} - x_n)`, in its harmonics:
    // `(2/N) Σ_h Re(X_h (z_h - 1) conj(F_h))`, `z_h = e^{j2πh/N}`, over the
    // band the rates are taken in. Past it, the reading's quantisation
    // and the hold's damping on it would add a power of their own
    // (`b q²/12T²` for steps `q` that differ tick to tick), which the
    // joints never took. The estimate is the mean spectra's; the periods'
    // own give its spread.
    let cycle = |h: usize| {
        Complex64::from_polar(1.0, std::f64::consts::TAU * h as f64 / period as f64) - 1.0
    };
    let work = |x: &[Complex64], f: &[Complex64]| -> f64 {
        x.iter()
            .zip(f)
            .zip(&harmonics)
            .map(|((x, f), &h)| (x * cycle(h) * f.conj()).re)
            .sum::<f64>()
            * 2.0
            / period as f64
    };
    let spectra = |s: &[f64]| spectra(s, period, &harmonics, skip, periods);
    let mut per_period = vec![0.0; periods];
    let mut mean = 0.0;
    // Each axis's mean position spectrum, for the rates below.
    let mut positions = Vec::with_capacity(n);
    let mut centre = Vec::with_capacity(n);
    for l in axes {
        let (x, f) = (spectra(&l.position_m), spectra(&l.force_n));
        for (w, (x, f)) in per_period.iter_mut().zip(x.iter().zip(&f)) {
            *w += work(x, f);
        }
        let xm = mean_of(&x);
        mean += work(&xm, &mean_of(&f));
        positions.push(xm);
        let used = &l.position_m[skip * period..(skip + periods) * period];
        centre.push(used.iter().sum::<f64>() / used.len() as f64);
    }
    let avg = per_period.iter().sum::<f64>() / periods as f64;
    let var = per_period.iter().map(|w| (w - avg).powi(2)).sum::<f64>() / (periods as f64 - 1.0);
    let duration = period as f64 * t;
    pose_at(jacobian_at, &centre, place)?;
    let (rate_sq, rate_abs) = joint_rates(
        &positions,
        &centre,
        jacobian_at,
        &harmonics,
        period,
        duration,
    )
    .ok_or_else(|| {
        bad(
            place.into(),
            "the handle's orbit leaves the linkage's reach, or passes a singular pose".into(),
        )
    })?;
    Ok(Dissipation {
        power_w: mean / duration,
        power_sd_w: (var / periods as f64).sqrt() / duration,
        rate_sq,
        rate_abs,
    })
}

/// Experiment `place`'s periodic excitation, checked alike on every axis:
/// its period (ticks), the harmonics the losses are read in, and how
/// many whole periods past the first `skip` every axis recorded.
fn orbit(
    axes: &[Log],
    skip: usize,
    place: &str,
) -> Result<(usize, Vec<usize>, usize), IdentifyError> {
    if axes.is_empty() {
        return Err(bad(place.into(), "no axis recorded".into()));
    }
    let e = axes[0].excitation.ok_or_else(|| {
        bad(
            format!("{place}, axis 0"),
            "it does not name its excitation (the `# twoport experiment:` line)".into(),
        )
    })?;
    let (period, first, last) = e.periodic().ok_or_else(|| {
        bad(
            format!("{place}, axis 0"),
            "a stepped sine: the losses are read from a sine repeated every period".into(),
        )
    })?;
    let max = period.saturating_sub(1) / 2;
    let top = last.saturating_mul(RATE_HARMONICS).min(max);
    if first == 0 || last > max {
        return Err(IdentifyError::Harmonic {
            harmonic: last.max(first),
            period,
            max,
        });
    }
    let harmonics: Vec<usize> = (1..=top).collect();
    let t = axes[0].period_s;
    let mut periods = usize::MAX;
    for (i, log) in axes.iter().enumerate() {
        let at = format!("{place}, axis {i}");
        if log.excitation != Some(e)
            || log.period_s != t
            || log.force_n.len() != axes[0].force_n.len()
        {
            return Err(bad(
                at,
                "it played another excitation, period or length than axis 0's".into(),
            ));
        }
        let p = whole_periods(&log.force_n, &log.position_m, period, &harmonics, skip)
            .map_err(|err| bad(at, err.to_string()))?;
        periods = periods.min(p);
    }
    if periods < 2 {
        return Err(bad(place.into(), "fewer than two whole periods".into()));
    }
    Ok((period, harmonics, periods))
}

/// That the linkage has a pose, with as many joints as `centre` has
/// axes, that puts the handle at `centre` (m).
fn pose_at(jacobian_at: JacobianAt, centre: &[f64], place: &str) -> Result<(), IdentifyError> {
    let n = centre.len();
    match jacobian_at(centre) {
        Some(j) if j.nrows() == n && j.ncols() == n => Ok(()),
        Some(j) => Err(bad(
            place.into(),
            format!("{n} axes recorded, but the pose has {} joints", j.ncols()),
        )),
        None => Err(bad(
            place.into(),
            "no pose of the linkage puts the handle where the records centre".into(),
        )),
    }
}

/// The joints' mean square and mean absolute rates (rad²/s², rad/s) over
/// the mean period whose Cartesian position spectra (at `harmonics` of a
/// `period`-tick period lasting `duration` s) are `positions` about
/// `centre` (m): the velocity band-limited to the harmonics, at every
/// tick, taken to the joints by the Jacobian where the handle is then. A
/// handle that swings a centimetre (a light arm on a weak hold) turns its
/// joints by what the pose's own Jacobian would not say: on the PHANToM
/// at 1.5 N, 12% of the base joint's losses. `None` where the orbit
/// leaves the kinematics.
fn joint_rates(
    positions: &[Vec<Complex64>],
    centre: &[f64],
    jacobian_at: JacobianAt,
    harmonics: &[usize],
    period: usize,
    duration: f64,
) -> Option<(Vec<f64>, Vec<f64>)> {
    let n = positions.len();
    // x = (2/N) Re(c e^{jφ}); x' = (2/N) Re(jω c e^{jφ}).
    let at = |c: &[Complex64], s: usize, rate: bool| -> f64 {
        c.iter()
            .zip(harmonics)
            .map(|(c, &h)| {
                let w = std::f64::consts::TAU * h as f64 / duration;
                let ph = std::f64::consts::TAU * (h * s) as f64 / period as f64;
                let (sin, cos) = ph.sin_cos();
                if rate {
                    -2.0 * w / period as f64 * (c.re * sin + c.im * cos)
                } else {
                    2.0 / period as f64 * (c.re * cos - c.im * sin)
                }
            })
            .sum()
    };
    let mut rate_sq = vec![0.0; n];
    let mut rate_abs = vec![0.0; n];
    for s in 0..period {
        let x: Vec<f64> = (0..n)
            .map(|i| centre[i] + at(&positions[i], s, false))
            .collect();
        let v = DVector::from_fn(n, |i, _| at(&positions[i], s, true));
        let q = jacobian_at(&x)?.lu().solve(&v)?;
        for ((sq, abs), r) in rate_sq.iter_mut().zip(&mut rate_abs).zip(q.iter()) {
            *sq += r * r / period as f64;
            *abs += r.abs() / period as f64;
        }
    }
    Some((rate_sq, rate_abs))
}

/// Fit every joint's damping and friction to the experiments (each one
/// every axis's record), the joints' rates taken from the handle's by
/// `jacobian_at` along each orbit. Each experiment's equation is
/// weighted by its power (the rates' band-limiting errs by a share of
/// it), the least-norm solution taken where the experiments do not tell
/// joints apart, and no loss is negative.
pub fn fit(
    experiments: &[Vec<Log>],
    jacobian_at: JacobianAt,
    skip: usize,
) -> Result<JointLosses, IdentifyError> {
    let n = experiments.first().map_or(0, Vec::len);
    if let Some(k) = experiments.iter().position(|axes| axes.len() != n) {
        return Err(bad(
            format!("experiment {k}"),
            format!(
                "{} axes recorded, but experiment 0 has {n}",
                experiments[k].len()
            ),
        ));
    }
    let dis = experiments
        .iter()
        .enumerate()
        .map(|(k, axes)| dissipation(axes, jacobian_at, skip, &format!("experiment {k}")))
        .collect::<Result<Vec<_>, _>>()?;
    if let Some(k) = dis
        .iter()
        .position(|d| d.power_w.is_nan() || d.power_w <= 0.0)
    {
        return Err(bad(
            format!("experiment {k}"),
            format!(
                "the motors put in {} W over a period: a passive device takes power in",
                dis[k].power_w
            ),
        ));
    }
    if dis.len() < 2 {
        return Err(bad(
            "the records".into(),
            "one experiment cannot tell damping from friction: play the sine at two levels or more"
                .into(),
        ));
    }
    let rows = DMatrix::from_fn(dis.len(), 2 * n, |r, c| {
        let d = &dis[r];
        (if c < n {
            d.rate_sq[c]
        } else {
            d.rate_abs[c - n]
        }) / d.power_w
    });
    let rhs = DVector::from_element(dis.len(), 1.0);
    // The standard deviations are the unconstrained fit's: a loss held
    // at zero is not known to be zero.
    let mut free: Vec<usize> = (0..2 * n).collect();
    let (mut p, sd, unresolved) = solve(&rows, &rhs, &free);
    while let Some(c) = free
        .iter()
        .copied()
        .filter(|&c| p[c] < 0.0)
        .min_by(|&a, &b| p[a].total_cmp(&p[b]))
    {
        free.retain(|&f| f != c);
        p = solve(&rows, &rhs, &free).0;
    }
    let res = &rows * &p - &rhs;
    Ok(JointLosses {
        damping_nmsprad: p.rows(0, n).iter().copied().collect(),
        friction_nm: p.rows(n, n).iter().copied().collect(),
        sd,
        misfit: (res.norm_squared() / dis.len() as f64).sqrt(),
        unresolved,
        experiments: dis,
    })
}

/// The least-norm least squares over the columns `free` (the others
/// zero): the parameters, their standard deviations (every column's) and
/// how many combinations it did not resolve.
fn solve(
    rows: &DMatrix<f64>,
    rhs: &DVector<f64>,
    free: &[usize],
) -> (DVector<f64>, Vec<f64>, usize) {
    let m = rows.nrows();
    let scale: Vec<f64> = free
        .iter()
        .map(|&c| rows.column(c).norm().max(f64::MIN_POSITIVE))
        .collect();
    let a = DMatrix::from_fn(m, free.len(), |r, k| rows[(r, free[k])] / scale[k]);
    let svd = a.clone().svd(true, true);
    let top = svd.singular_values.max();
    let cut = RESOLVED * top;
    let x = svd
        .solve(rhs, cut)
        .unwrap_or_else(|_| DVector::zeros(free.len()));
    let res = &a * &x - rhs;
    let resolved = svd.singular_values.iter().filter(|&&s| s > cut).count();
    let unresolved = free.len() - resolved;
    // The residuals' variance, at least the share the rates' errors give
    // (0.5% a row): a fit that happens to close exactly is not exact.
    let dof = m.saturating_sub(resolved).max(1) as f64;
    let s2 = (res.norm_squared() / dof).max(0.005f64.powi(2));
    // Every direction's variance, the null space's too (fewer
    // experiments than losses): the eigenvectors of `AᵀA`, each eigenvalue
    // at least the threshold's square.
    let ata = a.transpose() * &a;
    let eig = ata.symmetric_eigen();
    let mut p = DVector::zeros(rows.ncols());
    let mut sd = vec![0.0; rows.ncols()];
    for (k, &c) in free.iter().enumerate() {
        p[c] = x[k] / scale[k];
        let var: f64 = eig
            .eigenvalues
            .iter()
            .enumerate()
            .map(|(i, &l)| eig.eigenvectors[(k, i)].powi(2) / l.max(cut * cut))
            .sum();
        sd[c] = (s2 * var).sqrt() / scale[k];
    }
    (p, sd, unresolved)
}

impl JointLosses {
    /// The damping the handle feels at a pose, `J^-T B J^-1` (N s/m), `B`
    /// the joints' damping less `sigmas` standard deviations (none below
    /// zero): `sigmas = 0` the fit's, larger the least the data allow
    /// (the damping matrix only grows with each joint's).
    pub fn damping_nspm(&self, jacobian: &DMatrix<f64>, sigmas: f64) -> Option<DMatrix<f64>> {
        let inv = jacobian.clone().try_inverse()?;
        let b = DVector::from_iterator(
            self.damping_nmsprad.len(),
            self.damping_nmsprad
                .iter()
                .zip(&self.sd)
                .map(|(b, s)| (b - sigmas * s).max(0.0)),
        );
        let d = inv.transpose() * DMatrix::from_diagonal(&b) * &inv;
        Some((&d + d.transpose()) * 0.5)
    }
}

// (The body the tests simulate is the CLI tests' too.)
#[cfg(test)]
#[path = "../../../../tests/support/sine_body.rs"]
mod sine_body;

#[cfg(test)]
mod tests {
    use super::*;

    use super::sine_body as support;

    /// [`support::sine_log`] read in 1 µm steps.
    fn sine(mass: f64, b: f64, c: f64, peak: f64) -> Log {
        support::sine_log(mass, b, c, 1e-6, peak)
    }

    /// One pose's Jacobian, wherever the handle is.
    fn fixed(j: &DMatrix<f64>) -> impl Fn(&[f64]) -> Option<DMatrix<f64>> + Sync + '_ {
        move |_| Some(j.clone())
    }

    fn one_axis(levels: &[f64], b: f64, c: f64) -> Vec<Vec<Log>> {
        levels.iter().map(|&p| vec![sine(0.1, b, c, p)]).collect()
    }

    #[test]
    fn damping_and_friction_come_apart_over_the_levels() {
        let j = DMatrix::from_element(1, 1, 1.0);
        let l = fit(&one_axis(&[0.5, 1.0, 2.0], 0.5, 0.1), &fixed(&j), 4).unwrap();
        let (b, c) = (l.damping_nmsprad[0], l.friction_nm[0]);
        assert!((b / 0.5 - 1.0).abs() < 0.03, "{l:?}");
        assert!((c / 0.1 - 1.0).abs() < 0.03, "{l:?}");
        assert!(l.misfit < 0.01 && l.unresolved == 0, "{l:?}");
        // Within a few standard deviations, and they are not nothing.
        assert!((b - 0.5).abs() < 4.0 * l.sd[0] && l.sd[0] > 0.0, "{l:?}");
    }

    #[test]
    fn a_frictionless_body_gets_none() {
        let j = DMatrix::from_element(1, 1, 1.0);
        let l = fit(&one_axis(&[0.5, 1.0, 2.0], 0.5, 0.0), &fixed(&j), 4).unwrap();
        assert!((l.damping_nmsprad[0] / 0.5 - 1.0).abs() < 0.03, "{l:?}");
        assert!(l.friction_nm[0] < 2.0 * l.sd[1], "{l:?}");
    }

    #[test]
    fn a_joint_no_experiment_moves_is_not_credited() {
        // Two axes, the second never moved nor pushed.
        let still = |l: &Log| Log {
            force_n: vec![0.0; l.force_n.len()],
            position_m: vec![0.0; l.position_m.len()],
            ..l.clone()
        };
        let e: Vec<Vec<Log>> = [0.5, 1.0, 2.0]
            .iter()
            .map(|&p| {
                let l = sine(0.1, 0.5, 0.1, p);
                vec![still(&l), l].into_iter().rev().collect()
            })
            .collect();
        let j = DMatrix::identity(2, 2);
        let l = fit(&e, &fixed(&j), 4).unwrap();
        assert_eq!(l.unresolved, 2, "{l:?}");
        assert!((l.damping_nmsprad[0] / 0.5 - 1.0).abs() < 0.03, "{l:?}");
        // Its deviation is the threshold's, many times the moved joint's,
        // and the least damping the data allow gives it none.
        assert!(l.sd[1] > 10.0 * l.sd[0], "{l:?}");
        let least = l.damping_nspm(&j, 3.0).unwrap();
        assert_eq!(least[(1, 1)], 0.0);
        assert!(least[(0, 0)] > 0.4, "{least}");
    }

    #[test]
    fn the_handle_feels_the_joints_damping_through_the_jacobian() {
        let l = JointLosses {
            damping_nmsprad: vec![2.0, 0.5],
            friction_nm: vec![0.0, 0.0],
            sd: vec![0.1, 1.0, 0.0, 0.0],
            misfit: 0.0,
            unresolved: 0,
            experiments: Vec::new(),
        };
        // x = (q0 + q1, 2 q1): J = [[1, 1], [0, 2]].
        let j = DMatrix::from_row_slice(2, 2, &[1.0, 1.0, 0.0, 2.0]);
        let d = l.damping_nspm(&j, 0.0).unwrap();
        // The power at joint rates q' is q'ᵀ B q' = x'ᵀ D x'.
        let q = DVector::from_vec(vec![0.3, -0.7]);
        let x = &j * &q;
        let joint = 2.0 * 0.09 + 0.5 * 0.49;
        assert!(((x.transpose() * &d * &x)[0] - joint).abs() < 1e-12);
        // Three deviations down: joint 0 at 1.7, joint 1 at none.
        let least = l.damping_nspm(&j, 3.0).unwrap();
        let joint = 1.7 * 0.09;
        assert!(((x.transpose() * &least * &x)[0] - joint).abs() < 1e-12);
    }

    #[test]
    fn records_that_cannot_be_fitted_are_refused() {
        let j = DMatrix::from_element(1, 1, 1.0);
        let why = |e: IdentifyError| e.to_string();
        // One level: damping and friction are not told apart.
        let err = why(fit(&one_axis(&[1.0], 0.5, 0.1), &fixed(&j), 4).unwrap_err());
        assert!(err.contains("two levels"), "{err}");
        // A record the motors took power from.
        let mut e = one_axis(&[0.5, 1.0], 0.5, 0.1);
        e[1][0].force_n.iter_mut().for_each(|f| *f = -*f);
        let err = why(fit(&e, &fixed(&j), 4).unwrap_err());
        assert!(
            err.contains("experiment 1") && err.contains("passive"),
            "{err}"
        );
        // A sample that is not a number, named with its place.
        let mut e = one_axis(&[0.5, 1.0], 0.5, 0.1);
        e[0][0].position_m[1000] = f64::NAN;
        let err = why(fit(&e, &fixed(&j), 4).unwrap_err());
        assert!(err.contains("experiment 0, axis 0"), "{err}");
        // Too few periods with their end recorded.
        let err = why(fit(&one_axis(&[0.5, 1.0], 0.5, 0.1), &fixed(&j), 23).unwrap_err());
        assert!(err.contains("periods"), "{err}");
        // A record with another count of axes than the pose's joints.
        let j2 = DMatrix::identity(2, 2);
        let err = why(fit(&one_axis(&[0.5, 1.0], 0.5, 0.1), &fixed(&j2), 4).unwrap_err());
        assert!(err.contains("1 axes"), "{err}");
    }
}
