//! The device as a linear state-space model `x' = A x + B u (+ E F_nl)`,
//! with the human's grasp folded in; its `Stepper` advances it.
//!
//! State `x = [q, q', w]`: the model's coordinates (m), their velocities
//! (m/s) and, with the load-cell effect, the filtered strain-gauge force `w`
//! (N). Inputs `u = [f_ext, f_a]`: the hand's held force term on the handle
//! (N) and the held actuator force (N, positive resisting actuator motion).
//! `F_nl` is a force vector on the coordinates from nonlinear effects.

mod stepper;

pub use stepper::{Method, Nonlinear, Stepper};

use crate::Error;
use nalgebra::{Cholesky, DMatrix};
use twoport_design::DeviceModel;

/// The grasp's impedance `b + k/s` between the handle and the hand, and
/// optionally a passive arm behind it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grasp {
    /// Damping (N s/m).
    pub damping_nspm: f64,
    /// Stiffness (N/m).
    pub stiffness_npm: f64,
    /// The arm `Z_p` behind the grasp (paper Fig. 3): without it the grasp
    /// ends at the moving hand; with it the grasp ends at a node of mass
    /// `m` held to the (still) hand by its own spring and damper, so the
    /// human is `Z_max` in series with an arbitrary passive `Z_p`.
    pub arm: Option<Arm>,
}

/// A passive mass-spring-damper arm behind the grasp.
#[derive(Clone, Copy, Debug, PartialEq, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Arm {
    /// Node mass (kg), > 0.
    pub mass_kg: f64,
    /// Damping to the hand (N s/m).
    pub damping_nspm: f64,
    /// Stiffness to the hand (N/m).
    pub stiffness_npm: f64,
}

/// How the strain gauge sees the handle force.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Gauge {
    /// The flexible model's `C_f q`.
    Model,
    /// The rigid reduction: the gauge reads the hand force itself.
    HandForce,
}

/// A device model ready for simulation.
#[derive(Clone, Debug)]
pub struct SimDevice {
    /// Coordinates.
    pub n: usize,
    m: DMatrix<f64>,
    minv: DMatrix<f64>,
    d: DMatrix<f64>,
    k: DMatrix<f64>,
    g: DMatrix<f64>,
    /// Handle row of `C_v` (positions and velocities alike).
    pub handle: Vec<f64>,
    /// Actuator row: `x_a = actuator . q` (minus `C_v`'s second row).
    pub actuator: Vec<f64>,
    c_f: Vec<f64>,
    gauge: Gauge,
    pole: f64,
    /// A human-readable name.
    pub name: String,
}

impl SimDevice {
    /// The flexible model of a designer model file.
    pub fn flexible(model: &DeviceModel) -> Result<Self, Error> {
        let n = model.dof();
        let minv = Cholesky::new(model.m.clone())
            .ok_or("M is not positive definite")?
            .inverse();
        Ok(SimDevice {
            n,
            m: model.m.clone(),
            minv,
            d: model.d.clone(),
            k: model.k.clone(),
            g: model.g.clone(),
            handle: (0..n).map(|j| model.c_v[(0, j)]).collect(),
            actuator: (0..n).map(|j| -model.c_v[(1, j)]).collect(),
            c_f: (0..n).map(|j| model.c_f[(0, j)]).collect(),
            gauge: Gauge::Model,
            pole: model.load_cell_pole_rad_s,
            name: model.name.clone(),
        })
    }

    /// The rigid one-coordinate reduction: mass `m_kg`, damping `b_nspm`
    /// to ground, handle and actuator at one point; the gauge reads the hand
    /// force through the load-cell filter.
    pub fn rigid(m_kg: f64, b_nspm: f64, load_cell_pole_rad_s: f64) -> Self {
        SimDevice {
            n: 1,
            m: DMatrix::from_element(1, 1, m_kg),
            minv: DMatrix::from_element(1, 1, 1.0 / m_kg),
            d: DMatrix::from_element(1, 1, b_nspm),
            k: DMatrix::zeros(1, 1),
            g: DMatrix::from_row_slice(1, 2, &[1.0, -1.0]),
            handle: vec![1.0],
            actuator: vec![1.0],
            c_f: vec![0.0],
            gauge: Gauge::HandForce,
            pole: load_cell_pole_rad_s,
            name: format!("rigid {m_kg} kg, {b_nspm} N s/m"),
        }
    }

    /// `M[i][j]` (kg).
    pub fn mass(&self, i: usize, j: usize) -> f64 {
        self.m[(i, j)]
    }

    /// `K[i][j]` (N/m).
    pub fn stiffness(&self, i: usize, j: usize) -> f64 {
        self.k[(i, j)]
    }

