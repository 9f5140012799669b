//! Friction and cogging: forces the device adds that depend on its
//! motion, estimated beside the linear model and taken out of it.
//!
//! Under a periodic force, friction's force is periodic too, so averaging
//! periods keeps it: left in, it shows as damping the device does not
//! have (on the Excalibur, 0.2 N of it against a 20 N multisine made the
//! 79 Hz mode look 10% more damped, and the design 18% too stiff). A proof
//! must not lean on friction, which vanishes at small motions. So the
//! device is taken to feel the push less each such force, `F - Σ c_j R_j`,
//! each a known shape over the mean period ([`Regressor`]) times an
//! amount `c_j` to find: friction is `F_c` times the velocity's sign
//! ([`tick_sign`]), cogging `a sin(2π x/p) + b cos(2π x/p)` at the
//! actuator's position ([`super::cogging`]). Then `X = H (F - Σ c_j R_j)`
//! at every harmonic, and `F/X = Y_rigid + Σ c_j R_j/X` at the lowest
//! ones, where the device moves as one body (`Y_rigid = (-m ω² + j ω d)
//! e^{jωT/2}`), is linear in the mass, the damping and the amounts.

use super::Measured;
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64;
use std::f64::consts::TAU;

/// Instants a tick is evaluated at, across it.
pub(crate) const SUB: usize = 8;

/// The shape of a force the device adds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    /// Coulomb friction: the velocity's sign.
    Coulomb,
    /// Cogging's sine part, `sin(2π x/p)` at the actuator's position `x`.
    CoggingSin {
        /// The spatial period `p` (m).
        period_m: f64,
    },
    /// Cogging's cosine part, `cos(2π x/p)`.
    CoggingCos {
        /// The spatial period `p` (m).
        period_m: f64,
    },
}

/// A force the device adds, known up to its amount: its shape's spectrum
/// per unit push at each played harmonic, and how much of it (N) has been
/// taken out of the responses already.
#[derive(Clone, Debug, PartialEq)]
pub struct Regressor {
    /// What it is.
    pub shape: Shape,
    /// The shape's spectrum over the mean period per the force's, `R/F`.
    pub per_force: Vec<Complex64>,
    /// The amount taken out so far (N).
    pub taken_n: f64,
}

/// The mean period's position band-limited to its lowest `top` harmonics
/// (where the motion is, and little of the quantum), at eight instants
/// across each tick (`[instant][tick]`), with its mean; or, with
/// `derivative`, its rate of change (in units that do not matter to a
/// sign). `None` where there is no whole period after `skip`, or `top` is
/// not below half the period.
pub(crate) fn band_limited(
    position_m: &[f64],
    period: usize,
    top: usize,
    skip: usize,
    derivative: bool,
) -> Option<Vec<Vec<f64>>> {
    let periods = (position_m.len() / period.max(1)).checked_sub(skip)?;
    if periods == 0 || 2 * top >= period {
        return None;
    }
    let mut mean = vec![Complex64::new(0.0, 0.0); period];
    for k in skip..skip + periods {
        for (m, x) in mean
            .iter_mut()
            .zip(&position_m[k * period..(k + 1) * period])
        {
            m.re += x / periods as f64;
        }
    }
    let mut planner = rustfft::FftPlanner::new();
    planner.plan_fft_forward(period).process(&mut mean);
    let inverse = planner.plan_fft_inverse(period);
    let mut buf = vec![Complex64::new(0.0, 0.0); period];
    let out = (0..SUB)
        .map(|j| {
            let delta = (j as f64 + 0.5) / SUB as f64;
            buf.iter_mut().for_each(|b| *b = Complex64::new(0.0, 0.0));
            if !derivative {
                buf[0] = mean[0];
            }
            for k in 1..=top {
                // Harmonic k (or its rate), delayed by delta of a tick.
                let turn = TAU * k as f64 * delta / period as f64;
                let scale = if derivative {
                    Complex64::new(0.0, k as f64)
                } else {
                    Complex64::new(1.0, 0.0)
                };
                let v = scale * mean[k] * Complex64::from_polar(1.0, turn);
                buf[k] = v;
                buf[period - k] = v.conj();
            }
            inverse.process(&mut buf);
            buf.iter().map(|v| v.re / period as f64).collect()
        })
        .collect();
    Some(out)
}

