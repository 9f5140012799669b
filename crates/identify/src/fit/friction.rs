//! Coulomb friction, estimated beside the linear model and taken out of
//! it.
//!
//! Under a periodic force, friction's force is periodic too, so averaging
//! periods keeps it: left in, it shows as damping the device does not
//! have (on the Excalibur, 0.2 N of it against a 20 N multisine made the
//! 79 Hz mode look 10% more damped, and the design 18% too stiff). A proof
//! must not lean on friction, which vanishes at small motions. So the
//! device is taken to feel `F - F_c sign(v)`, the push less friction, with
//! `S` the spectrum of the velocity's sign over the mean period
//! ([`tick_sign`]): then
//! `X = H (F - F_c S)` at every harmonic, and
//! `F/X = Y_rigid + F_c S/X` at the lowest ones, where the device moves
//! as one body (`Y_rigid = (-m ω² + j ω d) e^{jωT/2}`), is linear in the
//! mass, the damping and `F_c`.

use super::Measured;
use nalgebra::{Matrix3, Vector3};
use num_complex::Complex64;
use std::f64::consts::TAU;

/// The velocity's sign over each tick of the mean period, averaged
/// within the tick: what friction opposed while that tick's force acted
/// (from reading `n` to reading `n + 1`).
///
/// Signs read from encoder differences are wrong near every reversal,
/// and a multisine reverses hundreds of times a second: noise in the
/// regressor, which biases the friction found toward zero and hands the
/// rest to the damping (on a 0.25 kg handle, 0.05 N of friction came back
/// as 0.02 N and the damping 9% too large). So the velocity is taken
/// from the mean period's position, band-limited to its lowest `top`
/// harmonics (where the motion is, and little of the quantum), and
/// evaluated at `SUB` instants across each tick. `None` where there is no
/// whole period after `skip`, or `top` is not below half the period.
pub fn tick_sign(position_m: &[f64], period: usize, top: usize, skip: usize) -> Option<Vec<f64>> {
    const SUB: usize = 8;
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
    let mut sign = vec![0.0; period];
    let mut buf = vec![Complex64::new(0.0, 0.0); period];
    for j in 0..SUB {
        let delta = (j as f64 + 0.5) / SUB as f64;
        buf.iter_mut().for_each(|b| *b = Complex64::new(0.0, 0.0));
        for k in 1..=top {
            // d/dt of harmonic k, delayed by delta of a tick (units do not
            // matter to a sign).
            let turn = TAU * k as f64 * delta / period as f64;
            let v = Complex64::new(0.0, k as f64) * mean[k] * Complex64::from_polar(1.0, turn);
            buf[k] = v;
            buf[period - k] = v.conj();
        }
        inverse.process(&mut buf);
        for (s, v) in sign.iter_mut().zip(&buf) {
            *s += v.re.signum() / SUB as f64;
        }
    }
    Some(sign)
}

/// The mass (kg), damping (N s/m) and Coulomb friction (N) that explain
/// the harmonics below `below_hz` as one body, or `None` where there are
/// fewer than three or the numbers make no sense (a mass not positive).
pub fn rigid_with_friction(
    data: &Measured,
    period_s: f64,
    below_hz: f64,
) -> Option<(f64, f64, f64)> {
    let s = data.friction.as_ref()?;
    let x = &data.position;
    let mut ata = Matrix3::zeros();
    let mut atb = Vector3::zeros();
    let mut used = 0;
    for ((f, h), s) in x.freq_hz.iter().zip(&x.response).zip(s) {
        if *f >= below_hz {
            break;
        }
        let w = TAU * f;
        let hold = Complex64::from_polar(1.0, w * period_s / 2.0);
        // F/X = (1/H): with S/F stored, S/X = (S/F) (F/X).
        let fx = 1.0 / h;
        let cols = [-w * w * hold, Complex64::new(0.0, w) * hold, s * fx];
        // Each harmonic weighted as a relative error of F/X.
        let wt = 1.0 / fx.norm_sqr();
        for part in [|c: Complex64| c.re, |c: Complex64| c.im] {
            let row = Vector3::new(part(cols[0]), part(cols[1]), part(cols[2]));
            ata += row * row.transpose() * wt;
            atb += row * part(fx) * wt;
        }
        used += 1;
    }
    if used < 3 {
        return None;
    }
    let p = ata.cholesky()?.solve(&atb);
    (p[0] > 0.0 && p.iter().all(|v| v.is_finite())).then_some((p[0], p[1], p[2].max(0.0)))
}