    /// Set the damping matrix to zero (for energy tests).
    pub fn without_damping(mut self) -> Self {
        self.d.fill(0.0);
        self
    }

    /// Kinetic plus elastic energy of the device in state `x` (J).
    pub fn energy(&self, x: &[f64]) -> f64 {
        let n = self.n;
        let (q, v) = (&x[..n], &x[n..2 * n]);
        // M and K are symmetric: column-major slices read as rows.
        let quad = |m: &DMatrix<f64>, y: &[f64]| -> f64 {
            m.as_slice()
                .chunks_exact(n)
                .zip(y)
                .map(|(row, yi)| yi * row.iter().zip(y).map(|(a, b)| a * b).sum::<f64>())
                .sum()
        };
        0.5 * (quad(&self.m, v) + quad(&self.k, q))
    }

    /// The continuous system with the grasp folded in.
    pub fn system(&self, grasp: Grasp, load_cell: bool) -> System {
        let n = self.n;
        let arm_at = 2 * n + usize::from(load_cell);
        let ns = arm_at + if grasp.arm.is_some() { 2 } else { 0 };
        let h = &self.handle;
        let mut kt = self.k.clone();
        let mut dt = self.d.clone();
        for i in 0..n {
            for j in 0..n {
                // f_h = k_h (x_hand - x_h) + b_h (v_hand - v_h) acts on the
                // handle through G's first column.
                let gi = self.g[(i, 0)];
                kt[(i, j)] += gi * grasp.stiffness_npm * h[j];
                dt[(i, j)] += gi * grasp.damping_nspm * h[j];
            }
        }
        let mk = &self.minv * &kt;
        let md = &self.minv * &dt;
        let mg = &self.minv * &self.g;
        let mut a = DMatrix::<f64>::zeros(ns, ns);
        let mut b = DMatrix::<f64>::zeros(ns, 2);
        let mut e = DMatrix::<f64>::zeros(ns, n);
        for i in 0..n {
            a[(i, n + i)] = 1.0;
            for j in 0..n {
                a[(n + i, j)] = -mk[(i, j)];
                a[(n + i, n + j)] = -md[(i, j)];
                e[(n + i, j)] = self.minv[(i, j)];
            }
            b[(n + i, 0)] = mg[(i, 0)];
            b[(n + i, 1)] = mg[(i, 1)];
        }
        let (kg, bg) = (grasp.stiffness_npm, grasp.damping_nspm);
        if let Some(arm) = grasp.arm {
            // The grasp pulls the handle toward the node, not the hand:
            // f_h = k_g (x_n - x_h) + b_g (v_n - v_h).
            let (xn, vn) = (arm_at, arm_at + 1);
            for i in 0..n {
                a[(n + i, xn)] += mg[(i, 0)] * kg;
                a[(n + i, vn)] += mg[(i, 0)] * bg;
            }
            let m = arm.mass_kg;
            a[(xn, vn)] = 1.0;
            for j in 0..n {
                a[(vn, j)] = kg * h[j] / m;
                a[(vn, n + j)] = bg * h[j] / m;
            }
            a[(vn, xn)] = -(kg + arm.stiffness_npm) / m;
            a[(vn, vn)] = -(bg + arm.damping_nspm) / m;
        }
        if load_cell {
            let p = self.pole;
            let w = 2 * n;
            a[(w, w)] = -p;
            match self.gauge {
                Gauge::Model => {
                    for j in 0..n {
                        a[(w, j)] = p * self.c_f[j];
                    }
                }
                Gauge::HandForce => {
                    for j in 0..n {
                        a[(w, j)] = -p * kg * h[j];
                        a[(w, n + j)] = -p * bg * h[j];
                    }
                    if grasp.arm.is_some() {
                        a[(w, arm_at)] = p * kg;
                        a[(w, arm_at + 1)] = p * bg;
                    }
                    b[(w, 0)] = p;
                }
            }
        }
        System { n, a, b, e }
    }
}

/// `x' = A x + B u + E F_nl`.
#[derive(Clone, Debug)]
pub struct System {
    /// Coordinates.
    pub n: usize,
    /// State matrix.
    pub a: DMatrix<f64>,
    /// Input matrix for `[f_ext, f_a]`.
    pub b: DMatrix<f64>,
    /// Input matrix for a force vector on the coordinates.
    pub e: DMatrix<f64>,
}

impl System {
    /// State dimension.
    pub fn states(&self) -> usize {
        self.a.nrows()
    }

    /// Eigenvalues of `A` (rad/s), or `None` where they cannot be found.
    pub fn poles(&self) -> Option<Vec<nalgebra::Complex<f64>>> {
        twoport_design::linalg::eigenvalues(&self.a)
    }
}
