//! The frequency response of a stepped sine: one frequency held for each
//! step of a record, the steps in any order.
//!
//! Each step's first quarter is its transient and is dropped. The rest is
//! cut into whole cycles of the step's frequency, at most four blocks of
//! them; in each block the force and each signal are fitted by least
//! squares with a sine, a cosine and a constant at that frequency, and the
//! step's response is the ratio of the blocks' mean amplitudes, with its
//! variance from their spread ([`frf::ratio`](crate::frf)), as a periodic
//! record's is from its periods'.
//!
//! The frequency is the force's own: the peak of its zero-padded spectrum,
//! refined by golden sections on what a sine there explains. A record made
//! elsewhere need not say what it played, only how long each step is.

use crate::frf::Frf;
use crate::IdentifyError;
use nalgebra::{Matrix3, Vector3};
use num_complex::Complex64;
use std::f64::consts::TAU;

/// The most blocks a step's cycles are cut into.
const BLOCKS: usize = 4;

/// What a stepped sine measured: at each step's frequency (sorted), the
/// response of each signal to the force.
#[derive(Clone, Debug, PartialEq)]
pub struct Steps {
    /// One response per signal, at the steps' frequencies.
    pub responses: Vec<Frf>,
    /// The force's amplitude at each step (N).
    pub force_n: Vec<f64>,
    /// Samples in one cycle of each step's frequency.
    pub cycle_ticks: Vec<f64>,
}

/// The responses of each of `signals` to `force_n` over the whole steps
/// of `step_ticks` samples after the first `skip`. Refused, naming the
/// step: one with no force, or fewer than two cycles past its transient.
pub fn stepped(
    force_n: &[f64],
    signals: &[&[f64]],
    period_s: f64,
    step_ticks: usize,
    skip: usize,
) -> Result<Steps, IdentifyError> {
    let steps = (force_n.len() / step_ticks.max(1)).saturating_sub(skip);
    if steps < 2 || step_ticks < 8 {
        return Err(IdentifyError::Log {
            place: "the record".into(),
            why: format!(
                "{steps} whole steps of {step_ticks} samples after the {skip} skipped: a stepped sine needs two steps at least"
            ),
        });
    }
    type Row = (f64, Vec<(Complex64, f64)>, f64, f64);
    let mut rows: Vec<Row> = Vec::with_capacity(steps);
    for k in skip..skip + steps {
        let from = k * step_ticks + step_ticks / 4;
        let to = (k + 1) * step_ticks;
        let f = &force_n[from..to];
        let w = frequency(f).ok_or_else(|| no_force(k, 0.0))?;
        let cycles = (w * f.len() as f64 / TAU).floor() as usize;
        if cycles < 2 {
            return Err(IdentifyError::Log {
                place: format!("step {k}"),
                why: format!(
                    "{:.3} Hz holds {cycles} whole cycles after the step's first quarter: make the steps longer",
                    w / (TAU * period_s)
                ),
            });
        }
        let blocks = cycles.min(BLOCKS);
        // Block edges at whole cycles.
        let edge = |b: usize| ((cycles * b / blocks) as f64 * TAU / w).round() as usize;
        let amplitudes = |x: &[f64]| -> Vec<Complex64> {
            (0..blocks)
                .map(|b| amplitude(&x[from + edge(b)..from + edge(b + 1)], w, edge(b)))
                .collect()
        };
        let fa = amplitudes(force_n);
        let per_signal = signals
            .iter()
            .map(|s| {
                crate::frf::ratio(&fa, &amplitudes(s))
                    .ok_or_else(|| no_force(k, fa.iter().sum::<Complex64>().norm() / blocks as f64))
            })
            .collect::<Result<Vec<_>, _>>()?;
        let force = fa.iter().sum::<Complex64>().norm() / blocks as f64;
        rows.push((w / (TAU * period_s), per_signal, force, TAU / w));
    }
    rows.sort_by(|a, b| a.0.total_cmp(&b.0));
    Ok(Steps {
        responses: (0..signals.len())
            .map(|i| Frf {
                freq_hz: rows.iter().map(|r| r.0).collect(),
                response: rows.iter().map(|r| r.1[i].0).collect(),
                variance: rows.iter().map(|r| r.1[i].1).collect(),
                periods: BLOCKS,
            })
            .collect(),
        force_n: rows.iter().map(|r| r.2).collect(),
        cycle_ticks: rows.iter().map(|r| r.3).collect(),
    })
}

fn no_force(step: usize, force_n: f64) -> IdentifyError {
    IdentifyError::Log {
        place: format!("step {step}"),
        why: format!("the force holds no sine there (|F| = {force_n:.3e} N)"),
    }
}