/// `data` with friction of `coulomb_n` taken out: each response per the
/// force the device felt, `X/(F - F_c S)`, and the velocity's sign per
/// that force, so that more can be taken out later.
pub fn without(data: &Measured, coulomb_n: f64) -> Measured {
    let Some(s) = &data.friction else {
        return data.clone();
    };
    let scale = |f: &crate::frf::Frf| {
        let mut f = f.clone();
        for (i, h) in f.response.iter_mut().enumerate() {
            let k = 1.0 - coulomb_n * s[i];
            *h /= k;
            f.variance[i] /= k.norm_sqr();
        }
        f
    };
    Measured {
        position: scale(&data.position),
        load_cell: data.load_cell.as_ref().map(scale),
        friction: Some(s.iter().map(|s| s / (1.0 - coulomb_n * s)).collect()),
        encoder_quantum_m: data.encoder_quantum_m,
        coulomb_n: Some(data.coulomb_n.unwrap_or(0.0) + coulomb_n),
        // The device's friction is the same with a mass on its handle.
        loaded: data.loaded.as_ref().map(|l| {
            Box::new(super::Loaded {
                added_kg: l.added_kg,
                data: without(&l.data, coulomb_n),
            })
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::log::{Excitation, Log};
    use twoport_control::multisine::Multisine;

    /// A 2 kg mass with 5 N s/m of damping and 0.5 N of Coulomb friction
    /// (smoothed over 0.1 mm/s), pushed by a 40 N multisine from 1 to 40 Hz
    /// and read by a 1 um encoder: the mass, the damping and the friction
    /// come back, and the response with friction taken out is the linear
    /// mass-damper's, where left in it is not.
    #[test]
    fn friction_is_found_and_taken_out() {
        let (m, d, fc, t) = (2.0, 5.0, 0.5, 1e-3);
        let ms = Multisine::new(1000, 1, 40, 40.0).unwrap();
        let (mut x, mut v) = (0.0f64, 0.0f64);
        let (mut force, mut pos) = (Vec::new(), Vec::new());
        for n in 0..20_000u32 {
            let y = (x / 1e-6).round() * 1e-6;
            // A weak hold keeps it centred, as the board's does.
            let f = ms.at(n) as f64 - 300.0 * y;
            force.push(f);
            pos.push(y);
            for _ in 0..20 {
                let a = (f - d * v - fc * (v / 1e-4).tanh()) / m;
                let h = t / 20.0;
                x += v * h + 0.5 * a * h * h;
                v += a * h;
            }
        }
        let log = Log {
            period_s: t,
            force_n: force,
            position_m: pos,
            load_cell_n: None,
            excitation: Some(Excitation {
                period_ticks: 1000,
                first: 1,
                last: 40,
            }),
        };
        // (Past the transient: the hold's lightly damped 2 Hz mode.)
        let data = Measured::from_log(&log, 8).unwrap();
        let (mm, dd, ff) = rigid_with_friction(&data, t, 41.0).unwrap();
        assert!((mm / m - 1.0).abs() < 0.02, "{mm} kg");
        assert!((dd / d - 1.0).abs() < 0.15, "{dd} N s/m");
        assert!((ff / fc - 1.0).abs() < 0.15, "{ff} N");
        let clean = without(&data, ff);
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