/// The velocity's sign over each tick of the mean period, averaged
/// within the tick: what friction opposed while that tick's force acted
/// (from reading `n` to reading `n + 1`).
///
/// Signs read from encoder differences are wrong near every reversal,
/// and a multisine reverses hundreds of times a second: noise in the
/// regressor, which biases the friction found toward zero and hands the
/// rest to the damping (on a 0.25 kg handle, 0.05 N of friction came back
/// as 0.02 N and the damping 9% too large). So the velocity is taken
/// from the mean period's position, band-limited to the played
/// harmonics and evaluated at eight instants across each tick.
pub fn tick_sign(position_m: &[f64], period: usize, top: usize, skip: usize) -> Option<Vec<f64>> {
    let v = band_limited(position_m, period, top, skip, true)?;
    Some(
        (0..period)
            .map(|n| v.iter().map(|at| at[n].signum()).sum::<f64>() / SUB as f64)
            .collect(),
    )
}

/// The rigid body that explains the harmonics below `below_hz` with each
/// of `data`'s forces and any `more`, and `bend` more terms of the
/// impedance's series, `(jω)^3 e^{jωT/2}` and up, which take up how the
/// structure's modes bend the band smoothly (so that a force's rough
/// shape is not asked to): its mass (kg), damping (N s/m), the amount of
/// each force (N; `data`'s first, then `more`'s), and the
/// weighted misfit (each harmonic by its measured variance, with the
/// model floor). `None` where the harmonics (two equations each) leave
/// fewer than two equations over the unknowns, or the numbers make no
/// sense (a mass not positive).
pub fn rigid_with(
    data: &Measured,
    more: &[&[Complex64]],
    bend: usize,
    period_s: f64,
    below_hz: f64,
) -> Option<(f64, f64, Vec<f64>, f64)> {
    let rows = RigidRows::new(data, more, bend, period_s, below_hz, 2)?;
    let (a, b) = (&rows.a, &rows.b);
    let p = a.clone().svd(true, true).solve(b, 1e-12).ok()?;
    let cost = (a * &p - b).norm_squared();
    let ok = p[0] > 0.0 && p.iter().all(|v| v.is_finite());
    ok.then(|| (p[0], p[1], p.as_slice()[rows.body + bend..].to_vec(), cost))
}

/// The weighted least-squares rows of [`rigid_with`]: two a harmonic
/// below the band's top (the real and imaginary parts of `F/X`), each
/// harmonic weighted as a relative error of `F/X` by its measured
/// variance with the model floor. Where the record shows a spring to the
/// frame ([`ground_shown`](super::ground_shown)), the body is held by
/// one: its stiffness is a column too.
pub(crate) struct RigidRows {
    /// The columns: mass, damping, the spring to the frame if shown, the
    /// `bend` terms, then each shape.
    pub a: DMatrix<f64>,
    /// The body's columns before the `bend` terms: 2, or 3 held.
    pub body: usize,
    /// `F/X`.
    pub b: DVector<f64>,
    /// Each harmonic's `F/X` times its weight: a shape per force times it
    /// is the shape's column.
    pub scale: Vec<Complex64>,
    /// Harmonics used.
    pub used: usize,
}

