//! What an experiment measured ([`Measured`]): the responses at the
//! played harmonics, the forces its motion adds, and a loaded record's
//! beside them; and the checks a record must pass first.

use super::{cogging, friction};
use crate::frf::Frf;

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
    pub motion: Option<cogging::MeanMotion>,
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

/// The least top of a record's band a fit is made from, as a share of
/// the sampling rate: a fifth (two fifths of Nyquist).
pub const LEAST_BAND_SHARE: f64 = 0.2;

impl Measured {
    /// Whether the played band reaches [`LEAST_BAND_SHARE`] of the
    /// sampling rate (`1/period_s`): what a design is made from must show
    /// the device where a coupling's proof binds, and a mode above the
    /// band is not in the record. A record stopped short of a mode but
    /// past this (the Excalibur to 200 Hz at 1 kHz) is fitted, its misfit
    /// widening its set.
    pub fn band_reaches(&self, period_s: f64) -> Result<(), crate::IdentifyError> {
        let top_hz = self.position.freq_hz.last().copied().unwrap_or(0.0);
        let needed_hz = LEAST_BAND_SHARE / period_s;
        // (A hundredth of a harmonic's rounding is not short.)
        if top_hz < needed_hz * (1.0 - 1e-9) {
            return Err(crate::IdentifyError::NarrowBand { top_hz, needed_hz });
        }
        Ok(())
    }

    /// The responses an experiment's record shows at the harmonics it
    /// played, averaged over its whole periods after the first `skip` (the
    /// transient). Refused, with the reason: a record that does not name
    /// its excitation, or one [`frf::periodic`](crate::frf::periodic)
    /// refuses.
    pub fn from_log(log: &crate::log::Log, skip: usize) -> Result<Measured, crate::IdentifyError> {
        let e = log.excitation.ok_or(crate::IdentifyError::Log {
            place: "the record".into(),
            why: "it does not name its excitation (the `# twoport experiment:` line, or `identify --excitation`)".into(),
        })?;
        clipped(&log.force_n, log.period_s)?;
        match e {
            crate::log::Excitation::Periodic {
                period_ticks,
                first,
                last,
            } => Self::periodic(log, skip, period_ticks, first, last),
            crate::log::Excitation::Stepped { step_ticks } => Self::stepped(log, skip, step_ticks),
        }
    }

    /// A stepped sine's responses ([`stepped`](crate::stepped)), `skip`
    /// whole steps first left out. Friction under a sine is, to first
    /// order, damping, and cogging's shapes need a motion that repeats:
    /// neither is estimated beside the model. A quantised reading's error
    /// repeats each cycle, so a cycle's samples bound its variance.
    fn stepped(
        log: &crate::log::Log,
        skip: usize,
        step_ticks: usize,
    ) -> Result<Measured, crate::IdentifyError> {
        let mut signals: Vec<&[f64]> = vec![&log.position_m];
        signals.extend(log.load_cell_n.as_deref());
        let steps =
            crate::stepped::stepped(&log.force_n, &signals, log.period_s, step_ticks, skip)?;
        let mut quanta: Vec<Option<f64>> = signals.iter().map(|s| quantum(s)).collect();
        let mut frfs = steps.responses;
        for (f, q) in frfs.iter_mut().zip(&quanta) {
            // A quantised reading's error repeats each cycle, so it does
            // not average over a step: its share of a cycle's amplitude,
            // `q²/(3 N)` for `N` samples a cycle, over the force's.
            if let Some(q) = q {
                for (i, v) in f.variance.iter_mut().enumerate() {
                    let a = steps.force_n[i];
                    *v += q * q / (3.0 * steps.cycle_ticks[i] * (a * a).max(f64::MIN_POSITIVE));
                }
            }
        }
        let load_cell = (frfs.len() > 1).then(|| frfs.remove(1));
        let position = frfs.remove(0);
        let encoder = quanta.swap_remove(0);
        passive(&position, log.period_s)?;
        Ok(Measured {
            position,
            load_cell,
            forces: Vec::new(),
            encoder_quantum_m: encoder,
            motion: None,
            loaded: None,
        })
    }

