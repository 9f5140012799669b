//! The physical model a fit adjusts when a load cell watches the handle:
//! the device's own modes (a rigid body and `r` flexible modes, mass
//! normalised), seen at the actuator and at the load cell's point of the
//! structure, with the handle's mass hung from that point on the load
//! cell's stiff flexure.
//!
//! In modal coordinates `η`, the actuator is at `x_a = φ_aᵀ η` and the
//! load cell's point at `x_s = φ_sᵀ η`; the rigid body's entries are both
//! `1/√m` (m the whole device's mass). The handle (`m_h`, coordinate
//! `q_h`) is part of the modes, so its mass is taken back out of the
//! structure's, `I − m_h φ_s φ_sᵀ`, and put on its own coordinate, joined
//! to `x_s` by the flexure (`k_lc`, `d_lc`). As `k_lc` grows, the model
//! tends to the modes themselves, with the load cell reading
//! `k_lc (q_h − x_s)`, the force that moves the handle.
//!
//! Unlike a chain, this form does not assume where along the structure the
//! handle sits: a mode may move the handle more, less or opposite to the
//! actuator, as it does on a linkage or a coupled transmission.
//!
//! Fitted with a loaded record too, the form may hold the handle by a
//! second path, a spring straight to the actuator beside the load cell
//! ([`Modal::bypass_npm`]): what the load cell does not read, and an
//! admittance display depends on.

use nalgebra::{DMatrix, DVector};
use twoport_design::plant::Mode;
use twoport_design::DeviceModel;

use super::chain::ModelBase;

/// One flexible mode and its shape at the two points the fit sees.
#[derive(Clone, Debug, PartialEq)]
pub struct ModeShape {
    /// The mode: its natural frequency (rad/s) and damping ratio.
    pub mode: Mode,
    /// The mode's amplitude at the actuator (1/√kg; positive by choice of
    /// the mode's sign).
    pub actuator: f64,
    /// Its amplitude at the load cell's point (1/√kg, either sign).
    pub load_cell: f64,
}

/// A modal model with the handle on a load cell. Units are SI.
#[derive(Clone, Debug, PartialEq)]
pub struct Modal {
    /// The whole device's mass (kg).
    pub mass_kg: f64,
    /// Its damping to ground (N s/m) before the load cell, on the rigid
    /// body.
    pub damping_nspm: f64,
    /// The handle's mass, past the load cell (kg).
    pub handle_kg: f64,
    /// The handle's damping to ground (N s/m), past the load cell: the
    /// load cell reads it at low frequency, and an admittance display
    /// depends on it there.
    pub handle_nspm: f64,
    /// The load cell's flexure (N/m).
    pub load_cell_npm: f64,
    /// Its damping (N s/m).
    pub load_cell_nspm: f64,
    /// `+1` if the load cell reads `k_lc (q_h − x_s)`, `−1` if the opposite.
    pub load_cell_sign: f64,
    /// The flexible modes, in no particular order.
    pub modes: Vec<ModeShape>,
    /// Damping that couples the modes (the rigid body first), as a share
    /// of the geometric mean of the two modes' own: `ρ_ij` for each pair
    /// `i < j`, row by row. Zero is proportional damping; a device's
    /// joints and grip rarely give it, and a lightly damped mode's
    /// residue is complex when they do not.
    pub coupling: Vec<f64>,
    /// A spring from the handle straight to the actuator (N/m), beside
    /// the load cell, which does not read what it carries; `None` where
    /// the fit has none. The actuator's own motion barely stretches it,
    /// so only an experiment that moves the handle's side (a known mass
    /// on the handle) can place it; an admittance display, which reads
    /// the hand's force by the load cell, depends on it.
    pub bypass_npm: Option<f64>,
}

/// Pairs of modal coordinates (the rigid body's included) for `r` modes.
fn pairs(r: usize) -> usize {
    (r + 1) * r / 2
}

/// Parameters a fit moves per mode.
const PER_MODE: usize = 4;
/// Parameters a fit moves besides the modes.
const GLOBAL: usize = 4;

/// The load cell's flexure a fit puts in: at five times Nyquist for the
/// handle's mass, 5% damped (N/m, N s/m). An experiment cannot place a
/// flexure past its band, and a design does not need it to: on the
/// Excalibur, any flexure from 10^7 to 10^10 N/m moves the design by less
/// than 0.01%.
pub fn flexure(handle_kg: f64, period_s: f64) -> (f64, f64) {
    let w = std::f64::consts::TAU * 5.0 / (2.0 * period_s);
    (handle_kg * w * w, 2.0 * 0.05 * handle_kg * w)
}

impl Modal {
    /// The parameters a fit moves: logarithms of every positive quantity,
    /// and each mode's load-cell amplitude times `√m` as it is. The
    /// flexure is not among them (see [`flexure`]).
    pub fn to_params(&self) -> DVector<f64> {
        let mut v = vec![
            self.mass_kg.ln(),
            self.damping_nspm.max(1e-300).ln(),
            self.handle_kg.ln(),
            self.handle_nspm.max(1e-300).ln(),
        ];
        let root = self.mass_kg.sqrt();
        for m in &self.modes {
            v.extend([
                m.mode.omega_n.ln(),
                m.mode.zeta.max(1e-300).ln(),
                (m.actuator * root).max(1e-300).ln(),
                m.load_cell * root,
            ]);
        }
        v.extend(&self.coupling);
        v.extend(self.bypass_npm.map(f64::ln));
        DVector::from_vec(v)
    }

