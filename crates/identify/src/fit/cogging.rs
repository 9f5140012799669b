//! Cogging: the motor's pull toward its detents, `a sin(2π x/p) + b
//! cos(2π x/p)` at the actuator's position `x`, repeating every `p` of
//! travel.
//!
//! It is conservative, but under a periodic push it is periodic too, so
//! averaging keeps it, and left in it corrupts the friction's estimate
//! (friction not found is read as damping): on a 0.25 kg handle, 0.01 N of
//! cogging beside 0.05 N of friction brought the friction back as 0.01 N
//! and the design 10% too stiff. Its shape is known once its period is:
//! the record's own motion gives `sin` and `cos` of `2π x/p` over the mean
//! period ([`shapes`]). The period is searched ([`find`]): the one whose
//! shapes best explain the lowest harmonics with the rigid body and the
//! friction, kept only if they explain more than a search over that many
//! periods would find in noise.

use super::friction::{band_limited, Regressor, RigidRows, Shape, SUB};
use super::Measured;
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64;
use std::f64::consts::TAU;

/// Cogging as a fit found it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Found {
    /// Its amplitude (N).
    pub amplitude_n: f64,
    /// Its period along the actuator's travel (m).
    pub period_m: f64,
}

/// The record's mean motion: what cogging's shapes are computed from.
#[derive(Clone, Debug, PartialEq)]
pub struct MeanMotion {
    /// The mean period's position, band-limited to the played harmonics
    /// with its mean, at eight instants across each tick (m).
    pub at: Vec<Vec<f64>>,
    /// The force's mean spectrum at the played harmonics.
    pub force: Vec<Complex64>,
    /// The played harmonics.
    pub harmonics: Vec<usize>,
}

impl MeanMotion {
    /// The motion of `position_m` under `force` (its mean spectrum at
    /// `harmonics`), `None` where the record has no whole period to average.
    pub fn new(
        position_m: &[f64],
        period: usize,
        harmonics: &[usize],
        force: Vec<Complex64>,
        skip: usize,
    ) -> Option<MeanMotion> {
        let top = *harmonics.last()?;
        Some(MeanMotion {
            at: band_limited(position_m, period, top, skip, false)?,
            force,
            harmonics: harmonics.to_vec(),
        })
    }

    /// The travel the mean period spans (m).
    pub fn span_m(&self) -> f64 {
        let (lo, hi) = self
            .at
            .iter()
            .flatten()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
                (lo.min(*x), hi.max(*x))
            });
        hi - lo
    }
}

/// Cogging's two shapes at a period of `period_m`, per unit force.
pub fn shapes(motion: &MeanMotion, period_m: f64) -> [Regressor; 2] {
    let (sin, cos) = Sweep::new(motion, 1.0 / period_m, 0.0).next();
    [
        Regressor {
            shape: Shape::CoggingSin { period_m },
            per_force: sin,
            taken_n: 0.0,
        },
        Regressor {
            shape: Shape::CoggingCos { period_m },
            per_force: cos,
            taken_n: 0.0,
        },
    ]
}

/// Periods searched per span of travel `s`: from `2 s` (half a period
/// across the motion) to `s/100`, in steps of wavenumber small enough that the
/// phase across the motion moves by a twentieth of a turn.
const STEP: f64 = 0.05;
/// Terms past the rigid body's the search gives the impedance (as
/// [`rigid_with`](super::friction::rigid_with)'s `bend`).
const BEND: usize = 3;
/// The shortest period tried, in encoder quanta.
const QUANTA: f64 = 10.0;

/// The lowest harmonics' fit as one body with `data`'s forces and the
/// smooth terms, ready to take two more columns: the weighted base
/// columns' orthonormal basis, what they leave of the data, and each
/// harmonic's `F/X` times its weight (what a shape per force is turned
/// into a column by).
struct Band {
    q: DMatrix<f64>,
    left: DVector<f64>,
    scale: Vec<Complex64>,
    used: usize,
}

impl Band {
    fn new(data: &Measured, period_s: f64, below_hz: f64) -> Option<Band> {
        // Room for the two columns to come, and two spare equations.
        let rows = RigidRows::new(data, &[], BEND, period_s, below_hz, 4)?;
        let q = rows.a.qr().q();
        let left = &rows.b - &q * (q.transpose() * &rows.b);
        Some(Band {
            q,
            left,
            scale: rows.scale,
            used: rows.used,
        })
    }

