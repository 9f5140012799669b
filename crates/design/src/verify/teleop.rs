//! The exact discrete closed loop of a teleoperator: the master device
//! with the operator at its handle and the slave with the environment at
//! its, each continuous and discretised exactly under the zero-order
//! hold, and between them the control crate's teleoperator law (its
//! z-form, channel delay included) on the sampled encoders and load
//! cells. It is stable iff its one-tick transition matrix's spectral
//! radius is below 1; [`verify_teleop`] searches the operators and
//! environments for the largest.

use super::closed_loop::{judge, sampled, Sampled};
use super::{Hand, Radius};
use crate::designer::TeleopVerifyReport;
use crate::linalg::balance;
use crate::rational::{mul, realise, scale, Rational, Ss};
use crate::DeviceModel;
use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};
use twoport_control::teleop::{
    Delayed, FourChannel, FourChannelGains, Sparse, TeleopTransfer, WaveVariables,
};

/// A teleoperator to check: the two devices (at their models' sample
/// period, which must agree) and the law between them.
#[derive(Clone, Copy, Debug)]
pub struct Teleoperator<'a> {
    /// The device under the operator's hand.
    pub master: &'a DeviceModel,
    /// The device on the environment.
    pub slave: &'a DeviceModel,
    /// The law's z-form ([`TeleopTransfer`]): the forces per each
    /// device's velocity, the slave's and the master's sensed force (each
    /// device's load-cell reading, as its model's `C_f` gives it).
    pub law: TeleopTransfer,
}

/// What terminates the teleoperator: a passive operator at the master's
/// handle and a passive environment at the slave's, each a lumped mass
/// with a spring and a damper to ground ([`Hand::OFF`]: let go, or free
/// space).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TeleopTermination {
    /// At the master's handle.
    pub operator: Hand,
    /// At the slave's handle.
    pub environment: Hand,
}

/// A law's term as a rational function of `z^-1`, dense.
fn rational(t: &Delayed) -> Rational {
    let dense = |p: &Sparse| {
        let mut c = vec![0.0; p.degree() as usize + 1];
        for (v, k) in p.coef.iter().zip(p.power) {
            if *v != 0.0 {
                c[k as usize] += v;
            }
        }
        c
    };
    (dense(&t.num), dense(&t.den))
}

/// The teleoperator's one-tick transition matrix for one termination,
/// balanced.
pub fn teleop_closed_loop(
    t: &Teleoperator,
    term: &TeleopTermination,
) -> Result<DMatrix<f64>, String> {
    let period_s = t.master.period_s;
    if t.slave.period_s != period_s {
        return Err(format!(
            "the master samples every {} s and the slave every {} s: one period for both",
            t.master.period_s, t.slave.period_s
        ));
    }
    let plants = [
        sampled(t.master, &term.operator, period_s)?,
        sampled(t.slave, &term.environment, period_s)?,
    ];
    let offsets = [0, plants[0].ad.nrows()];
    let np = offsets[1] + plants[1].ad.nrows();
    // The law's inputs, each read from one plant's state: the master's
    // and the slave's encoder, the slave's and the master's load cell.
    let reading = |j: usize| -> Vec<f64> {
        let (side, encoder) = [(0, true), (1, true), (1, false), (0, false)][j];
        let p: &Sampled = &plants[side];
        let c = if encoder { &p.c_xa[..] } else { p.c_fm() };
        let mut row = vec![0.0; np];
        for (i, v) in c.iter().enumerate() {
            row[offsets[side] + i] = *v;
        }
        row
    };
    // Every nonzero term, realised; a velocity column taken from the
    // position as the law's estimator does, `v = (1 - z^-1)/T x`.
    let mut terms: Vec<(usize, usize, Ss)> = Vec::new();
    for (r, row) in t.law.z.iter().enumerate() {
        for (j, term) in row.iter().enumerate() {
            if term.num.is_zero() {
                continue;
            }
            let (mut num, den) = rational(term);
            if j < 2 {
                num = scale(&mul(&num, &[1.0, -1.0]), 1.0 / period_s);
            }
            terms.push((r, j, realise(&num, &den).map_err(|e| e.to_string())?));
        }
    }
    let n = np + terms.iter().map(|(_, _, s)| s.a.nrows()).sum::<usize>();
    let mut a = DMatrix::<f64>::zeros(n, n);
    for (side, p) in plants.iter().enumerate() {
        let o = offsets[side];
        let m = p.ad.nrows();
        a.view_mut((o, o), (m, m)).copy_from(&p.ad);
    }
    let mut off = np;
    for (r, j, s) in &terms {
        let (o, p) = (offsets[*r], &plants[*r]);
        let y = reading(*j);
        let m = s.a.nrows();
        for i in 0..p.ad.nrows() {
            // u_r = C s + D y, into the plant through its hold.
            for (col, v) in y.iter().enumerate() {
                a[(o + i, col)] += p.bd[i] * s.d * v;
            }
            for k in 0..m {
                a[(o + i, off + k)] += p.bd[i] * s.c[k];
            }
        }
        for i in 0..m {
            for (col, v) in y.iter().enumerate() {
                a[(off + i, col)] += s.b[i] * v;
            }
            for k in 0..m {
                a[(off + i, off + k)] = s.a[(i, k)];
            }
        }
        off += m;
    }
    if a.iter().any(|v| !v.is_finite()) {
        return Err("the teleoperator's closed loop is not finite".into());
    }
    let d = balance(&a);
    Ok(DMatrix::from_fn(n, n, |i, k| a[(i, k)] * d[k] / d[i]))
}

