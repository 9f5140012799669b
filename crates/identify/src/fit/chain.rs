//! The physical model a fit adjusts: a chain of masses from the actuator
//! (the encoder's) to the handle, springs and dampers between neighbours,
//! a damper to ground at each end, at most one spring to ground (a return
//! spring, a flexure to the frame) at any mass, and the load cell, if any,
//! in the last spring. Written in the model-file form (`M`, `D`, `K`, `G`, `C_v`,
//! `C_f`) that `twoport design` reads.

use nalgebra::{DMatrix, DVector};
use twoport_design::DeviceModel;

/// A chain of `n` masses (`n - 1` modes). Units are SI.
#[derive(Clone, Debug, PartialEq)]
pub struct Chain {
    /// Masses from the actuator to the handle (kg).
    pub masses_kg: Vec<f64>,
    /// Springs between neighbours (N/m).
    pub springs_npm: Vec<f64>,
    /// Dampers between neighbours (N s/m).
    pub links_nspm: Vec<f64>,
    /// Damper from the actuator's mass to ground (N s/m).
    pub actuator_nspm: f64,
    /// Damper from the handle's mass to ground (N s/m; none for a single
    /// mass, whose one damper is the actuator's).
    pub handle_nspm: f64,
    /// The load cell's sign: `+1` reads `k (q_handle - q_before)`.
    pub load_cell_sign: f64,
    /// A spring from one mass to the frame, if the device has one.
    pub ground: Option<Ground>,
}

/// A spring from a mass of the chain to the frame: a centring or return
/// spring, a flexure or cable anchored to the frame, gravity on an arm
/// about its pose. Units are SI.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ground {
    /// The mass it holds, counted from the actuator's (0).
    pub at: usize,
    /// Its stiffness (N/m).
    pub npm: f64,
}

/// What a model needs beside its dynamics: the board's and the
/// amplifier's numbers, which an experiment does not measure.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelBase {
    /// The model's name.
    pub name: String,
    /// The controller's sample period (s).
    pub period_s: f64,
    /// The amplifier's peak force (N).
    pub peak_force_n: f64,
    /// Its continuous force (N).
    pub continuous_force_n: f64,
    /// The load cell's filter pole (rad/s), if the device has one.
    pub load_cell_pole_rad_s: Option<f64>,
}

impl Chain {
    /// Modes: one fewer than the masses.
    pub fn modes(&self) -> usize {
        self.masses_kg.len() - 1
    }

    /// The parameters a fit moves: the logarithms of every mass, spring
    /// and damper, so that each stays positive; the spring to ground, if
    /// any, last.
    pub fn to_log(&self) -> DVector<f64> {
        let mut v: Vec<f64> = Vec::new();
        v.extend(&self.masses_kg);
        v.extend(&self.springs_npm);
        v.extend(&self.links_nspm);
        v.push(self.actuator_nspm);
        if self.modes() > 0 {
            v.push(self.handle_nspm);
        }
        v.extend(self.ground.map(|g| g.npm));
        DVector::from_iterator(v.len(), v.iter().map(|x| x.max(1e-300).ln()))
    }

    /// The chain of `masses` masses, held to the frame at mass
    /// `ground_at` if given, from [`to_log`](Self::to_log)'s form.
    pub fn from_log(
        masses: usize,
        ground_at: Option<usize>,
        p: &DVector<f64>,
        load_cell_sign: f64,
    ) -> Chain {
        let e: Vec<f64> = p.iter().map(|x| x.exp()).collect();
        let n = masses;
        Chain {
            ground: ground_at.map(|at| Ground {
                at,
                npm: e[e.len() - 1],
            }),
            masses_kg: e[..n].to_vec(),
            springs_npm: e[n..2 * n - 1].to_vec(),
            links_nspm: e[2 * n - 1..3 * n - 2].to_vec(),
            actuator_nspm: e[3 * n - 2],
            handle_nspm: if n > 1 { e[3 * n - 1] } else { 0.0 },
            load_cell_sign,
        }
    }

    /// The chain in the model-file form; `None` if the numbers make no
    /// valid model.
    pub fn model(&self, base: &ModelBase) -> Option<DeviceModel> {
        let n = self.masses_kg.len();
        let m = DMatrix::from_diagonal(&DVector::from_column_slice(&self.masses_kg));
        let mut d = DMatrix::zeros(n, n);
        let mut k = DMatrix::zeros(n, n);
        for i in 0..n - 1 {
            for (a, v) in [(&mut k, self.springs_npm[i]), (&mut d, self.links_nspm[i])] {
                a[(i, i)] += v;
                a[(i + 1, i + 1)] += v;
                a[(i, i + 1)] -= v;
                a[(i + 1, i)] -= v;
            }
        }
        d[(0, 0)] += self.actuator_nspm;
        if n > 1 {
            d[(n - 1, n - 1)] += self.handle_nspm;
        }
        if let Some(gr) = self.ground {
            if gr.at >= n || !gr.npm.is_finite() {
                return None;
            }
            k[(gr.at, gr.at)] += gr.npm;
        }
        let mut g = DMatrix::zeros(n, 2);
        g[(n - 1, 0)] = 1.0;
        g[(0, 1)] = -1.0;
        let mut c_v = DMatrix::zeros(2, n);
        c_v[(0, n - 1)] = 1.0;
        c_v[(1, 0)] = -1.0;
        let sensor = base.load_cell_pole_rad_s.filter(|_| n > 1);
        let mut c_f = DMatrix::zeros(1, n);
        if sensor.is_some() {
            let s = self.load_cell_sign * self.springs_npm[n - 2];
            c_f[(0, n - 1)] = s;
            c_f[(0, n - 2)] = -s;
        }
        let finite = self
            .masses_kg
            .iter()
            .chain(&self.springs_npm)
            .chain(&self.links_nspm)
            .chain([&self.actuator_nspm, &self.handle_nspm])
            .all(|v| v.is_finite());
        if !finite {
            return None;
        }
        Some(DeviceModel {
            name: base.name.clone(),
            period_s: base.period_s,
            load_cell_pole_rad_s: sensor
                .unwrap_or(twoport_design::model::DEFAULT_LOAD_CELL_POLE_RAD_S),
            peak_force_n: base.peak_force_n,
            continuous_force_n: base.continuous_force_n,
            m,
            d,
            k,
            g,
            c_v,
            c_f,
            force_sensor: sensor.is_some(),
            delay_samples: 0,
            latency_s: 0.0,
            encoder_quantum_m: None,
            coulomb_friction_n: None,
        })
    }
}