    /// The misfit with no more columns.
    fn bare(&self) -> f64 {
        self.left.norm_squared()
    }

    /// The misfit with two more shapes (per force, at the harmonics).
    fn with(&self, s: &[Complex64], c: &[Complex64]) -> f64 {
        let mut x = DMatrix::zeros(2 * self.used, 2);
        for i in 0..self.used {
            for (j, shape) in [s, c].iter().enumerate() {
                let v = shape[i] * self.scale[i];
                x[(2 * i, j)] = v.re;
                x[(2 * i + 1, j)] = v.im;
            }
        }
        // What the base columns leave of the new ones, and the least
        // squares in those two alone (Frisch-Waugh).
        let x = &x - &self.q * (self.q.transpose() * &x);
        let g = x.transpose() * &x;
        let r = x.transpose() * &self.left;
        match g.cholesky() {
            Some(ch) => self.bare() - r.dot(&ch.solve(&r)),
            None => self.bare(),
        }
    }
}

/// Cogging's two shapes per force at wavenumbers `from + i step`, in
/// turn, from the motion's phasors: each step turns every instant's
/// phasor `e^{j k x}` by `e^{j step x}`, and one FFT of their tick means
/// gives the sine's and the cosine's spectra.
struct Sweep<'a> {
    motion: &'a MeanMotion,
    z: Vec<Vec<Complex64>>,
    turn: Vec<Vec<Complex64>>,
    fft: std::sync::Arc<dyn rustfft::Fft<f64>>,
}

impl<'a> Sweep<'a> {
    fn new(motion: &'a MeanMotion, from: f64, step: f64) -> Sweep<'a> {
        let phasors = |k: f64| -> Vec<Vec<Complex64>> {
            motion
                .at
                .iter()
                .map(|at| {
                    at.iter()
                        .map(|x| Complex64::from_polar(1.0, TAU * k * x))
                        .collect()
                })
                .collect()
        };
        let period = motion.at.first().map_or(0, Vec::len);
        Sweep {
            motion,
            z: phasors(from),
            turn: phasors(step),
            fft: rustfft::FftPlanner::new().plan_fft_forward(period),
        }
    }

    /// The current wavenumber's (sine, cosine) per force; then step on.
    fn next(&mut self) -> (Vec<Complex64>, Vec<Complex64>) {
        let period = self.z.first().map_or(0, Vec::len);
        let mut buf: Vec<Complex64> = (0..period)
            .map(|n| self.z.iter().map(|z| z[n]).sum::<Complex64>() / SUB as f64)
            .collect();
        for (z, t) in self.z.iter_mut().zip(&self.turn) {
            for (a, b) in z.iter_mut().zip(t) {
                *a *= b;
            }
        }
        self.fft.process(&mut buf);
        let j = Complex64::new(0.0, 1.0);
        let mut sin = Vec::with_capacity(self.motion.harmonics.len());
        let mut cos = Vec::with_capacity(self.motion.harmonics.len());
        for (&h, f) in self.motion.harmonics.iter().zip(&self.motion.force) {
            // The tick means' real part is the cosine, the imaginary the
            // sine: split the one FFT into the two real signals' spectra.
            let (a, b) = (buf[h], buf[period - h].conj());
            cos.push((a + b) / 2.0 / f);
            sin.push((a - b) / (2.0 * j) / f);
        }
        (sin, cos)
    }
}

/// The cogging the lowest harmonics of `data` (below `below_hz`, where
/// the device moves as one body) show beside its other forces, if any:
/// its two shapes at the period that explains them best, or `None` where
/// no period explains more than the search would find in noise.
pub fn find(
    data: &Measured,
    motion: &MeanMotion,
    period_s: f64,
    below_hz: f64,
) -> Option<[Regressor; 2]> {
    let span = motion.span_m();
    let q = data.encoder_quantum_m.unwrap_or(0.0);
    if span.is_nan() || span <= 0.0 {
        return None;
    }
    let band = Band::new(data, period_s, below_hz)?;
    let bare = band.bare();
    let longest = 2.0 * span;
    let shortest = (span / 100.0).max(QUANTA * q);
    if shortest >= longest {
        return None;
    }
    let (from, to, step) = (1.0 / longest, 1.0 / shortest, STEP / span);
    let tries = ((to - from) / step).ceil() as usize;
    let mut sweep = Sweep::new(motion, from, step);
    let (mut best, at) = (0..=tries)
        .map(|i| {
            let (s, c) = sweep.next();
            (band.with(&s, &c), from + i as f64 * step)
        })
        .min_by(|a, b| a.0.total_cmp(&b.0))?;
    // Then within a step either side, by golden sections.
    let cost = |wavenumber: f64| {
        let [s, c] = shapes(motion, 1.0 / wavenumber);
        band.with(&s.per_force, &c.per_force)
    };
    let (mut lo, mut hi) = (at - step, at + step);
    let r = (5f64.sqrt() - 1.0) / 2.0;
    let (mut a, mut b) = (hi - r * (hi - lo), lo + r * (hi - lo));
    let (mut ca, mut cb) = (cost(a), cost(b));
    for _ in 0..24 {
        if ca < cb {
            (hi, b, cb) = (b, a, ca);
            a = hi - r * (hi - lo);
            ca = cost(a);
        } else {
            (lo, a, ca) = (a, b, cb);
            b = lo + r * (hi - lo);
            cb = cost(b);
        }
    }
    let (refined, k) = if ca < cb { (ca, a) } else { (cb, b) };
    let period = if refined <= best { 1.0 / k } else { 1.0 / at };
    best = best.min(refined);
    // The criterion: two amounts, and the best of `tries` periods, in
    // units of the misfit left per degree of freedom with the cogging,
    // where that is more than the noise's (the band is not quite rigid,
    // and the cogging could be taking up the model's error).
    let used = band.used;
    let nu = (2 * used)
        .saturating_sub(4 + BEND + data.forces.len())
        .max(1) as f64;
    let charge =
        (2.0 * ((2 * used) as f64).ln() + 2.0 * (tries.max(1) as f64).ln()) * (best / nu).max(1.0);
    (bare - best > charge).then(|| shapes(motion, period))
}

#[cfg(test)]
mod tests {
    use super::super::friction::tests::Bench;
    use super::super::friction::{rigid_with, without};
    use super::*;

