//! Where a modal fit starts: its poles searched one mode at a time, and
//! for each candidate set of poles the residues by linear least squares
//! (variable projection). Each mode's response is the exact sampled one
//! (zero-order hold, the load cell's filter) of a lone mass-normalised
//! mode, so the start is what the exact model would give with a rigid
//! load cell, not a continuous-time approximation that is off near
//! Nyquist.

use super::modal::{Modal, ModeShape};
use super::Measured;
use crate::frf::Frf;
use nalgebra::{DMatrix, DVector, Matrix3, Vector3};
use num_complex::Complex64;
use std::f64::consts::TAU;
use twoport_design::linalg::expm_balanced;
use twoport_design::plant::Mode;

/// A pole of one basis response: `s² + a1 s + a0`.
#[derive(Clone, Copy, Debug)]
struct Pole {
    a1: f64,
    a0: f64,
}

impl Pole {
    fn mode(omega: f64, zeta: f64) -> Pole {
        Pole {
            a1: 2.0 * zeta * omega,
            a0: omega * omega,
        }
    }
}

/// The sampled responses of one mode to a held force, at `freq_hz`: its
/// displacement, and its acceleration through the load cell's filter
/// (pole `p`, rad/s).
fn basis(
    pole: Pole,
    p: f64,
    period_s: f64,
    freq_hz: &[f64],
) -> Option<Vec<(Complex64, Complex64)>> {
    let mut aug = DMatrix::zeros(4, 4);
    let a = [
        [0.0, 1.0, 0.0],
        [-pole.a0, -pole.a1, 0.0],
        [-p * pole.a0, -p * pole.a1, -p],
    ];
    let b = [0.0, 1.0, p];
    for i in 0..3 {
        for j in 0..3 {
            aug[(i, j)] = a[i][j] * period_s;
        }
        aug[(i, 3)] = b[i] * period_s;
    }
    let phi = expm_balanced(&aug).ok()?;
    let ad = Matrix3::from_fn(|i, j| Complex64::new(phi[(i, j)], 0.0));
    let bd = Vector3::from_fn(|i, _| Complex64::new(phi[(i, 3)], 0.0));
    freq_hz
        .iter()
        .map(|f| {
            let z = Complex64::from_polar(1.0, TAU * f * period_s);
            let v = (Matrix3::identity() * z - ad).lu().solve(&bd)?;
            Some((v[0], v[2]))
        })
        .collect()
}

/// One channel's weighted least squares: the real residues `c` that make
/// `Σ c_k basis_k` closest to `measured`, relative to each harmonic's
/// deviation; the residues and the cost. By the normal equations: a
/// handful of unknowns against thousands of harmonics.
fn project(
    columns: &[&[Complex64]],
    measured: &[Complex64],
    weight: &[f64],
) -> Option<(DVector<f64>, f64)> {
    let k = columns.len();
    let mut ata = DMatrix::zeros(k, k);
    let mut atb = DVector::zeros(k);
    let mut btb = 0.0;
    for (j, (y, w)) in measured.iter().zip(weight).enumerate() {
        let w2 = w * w;
        for a in 0..k {
            let ca = columns[a][j];
            atb[a] += w2 * (ca.conj() * y).re;
            for b in a..k {
                ata[(a, b)] += w2 * (ca.conj() * columns[b][j]).re;
            }
        }
        btb += w2 * y.norm_sqr();
    }
    for a in 0..k {
        for b in 0..a {
            ata[(a, b)] = ata[(b, a)];
        }
    }
    let x: DVector<f64> = ata.clone().cholesky()?.solve(&atb);
    let cost = (btb - 2.0 * x.dot(&atb) + x.dot(&(&ata * &x))).max(0.0);
    Some((x, cost))
}

/// Each harmonic's weight: one over the deviation of the measurement, as
/// in the fit's own residual (with its floor).
fn weights(response: &[Complex64], variance: &[f64]) -> Vec<f64> {
    response
        .iter()
        .zip(variance)
        .map(|(h, v)| {
            let n2 = h.norm_sqr().max(f64::MIN_POSITIVE);
            1.0 / (v + super::MODEL_FLOOR * super::MODEL_FLOOR * n2).sqrt()
        })
        .collect()
}

/// The two channels' responses of each pole, kept while one pole at a
/// time is searched.
struct Problem<'a> {
    data: &'a Measured,
    load_cell: &'a Frf,
    period_s: f64,
    pole_rad_s: f64,
    wx: Vec<f64>,
    wf: Vec<f64>,
    x: Vec<Vec<Complex64>>,
    f: Vec<Vec<Complex64>>,
}