impl RigidRows {
    /// The rows for `data`'s forces and `more`; `None` where they would
    /// leave fewer than `spare` equations over the unknowns.
    pub fn new(
        data: &Measured,
        more: &[&[Complex64]],
        bend: usize,
        period_s: f64,
        below_hz: f64,
        spare: usize,
    ) -> Option<RigidRows> {
        let x = &data.position;
        let shapes: Vec<&[Complex64]> = data
            .forces
            .iter()
            .map(|r| r.per_force.as_slice())
            .chain(more.iter().copied())
            .collect();
        let held = super::ground_shown(x, period_s).is_some();
        let body = 2 + usize::from(held);
        let n = body + bend + shapes.len();
        let used = x.freq_hz.iter().take_while(|f| **f < below_hz).count();
        if 2 * used < n + spare {
            return None;
        }
        let mut a = DMatrix::zeros(2 * used, n);
        let mut b = DVector::zeros(2 * used);
        let mut scale = Vec::with_capacity(used);
        for i in 0..used {
            let w = TAU * x.freq_hz[i];
            let hold = Complex64::from_polar(1.0, w * period_s / 2.0);
            // F/X = 1/H: with R/F stored, R/X = (R/F) (F/X).
            let fx = 1.0 / x.response[i];
            let rel = x.variance[i] / x.response[i].norm_sqr() + super::MODEL_FLOOR.powi(2);
            let wt = 1.0 / (fx.norm() * rel.sqrt());
            let mut cols = vec![-w * w * hold, Complex64::new(0.0, w) * hold];
            if held {
                cols.push(hold);
            }
            cols.extend((0..bend).map(|k| Complex64::new(0.0, w).powi(3 + k as i32) * hold));
            cols.extend(shapes.iter().map(|s| s[i] * fx));
            for (j, c) in cols.iter().enumerate() {
                a[(2 * i, j)] = c.re * wt;
                a[(2 * i + 1, j)] = c.im * wt;
            }
            b[2 * i] = fx.re * wt;
            b[2 * i + 1] = fx.im * wt;
            scale.push(fx * wt);
        }
        Some(RigidRows {
            a,
            body,
            b,
            scale,
            used,
        })
    }
}