    /// A 0.25 kg handle with 2 N s/m of damping, 0.05 N of Coulomb
    /// friction and `cogging_n` of cogging every 2 mm, pushed by an 8 N
    /// multisine from 1 to 100 Hz.
    fn record(cogging_n: f64) -> crate::log::Log {
        Bench {
            m: 0.25,
            d: 2.0,
            fc: 0.05,
            cogging: cogging_n,
            top: 100,
            peak: 8.0,
            hold: (300.0, 10.0),
        }
        .record()
    }

    /// Cogging is found near its period and at its amplitude, and with it
    /// the friction and the mass; a record without cogging shows none.
    #[test]
    fn cogging_is_found_at_its_period() {
        let data = Measured::from_log(&record(0.01), 4).unwrap();
        let shapes: Vec<_> = data.forces.iter().map(|f| f.shape).collect();
        let Some(Shape::CoggingSin { period_m }) = shapes.get(1).copied() else {
            panic!("no cogging: {shapes:?}");
        };
        // (Near the period the misfit is at the noise's over a few
        // percent: the motion spans some ten periods.)
        assert!((period_m / 2e-3 - 1.0).abs() < 0.05, "{period_m} m");
        let (mass, _, amounts, _) = rigid_with(&data, &[], 0, 1e-3, 25.0).unwrap();
        let amplitude = amounts[1].hypot(amounts[2]);
        assert!((amplitude / 0.01 - 1.0).abs() < 0.1, "{amplitude} N");
        assert!((amounts[0] / 0.05 - 1.0).abs() < 0.1, "{} N", amounts[0]);
        assert!((mass / 0.25 - 1.0).abs() < 0.01, "{mass} kg");
        // Taken out, the shapes are left with nothing to explain.
        let clean = without(&data, &amounts);
        let again = rigid_with(&clean, &[], 0, 1e-3, 25.0).unwrap().2;
        assert!(again.iter().all(|c| c.abs() < 1e-3), "{again:?}");

        let plain = Measured::from_log(&record(0.0), 4).unwrap();
        assert_eq!(
            plain.forces.len(),
            1,
            "{:?}",
            plain.forces.iter().map(|f| f.shape).collect::<Vec<_>>()
        );
    }
}