    /// The model from [`to_params`](Self::to_params)'s form, with the
    /// [`flexure`] for a sample period of `period_s`; `bypass` says
    /// whether the last parameter is the [bypass](Self::bypass_npm)'s.
    pub fn from_params(
        p: &DVector<f64>,
        load_cell_sign: f64,
        period_s: f64,
        bypass: bool,
    ) -> Modal {
        let e = |i: usize| p[i].exp();
        let mass_kg = e(0);
        let root = mass_kg.sqrt();
        let bypass_npm = bypass.then(|| e(p.len() - 1));
        let own = p.len() - usize::from(bypass);
        // own = GLOBAL + PER_MODE r + r (r + 1) / 2.
        let r = (0..)
            .find(|r| GLOBAL + PER_MODE * r + pairs(*r) >= own)
            .unwrap_or(0);
        let modes = (0..r)
            .map(|i| {
                let at = GLOBAL + PER_MODE * i;
                ModeShape {
                    mode: Mode {
                        omega_n: e(at),
                        zeta: e(at + 1),
                    },
                    actuator: e(at + 2) / root,
                    load_cell: p[at + 3] / root,
                }
            })
            .collect();
        let handle_kg = e(2);
        let (load_cell_npm, load_cell_nspm) = flexure(handle_kg, period_s);
        Modal {
            mass_kg,
            damping_nspm: e(1),
            handle_kg,
            handle_nspm: e(3),
            load_cell_npm,
            load_cell_nspm,
            load_cell_sign,
            modes,
            coupling: p.as_slice()[GLOBAL + PER_MODE * r..own].to_vec(),
            bypass_npm,
        }
    }

    /// The model in the model-file form; `None` if the numbers make no
    /// valid model (the handle heavier than the structure can carry in
    /// some mode, or a number not finite).
    pub fn model(&self, base: &ModelBase) -> Option<DeviceModel> {
        let r = self.modes.len();
        let n = r + 2;
        let h = n - 1;
        let root = self.mass_kg.sqrt();
        let mut phi_a = DVector::zeros(r + 1);
        let mut phi_s = DVector::zeros(r + 1);
        phi_a[0] = 1.0 / root;
        phi_s[0] = 1.0 / root;
        for (i, m) in self.modes.iter().enumerate() {
            phi_a[i + 1] = m.actuator;
            phi_s[i + 1] = m.load_cell;
        }
        let mut mm = DMatrix::identity(n, n);
        let carried = &phi_s * phi_s.transpose() * self.handle_kg;
        for i in 0..=r {
            for j in 0..=r {
                mm[(i, j)] -= carried[(i, j)];
            }
        }
        mm[(h, h)] = self.handle_kg;
        // ψ: the flexure's stretch, q_h − x_s, per coordinate.
        let mut psi = DVector::zeros(n);
        psi.rows_mut(0, r + 1).copy_from(&(-&phi_s));
        psi[h] = 1.0;
        let flex = &psi * psi.transpose();
        let mut k = &flex * self.load_cell_npm;
        if let Some(kb) = self.bypass_npm {
            // Its stretch, q_h - x_a.
            let mut beta = DVector::zeros(n);
            beta.rows_mut(0, r + 1).copy_from(&(-&phi_a));
            beta[h] = 1.0;
            k += &beta * beta.transpose() * kb;
        }
        let mut d = &flex * self.load_cell_nspm;
        d[(h, h)] += self.handle_nspm;
        let mut own = vec![self.damping_nspm / self.mass_kg];
        for m in &self.modes {
            own.push(2.0 * m.mode.zeta * m.mode.omega_n);
        }
        let mut modal = DMatrix::from_diagonal(&DVector::from_vec(own.clone()));
        let mut rho = self.coupling.iter();
        for i in 0..=r {
            for j in i + 1..=r {
                let c = rho.next().copied().unwrap_or(0.0) * (own[i] * own[j]).sqrt();
                modal[(i, j)] = c;
                modal[(j, i)] = c;
            }
        }
        // Damping must dissipate: the modal block positive semidefinite.
        let tiny = DMatrix::identity(r + 1, r + 1) * (1e-12 * modal.norm());
        (&modal + tiny).cholesky()?;
        for i in 0..=r {
            for j in 0..=r {
                d[(i, j)] += modal[(i, j)];
            }
        }
        for (i, m) in self.modes.iter().enumerate() {
            k[(i + 1, i + 1)] += m.mode.omega_n * m.mode.omega_n;
        }
        let mut g = DMatrix::zeros(n, 2);
        g[(h, 0)] = 1.0;
        let mut c_v = DMatrix::zeros(2, n);
        c_v[(0, h)] = 1.0;
        for i in 0..=r {
            g[(i, 1)] = -phi_a[i];
            c_v[(1, i)] = -phi_a[i];
        }
        let c_f = DMatrix::from_row_slice(
            1,
            n,
            (psi * (self.load_cell_sign * self.load_cell_npm)).as_slice(),
        );
        let finite = mm.iter().chain(&k).chain(&d).all(|v| v.is_finite());
        if !finite || mm.clone().cholesky().is_none() {
            return None;
        }
        Some(DeviceModel {
            name: base.name.clone(),
            period_s: base.period_s,
            load_cell_pole_rad_s: base
                .load_cell_pole_rad_s
                .unwrap_or(twoport_design::model::DEFAULT_LOAD_CELL_POLE_RAD_S),
            peak_force_n: base.peak_force_n,
            continuous_force_n: base.continuous_force_n,
            m: mm,
            d,
            k,
            g,
            c_v,
            c_f,
            force_sensor: true,
            delay_samples: 0,
            latency_s: 0.0,
            encoder_quantum_m: None,
            coulomb_friction_n: None,
        })
    }
}