/// `data` with `amounts` (N, one per force of `data`'s, in order) taken
/// out: each response per the force the device felt, `X/(F - Σ c_j R_j)`,
/// and each shape per that force, so that more can be taken out later.
pub fn without(data: &Measured, amounts: &[f64]) -> Measured {
    let felt = |i: usize| {
        1.0 - data
            .forces
            .iter()
            .zip(amounts)
            .map(|(r, c)| c * r.per_force[i])
            .sum::<Complex64>()
    };
    let scale = |f: &crate::frf::Frf| {
        let mut f = f.clone();
        for (i, h) in f.response.iter_mut().enumerate() {
            let k = felt(i);
            *h /= k;
            f.variance[i] /= k.norm_sqr();
        }
        f
    };
    Measured {
        position: scale(&data.position),
        load_cell: data.load_cell.as_ref().map(scale),
        forces: data
            .forces
            .iter()
            .zip(amounts.iter().chain(std::iter::repeat(&0.0)))
            .map(|(r, c)| Regressor {
                shape: r.shape,
                per_force: r
                    .per_force
                    .iter()
                    .enumerate()
                    .map(|(i, s)| s / felt(i))
                    .collect(),
                taken_n: r.taken_n + c,
            })
            .collect(),
        encoder_quantum_m: data.encoder_quantum_m,
        motion: data.motion.clone(),
        // The device's friction and cogging are the same with a mass on
        // its handle (the loaded record's shapes are its own motion's).
        loaded: data.loaded.as_ref().map(|l| {
            Box::new(super::Loaded {
                added_kg: l.added_kg,
                data: without(&l.data, amounts),
            })
        }),
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::log::{Excitation, Log};
    use twoport_control::multisine::Multisine;

    /// A handle on a bench: a mass with damping, Coulomb friction
    /// (smoothed over 0.1 mm/s) and cogging every 2 mm, pushed by a
    /// multisine of 1 s periods, held by a weak spring-damper, and read
    /// by a 1 um encoder: twenty seconds of its record.
    pub(crate) struct Bench {
        /// Mass (kg), damping (N s/m), friction (N), cogging (N).
        pub m: f64,
        pub d: f64,
        pub fc: f64,
        pub cogging: f64,
        /// The multisine's top harmonic and peak (N).
        pub top: u32,
        pub peak: f32,
        /// The hold's stiffness (N/m) and damping (N s/m).
        pub hold: (f64, f64),
    }

    impl Bench {
        pub fn record(&self) -> Log {
            let t = 1e-3;
            let ms = Multisine::new(1000, 1, self.top, self.peak).unwrap();
            let (mut x, mut v) = (0.0f64, 0.0f64);
            let (mut force, mut pos) = (Vec::new(), Vec::new());
            for n in 0..20_000u32 {
                let y = (x / 1e-6).round() * 1e-6;
                // A weak hold keeps it centred, as the board's does.
                let f = ms.at(n) as f64 - self.hold.0 * y - self.hold.1 * v;
                force.push(f);
                pos.push(y);
                for _ in 0..20 {
                    let cog = self.cogging * (TAU * x / 2e-3).sin();
                    let a = (f - self.d * v - self.fc * (v / 1e-4).tanh() + cog) / self.m;
                    let h = t / 20.0;
                    x += v * h + 0.5 * a * h * h;
                    v += a * h;
                }
            }
            Log {
                period_s: t,
                force_n: force,
                position_m: pos,
                load_cell_n: None,
                excitation: Some(Excitation::Periodic {
                    period_ticks: 1000,
                    first: 1,
                    last: self.top as usize,
                }),
            }
        }
    }

    /// A 2 kg mass with 5 N s/m of damping and 0.5 N of Coulomb friction,
    /// pushed by a 40 N multisine from 1 to 40 Hz: the mass, the damping
    /// and the friction come back, and the response with friction taken
    /// out is the linear mass-damper's, where left in it is not.
    #[test]
    fn friction_is_found_and_taken_out() {
        let (m, d, fc, t) = (2.0, 5.0, 0.5, 1e-3);
        let log = Bench {
            m,
            d,
            fc,
            cogging: 0.0,
            top: 40,
            peak: 40.0,
            hold: (300.0, 0.0),
        }
        .record();
        // (Past the transient: the hold's lightly damped 2 Hz mode.)
        let data = Measured::from_log(&log, 8).unwrap();
        let (mm, dd, ff, _) = rigid_with(&data, &[], 0, t, 41.0).unwrap();
        let ff = ff[0];
        assert!((mm / m - 1.0).abs() < 0.02, "{mm} kg");
        assert!((dd / d - 1.0).abs() < 0.15, "{dd} N s/m");
        assert!((ff / fc - 1.0).abs() < 0.15, "{ff} N");
        let clean = without(&data, &[ff]);
        // The exact sampled response, the designer's, of the mass-damper.
        let model = twoport_design::DeviceModel::from_toml(
            "name = \"mass\"\nperiod_s = 0.001\npeak_force_n = 50.0\ncontinuous_force_n = 20.0\n\
             M = [[2.0]]\nD = [[5.0]]\nK = [[0.0]]\nG = [[1.0, -1.0]]\nC_v = [[1.0], [-1.0]]\n",
            "mass",
        )
        .unwrap();
        let exact = super::super::sampled_response(&model, &data.position.freq_hz).unwrap();
        let worst = |data: &Measured| {
            data.position
                .response
                .iter()
                .zip(&exact)
                .map(|(h, e)| (h / e.0 - 1.0).norm())
                .fold(0.0, f64::max)
        };
        assert!(worst(&clean) < 0.03, "{}", worst(&clean));
        assert!(
            worst(&data) > 3.0 * worst(&clean),
            "{} {}",
            worst(&data),
            worst(&clean)
        );
    }
}