/// The teleoperator's spectral radius for one termination.
pub fn teleop_radius(t: &Teleoperator, term: &TeleopTermination) -> Result<Radius, String> {
    Ok(judge(&teleop_closed_loop(t, term)?, t.master.period_s))
}

/// What the search over operators and environments found.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TeleopVerdict {
    /// Whether the worst termination makes the loop unstable.
    pub unstable: bool,
    /// The worst spectral radius found.
    pub spectral_radius: f64,
    /// Its frequency (Hz).
    pub frequency_hz: f64,
    /// The termination that gave it.
    pub termination: TeleopTermination,
    /// Closed loops evaluated.
    pub evaluations: usize,
}

/// The terminations a search sweeps at each end: let go (or free space),
/// and lumped masses from 10 g to 3 kg on springs from none to 10^7 N/m
/// (a stiff wall) and dampers from none to 30 N s/m.
fn sweep() -> Vec<Hand> {
    let mut out = vec![Hand::OFF];
    for m in [0.0, 0.01, 0.05, 0.2, 1.0, 3.0] {
        for k in [0.0, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7] {
            for b in [0.0, 1.0, 30.0] {
                if m == 0.0 && k == 0.0 && b == 0.0 {
                    continue;
                }
                out.push(Hand {
                    mass_kg: m,
                    stiffness_npm: k,
                    damping_nspm: b,
                    grasp: None,
                    hanging: Vec::new(),
                });
            }
        }
    }
    out
}

/// Search passive operators and environments for the one that makes the
/// teleoperator's loop grow fastest: every operator of the sweep against
/// a few environments (free space, a soft, a firm and a stiff wall), and
/// every environment against a few operators (let go, a light and a heavy
/// hand), the worst kept. It proves nothing when it finds nothing; what
/// it finds is a real instability of the sampled loop.
pub fn verify_teleop(t: &Teleoperator) -> Result<TeleopVerdict, String> {
    let ends = sweep();
    let wall = |k: f64| Hand {
        stiffness_npm: k,
        ..Hand::OFF
    };
    let hand = |m: f64| Hand {
        mass_kg: m,
        damping_nspm: 1.0,
        ..Hand::OFF
    };
    let environments = [Hand::OFF, wall(1e3), wall(1e5), wall(1e7)];
    let operators = [Hand::OFF, hand(0.05), hand(1.0)];
    let pairs = ends
        .iter()
        .flat_map(|o| {
            environments.iter().map(move |e| TeleopTermination {
                operator: o.clone(),
                environment: e.clone(),
            })
        })
        .chain(ends.iter().flat_map(|e| {
            operators.iter().map(move |o| TeleopTermination {
                operator: o.clone(),
                environment: e.clone(),
            })
        }));
    let mut worst: Option<(Radius, TeleopTermination)> = None;
    let mut evaluations = 0;
    for term in pairs {
        let r = teleop_radius(t, &term)?;
        evaluations += 1;
        if worst.as_ref().is_none_or(|(w, _)| r.score > w.score) {
            worst = Some((r, term));
        }
    }
    let (r, termination) = worst.ok_or("no termination swept")?;
    Ok(TeleopVerdict {
        unstable: r.unstable,
        spectral_radius: r.spectral_radius,
        frequency_hz: r.frequency_hz,
        termination,
        evaluations,
    })
}