    /// A periodic record's responses at its harmonics `first..=last`.
    fn periodic(
        log: &crate::log::Log,
        skip: usize,
        period_ticks: usize,
        first: usize,
        last: usize,
    ) -> Result<Measured, crate::IdentifyError> {
        let harmonics: Vec<usize> = (first..=last).collect();
        let at = |signal: &[f64]| {
            crate::frf::periodic(
                &log.force_n,
                signal,
                log.period_s,
                period_ticks,
                &harmonics,
                skip,
            )
        };
        let spectrum = |x: &[f64]| crate::frf::mean_spectrum(x, period_ticks, &harmonics, skip);
        let force = spectrum(&log.force_n);
        // A quantised reading's error repeats with the motion, period after
        // period, so no averaging removes it: its share of each harmonic,
        // `N q²/12` (`q` the least step the record shows), is a floor on
        // that harmonic's variance. Where the response is far below a
        // count, the harmonic then counts for what it is worth.
        let floored = |mut f: Frf, signal: &[f64]| {
            let q = quantum(signal);
            if let Some(q) = q {
                let floor = period_ticks as f64 * q * q / 12.0;
                for (v, fm) in f.variance.iter_mut().zip(&force) {
                    *v += floor / fm.norm_sqr().max(f64::MIN_POSITIVE);
                }
            }
            (f, q)
        };
        let (position, encoder) = floored(at(&log.position_m)?, &log.position_m);
        passive(&position, log.period_s)?;
        let load_cell = match log.load_cell_n.as_deref() {
            Some(lc) => Some(floored(at(lc)?, lc).0),
            None => None,
        };
        let sign = friction::tick_sign(&log.position_m, period_ticks, last, skip);
        let mut forces: Vec<friction::Regressor> = sign
            .map(|sign| friction::Regressor {
                shape: friction::Shape::Coulomb,
                per_force: crate::frf::mean_spectrum(&sign, period_ticks, &harmonics, 0)
                    .iter()
                    .zip(&force)
                    .map(|(s, f)| s / f)
                    .collect(),
                taken_n: 0.0,
            })
            .into_iter()
            .collect();
        let motion =
            cogging::MeanMotion::new(&log.position_m, period_ticks, &harmonics, force, skip);
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
            let below = super::body_band_hz(&data.position, log.period_s);
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
pub(crate) fn clipped(force_n: &[f64], period_s: f64) -> Result<(), crate::IdentifyError> {
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

/// Refuse a response that gives out power. The actuator's force and its
/// encoder meet at one point, so the device's mobility there, `Y = jω H`,
/// is positive real: `Re Y >= 0` at every frequency, for any passive
/// device (free, on springs to ground, with any modes). With the sign of
/// the force or of the encoder turned, `Re Y <= 0`. The sampled response
/// lags the continuous one by the hold's half sample (exactly so for a
/// rigid body), which is put back; only harmonics below a fifth of Nyquist
/// are weighed, where what is left of the hold is small. The evidence is
/// each harmonic's `Re Y` over its standard deviation, summed; the sign is
/// named reversed only when that sum is 8 standard deviations below zero
/// and the weighted mean of `Re Y/|Y|` below -0.02, so that noise, or a
/// device with next to no damping, is never taken for it.
pub(crate) fn passive(h: &Frf, period_s: f64) -> Result<(), crate::IdentifyError> {
    let nyquist = 0.5 / period_s;
    let (mut z, mut n, mut negative, mut share, mut weight) = (0.0, 0usize, 0usize, 0.0, 0.0);
    for ((f, r), v) in h.freq_hz.iter().zip(&h.response).zip(&h.variance) {
        if *f <= 0.0 || *f > 0.2 * nyquist {
            continue;
        }
        let w = 2.0 * std::f64::consts::PI * f;
        let advance = num_complex::Complex64::from_polar(1.0, 0.5 * w * period_s);
        let y = num_complex::Complex64::new(0.0, w) * r * advance;
        let sd = w * v.sqrt();
        if !(sd > 0.0 && y.norm() > 0.0) {
            continue;
        }
        z += y.re / sd;
        n += 1;
        negative += usize::from(y.re < 0.0);
        // Weighted by how well each harmonic is known.
        let snr = y.norm() / sd;
        share += snr * y.re / y.norm();
        weight += snr;
    }
    if n == 0 || weight == 0.0 {
        return Ok(());
    }
    let (sigmas, share) = (z / (n as f64).sqrt(), share / weight);
    if sigmas < -8.0 && share < -0.02 {
        return Err(crate::IdentifyError::ReversedSign {
            negative,
            harmonics: n,
            share: -share,
            sigmas: -sigmas,
        });
    }
    Ok(())
}

/// The least step between the values a quantised signal took, if it
/// took two.
pub(crate) fn quantum(signal: &[f64]) -> Option<f64> {
    let mut levels = signal.to_vec();
    levels.sort_by(f64::total_cmp);
    levels.dedup();
    let q = levels
        .windows(2)
        .map(|w| w[1] - w[0])
        .fold(f64::INFINITY, f64::min);
    q.is_finite().then_some(q)
}