/// The least squares of `x ≈ a cos(ω n) + b sin(ω n) + c` (`ω` in
/// radians a sample, `n` counted from `start`): `(a, b, c)`, and the
/// projection `y` of `x` on the three (whose product with them is what
/// they explain of `x`); `None` where the three are not independent.
fn sine_fit(x: &[f64], w: f64, start: usize) -> Option<(Vector3<f64>, Vector3<f64>)> {
    let mut a = Matrix3::zeros();
    let mut y = Vector3::zeros();
    for (i, v) in x.iter().enumerate() {
        let t = w * (start + i) as f64;
        let row = Vector3::new(t.cos(), t.sin(), 1.0);
        a += row * row.transpose();
        y += row * *v;
    }
    a.cholesky().map(|c| (c.solve(&y), y))
}

/// The complex amplitude `a - j b` of [`sine_fit`]: the amplitude a DFT
/// at `ω` would give, over two.
fn amplitude(x: &[f64], w: f64, start: usize) -> Complex64 {
    match sine_fit(x, w, start) {
        Some((p, _)) => Complex64::new(p[0], -p[1]),
        None => Complex64::new(0.0, 0.0),
    }
}

/// The frequency (radians a sample) of the sine in `f`: its spectrum's
/// peak, zero-padded four times, refined by golden sections on what a
/// sine there explains, within a bin either side. `None` for a flat
/// force.
fn frequency(f: &[f64]) -> Option<f64> {
    let n = (4 * f.len()).next_power_of_two();
    let mean = f.iter().sum::<f64>() / f.len() as f64;
    let mut buf: Vec<Complex64> = f
        .iter()
        .map(|v| Complex64::new(v - mean, 0.0))
        .chain(std::iter::repeat(Complex64::new(0.0, 0.0)))
        .take(n)
        .collect();
    rustfft::FftPlanner::new()
        .plan_fft_forward(n)
        .process(&mut buf);
    let (peak, power) = buf[1..n / 2]
        .iter()
        .enumerate()
        .map(|(i, c)| (i + 1, c.norm_sqr()))
        .max_by(|a, b| a.1.total_cmp(&b.1))?;
    if power.is_nan() || power <= 0.0 {
        return None;
    }
    let bin = TAU / n as f64;
    // What a sine, a cosine and a constant at `w` explain of `f`, by least
    // squares: exact for a pure sine however few its cycles, where the
    // spectrum's peak leans toward its image at `-w`.
    let power_at = |w: f64| -> f64 { sine_fit(f, w, 0).map_or(0.0, |(p, y)| y.dot(&p)) };
    let (mut lo, mut hi) = ((peak as f64 - 1.0) * bin, (peak as f64 + 1.0) * bin);
    let g = (5f64.sqrt() - 1.0) / 2.0;
    for _ in 0..40 {
        let (a, b) = (hi - g * (hi - lo), lo + g * (hi - lo));
        if power_at(a) > power_at(b) {
            hi = b;
        } else {
            lo = a;
        }
    }
    Some((lo + hi) / 2.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Sines at 3.7, 41.2 and 180.05 Hz (a 1 kHz record, 2,000 samples a
    /// step, steps out of order), the signal each sine through a known
    /// gain and phase plus a slow drift: the frequencies come back to 1e-6
    /// Hz and the responses to 1e-6; a step of constant force is named.
    #[test]
    fn each_steps_frequency_and_response_come_back() {
        let (t, l) = (1e-3, 2000);
        let steps = [41.2, 3.7, 180.05];
        let gain = |hz: f64| Complex64::from_polar(1e-3 / (1.0 + hz / 50.0), -hz / 100.0);
        let (mut f, mut x) = (Vec::new(), Vec::new());
        for (k, hz) in steps.iter().enumerate() {
            for i in 0..l {
                let n = k * l + i;
                let phase = TAU * hz * n as f64 * t;
                let g = gain(*hz);
                f.push(2.0 * phase.sin() + 0.1);
                x.push(2.0 * g.norm() * (phase + g.arg()).sin() + 1e-6 * n as f64 / l as f64);
            }
        }
        let out = stepped(&f, &[&x], t, l, 0).unwrap();
        let r = &out.responses[0];
        assert!(
            out.force_n.iter().all(|a| (a - 2.0).abs() < 1e-3),
            "{:?}",
            out.force_n
        );
        let mut want = steps.to_vec();
        want.sort_by(f64::total_cmp);
        for (i, hz) in want.iter().enumerate() {
            assert!((r.freq_hz[i] - hz).abs() < 1e-6, "{:?}", r.freq_hz);
            let e = (r.response[i] / gain(*hz) - 1.0).norm();
            // (The drift is not a sine: it leaks a little.)
            assert!(e < 1e-3, "{hz} Hz: {e}");
        }
        let mut flat = f.clone();
        flat[l..2 * l].iter_mut().for_each(|v| *v = 0.5);
        let e = stepped(&flat, &[&x], t, l, 0).unwrap_err().to_string();
        assert!(e.contains("step 1") && e.contains("no sine"), "{e}");
    }
}