/// The longest channel delay [`verify_four_channel`] takes (ticks).
pub const MAX_DELAY_TICKS: usize = 1024;

/// A teleoperator's law as a lab names it: Lawrence's four channels (in
/// JSON and scene files, `"gains"`, each channel not named off), or the
/// wave-variable channel (`"wave"`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum TeleopLaw {
    /// Lawrence's four channels.
    #[serde(rename = "gains")]
    FourChannel(FourChannelGains),
    /// The wave-variable channel.
    #[serde(rename = "wave")]
    Wave(WaveGains),
}

/// The wave-variable channel's parameters.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WaveGains {
    /// The wave impedance (N s/m, > 0).
    pub b_nspm: f32,
    /// Each side's incoming-wave filter pole, in `[0, 1)` (0, the
    /// default: none).
    #[serde(default)]
    pub filter_pole: f32,
}

impl TeleopLaw {
    /// Its z-form at `period_s` across a channel `delay_ticks` long each
    /// way (at most [`MAX_DELAY_TICKS`]; at least one for waves): the law
    /// the control crate runs.
    pub fn tf(&self, period_s: f64, delay_ticks: usize) -> Result<TeleopTransfer, String> {
        match *self {
            TeleopLaw::FourChannel(g) => four_channel_tf(g, period_s, delay_ticks),
            TeleopLaw::Wave(w) => {
                if delay_ticks > MAX_DELAY_TICKS {
                    return Err(format!(
                        "delay {delay_ticks} ticks: at most {MAX_DELAY_TICKS}"
                    ));
                }
                WaveVariables::<f32, MAX_DELAY_TICKS>::new(w.b_nspm, delay_ticks)
                    .and_then(|l| l.with_wave_filter(w.filter_pole))
                    .map(|l| l.tf())
                    .map_err(|e| e.to_string())
            }
        }
    }
}

/// The z-form of Lawrence's four-channel law of `gains` across a channel
/// `delay_ticks` long each way, at `period_s`: the law the control crate
/// runs (a delay of at most [`MAX_DELAY_TICKS`]).
pub fn four_channel_tf(
    gains: FourChannelGains,
    period_s: f64,
    delay_ticks: usize,
) -> Result<TeleopTransfer, String> {
    if delay_ticks > MAX_DELAY_TICKS {
        return Err(format!(
            "delay {delay_ticks} ticks: at most {MAX_DELAY_TICKS}"
        ));
    }
    FourChannel::<f32, MAX_DELAY_TICKS>::new(
        gains,
        period_s as f32,
        delay_ticks,
        twoport_control::Position::ZERO,
    )
    .map(|law| law.tf())
    .map_err(|e| e.to_string())
}

/// [`verify_teleop_near_proof`](super::verify_teleop_near_proof) on
/// Lawrence's four-channel law of `gains` across a channel `delay_ticks`
/// long each way, between the models `master` and `slave` (which must
/// sample at one period): the law the control crate runs, its z-form
/// searched, with the proof's own worst hands.
pub fn verify_four_channel(
    master: &DeviceModel,
    slave: &DeviceModel,
    gains: FourChannelGains,
    delay_ticks: usize,
) -> Result<TeleopVerifyReport, crate::Error> {
    verify_law(master, slave, TeleopLaw::FourChannel(gains), delay_ticks)
}

/// [`verify_four_channel`] for any [`TeleopLaw`].
pub fn verify_law(
    master: &DeviceModel,
    slave: &DeviceModel,
    law: TeleopLaw,
    delay_ticks: usize,
) -> Result<TeleopVerifyReport, crate::Error> {
    let fail = |why: String| crate::Error::Verify {
        model: format!("{} and {}", master.name, slave.name),
        why,
    };
    let tf = law.tf(master.period_s, delay_ticks).map_err(fail)?;
    let analysis = crate::analysis::TeleopAnalysis::of(master, slave)?;
    let verdict = super::verify_teleop_near_proof(&analysis, &tf).map_err(fail)?;
    Ok(TeleopVerifyReport {
        master: master.name.clone(),
        slave: slave.name.clone(),
        period_s: master.period_s,
        delay_ticks,
        law,
        verdict,
    })
}