impl Problem<'_> {
    /// Put `pole` in place `i` (or at the end).
    fn set(&mut self, i: usize, pole: Pole) -> Option<()> {
        let b = basis(
            pole,
            self.pole_rad_s,
            self.period_s,
            &self.data.position.freq_hz,
        )?;
        let (x, f) = b.into_iter().unzip();
        if i == self.x.len() {
            self.x.push(x);
            self.f.push(f);
        } else {
            self.x[i] = x;
            self.f[i] = f;
        }
        Some(())
    }

    /// The projected cost with pole `i` replaced by `pole`, if given, and
    /// the residues of both channels.
    fn solve(&self, swap: Option<(usize, Pole)>) -> Option<(f64, DVector<f64>, DVector<f64>)> {
        let new = match swap {
            Some((_, p)) => Some(basis(
                p,
                self.pole_rad_s,
                self.period_s,
                &self.data.position.freq_hz,
            )?),
            None => None,
        };
        let (nx, nf): (Vec<Complex64>, Vec<Complex64>) =
            new.map(|b| b.into_iter().unzip()).unwrap_or_default();
        let xs: Vec<&[Complex64]> = (0..self.x.len())
            .map(|k| match swap {
                Some((i, _)) if i == k => nx.as_slice(),
                _ => self.x[k].as_slice(),
            })
            .collect();
        let fs: Vec<&[Complex64]> = (0..self.f.len())
            .map(|k| match swap {
                Some((i, _)) if i == k => nf.as_slice(),
                _ => self.f[k].as_slice(),
            })
            .collect();
        let (rx, cx) = project(&xs, &self.data.position.response, &self.wx)?;
        let (rf, cf) = project(&fs, &self.load_cell.response, &self.wf)?;
        Some((cx + cf, rx, rf))
    }
}

/// The start of a modal fit with `omegas.len()` modes, from the rigid
/// body's mass and damping (kg, N s/m) and the resonances seen (rad/s);
/// `None` if the projection finds no physical model.
pub fn modal_start(
    data: &Measured,
    period_s: f64,
    pole_rad_s: f64,
    rigid: (f64, f64),
    omegas: &[f64],
) -> Option<Modal> {
    let load_cell = data.load_cell.as_ref()?;
    let mut pr = Problem {
        data,
        load_cell,
        period_s,
        pole_rad_s,
        wx: weights(&data.position.response, &data.position.variance),
        wf: weights(&load_cell.response, &load_cell.variance),
        x: Vec::new(),
        f: Vec::new(),
    };
    let mut omega: Vec<f64> = omegas.to_vec();
    let mut zeta = vec![0.02; omega.len()];
    pr.set(
        0,
        Pole {
            a1: rigid.1 / rigid.0,
            a0: 0.0,
        },
    )?;
    for (i, w) in omega.iter().enumerate() {
        pr.set(i + 1, Pole::mode(*w, zeta[i]))?;
    }
    let mut best = pr.solve(None)?.0;
    // Coordinate search, one mode's frequency then its damping, coarse to
    // fine: the projected cost is smooth in each, with one valley near the
    // peak that started it.
    for (span, log_zeta, steps) in [(0.015, 3.0, 7), (0.002, 0.3, 3)] {
        for _sweep in 0..2 {
            for i in 0..omega.len() {
                let (w0, z0) = (omega[i], zeta[i]);
                for s in -steps..=steps {
                    let w = w0 * (1.0 + span * s as f64 / steps as f64);
                    if let Some((c, ..)) = pr.solve(Some((i + 1, Pole::mode(w, zeta[i])))) {
                        if c < best {
                            best = c;
                            omega[i] = w;
                        }
                    }
                }
                for s in -steps..=steps {
                    let z = (z0 * (log_zeta * s as f64 / steps as f64).exp()).clamp(1e-4, 0.9);
                    if let Some((c, ..)) = pr.solve(Some((i + 1, Pole::mode(omega[i], z)))) {
                        if c < best {
                            best = c;
                            zeta[i] = z;
                        }
                    }
                }
                pr.set(i + 1, Pole::mode(omega[i], zeta[i]))?;
            }
        }
    }
    let (_, rx, rf) = pr.solve(None)?;
    // x: residues φ_a²; the load cell: −sign m_h φ_a φ_s (see `Modal`).
    let mass_kg = 1.0 / rx[0];
    if !(mass_kg.is_finite() && mass_kg > 0.0) {
        return None;
    }
    let sign = if rf[0] < 0.0 { 1.0 } else { -1.0 };
    let handle_kg = (rf[0].abs() * mass_kg).clamp(1e-4 * mass_kg, 0.5 * mass_kg);
    let modes = omega
        .iter()
        .zip(&zeta)
        .enumerate()
        .map(|(i, (w, z))| {
            let actuator = rx[i + 1].max(1e-6 * rx[0]).sqrt();
            ModeShape {
                mode: Mode {
                    omega_n: *w,
                    zeta: *z,
                },
                actuator,
                load_cell: -rf[i + 1] / (sign * handle_kg * actuator),
            }
        })
        .collect();
    let (load_cell_npm, load_cell_nspm) = super::modal::flexure(handle_kg, period_s);
    // The ground's damping shared as the mass is: the load cell then reads
    // the handle's share of the push at low frequency, in phase with it.
    let handle_nspm = rigid.1 * handle_kg / mass_kg;
    Some(Modal {
        mass_kg,
        damping_nspm: rigid.1 - handle_nspm,
        handle_kg,
        handle_nspm,
        load_cell_npm,
        load_cell_nspm,
        load_cell_sign: sign,
        coupling: vec![0.0; omega.len() * (omega.len() + 1) / 2],
        bypass_npm: None,
        modes,
    })
}
