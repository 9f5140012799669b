//! A linkage's nonlinear rigid-body dynamics in joint space:
//! `M(q) q'' + c(q, q') + g(q) + D q' + f_c(q') = -τ_a + J(q)^T f_h`.
//!
//! `M(q)` is the device file's mass matrix (links and reflected rotors),
//! `c` the Coriolis and centrifugal terms from its derivatives
//! (`c = M' q' - ½ ∂(q'^T M q')/∂q`, by central differences), `g` the
//! gravity on the moving masses (a lumped handle mass, or the serial arm's
//! links), `D` the joints' viscous damping and
//! `f_c` their Coulomb friction (smoothed over a small speed). `τ_a` is the
//! motors' torque as the servo gives it (positive resisting positive joint
//! motion) and `f_h` the hand's force on the handle (N). Integrated by
//! fourth-order Runge-Kutta at a fixed sub-step.

use crate::Error;
use nalgebra::{DMatrix, DVector};
use twoport_design::linkage::{forward, LinkageFile};

/// The hand on a linkage's handle, in Cartesian space: a spring to an
/// anchor and a damper, each a symmetric matrix (a passive N-port hand
/// when both are positive semi-definite).
#[derive(Clone, Debug, PartialEq)]
pub struct CartesianHand {
    /// The anchor the spring pulls toward (m).
    pub anchor_m: Vec<f64>,
    /// Stiffness (N/m).
    pub k_npm: DMatrix<f64>,
    /// Damping (N s/m).
    pub b_nspm: DMatrix<f64>,
}

impl CartesianHand {
    /// No hand: the handle is free.
    pub fn off(n: usize) -> Self {
        CartesianHand {
            anchor_m: vec![0.0; n],
            k_npm: DMatrix::zeros(n, n),
            b_nspm: DMatrix::zeros(n, n),
        }
    }

    /// A grasp that damps every direction by `b_nspm` (N s/m) and holds
    /// every direction but the unit vector `free` with `k_npm` (N/m)
    /// toward `anchor_m`: the hand that leaves the device one direction.
    pub fn holding(anchor_m: &[f64], free: &[f64], k_npm: f64, b_nspm: f64) -> Self {
        let n = free.len();
        let u = DVector::from_column_slice(free);
        let p = DMatrix::identity(n, n) - &u * u.transpose();
        CartesianHand {
            anchor_m: anchor_m.to_vec(),
            k_npm: p * k_npm,
            b_nspm: DMatrix::identity(n, n) * b_nspm,
        }
    }

    /// The hand's force on the handle (N) at position `x` (m) and
    /// velocity `v` (m/s).
    pub fn force(&self, x: &[f64], v: &[f64]) -> DVector<f64> {
        let dx = DVector::from_iterator(x.len(), x.iter().zip(&self.anchor_m).map(|(a, b)| a - b));
        -(&self.k_npm * dx) - &self.b_nspm * DVector::from_column_slice(v)
    }
}

/// The hand's force on the handle (N) given the handle's position (m) and
/// velocity (m/s).
pub type HandForce<'a> = dyn Fn(&[f64], &[f64]) -> DVector<f64> + 'a;

/// A linkage's state and its dynamics.
#[derive(Clone, Debug)]
pub struct LinkagePlant {
    file: LinkageFile,
    /// Joint angles (rad).
    pub q: DVector<f64>,
    /// Joint rates (rad/s).
    pub qd: DVector<f64>,
    /// Gravity along `-z` (m/s²) on the moving masses; 0 leaves it out.
    pub gravity_mps2: f64,
    /// Whether the joints' Coulomb friction acts.
    pub friction: bool,
}

/// The speed (rad/s) over which Coulomb friction rises to its level.
const FRICTION_SPEED: f64 = 1e-3;

impl LinkagePlant {
    /// The linkage at rest at `q` (rad): no gravity, no friction until
    /// asked for.
    pub fn at_rest(file: &LinkageFile, q: &[f64]) -> Self {
        LinkagePlant {
            file: file.clone(),
            q: DVector::from_column_slice(q),
            qd: DVector::zeros(q.len()),
            gravity_mps2: 0.0,
            friction: false,
        }
    }

    /// The device file it integrates.
    pub fn file(&self) -> &LinkageFile {
        &self.file
    }

    /// The handle's position (m) and the Jacobian at `q`.
    pub fn kinematics(&self, q: &DVector<f64>) -> Result<(Vec<f64>, DMatrix<f64>), Error> {
        forward(&self.file.geometry, q.as_slice()).map_err(|_| Error::Pose(q.as_slice().to_vec()))
    }

    fn mass(&self, q: &DVector<f64>) -> Result<DMatrix<f64>, Error> {
        let (_, j) = self.kinematics(q)?;
        Ok(self.file.joint_mass(q.as_slice(), &j))
    }

    /// The torques gravity asks (N m): the device file's moving masses
    /// (a lumped handle's, or the serial arm's links).
    fn gravity(&self, q: &DVector<f64>, j: &DMatrix<f64>) -> DVector<f64> {
        if self.gravity_mps2 == 0.0 {
            return DVector::zeros(q.len());
        }
        DVector::from_vec(self.file.gravity_nm(q.as_slice(), j, self.gravity_mps2))
    }

    /// The moving masses' potential energy under gravity (J).
    pub fn potential_j(&self) -> Result<f64, Error> {
        let (x, _) = self.kinematics(&self.q)?;
        let z = x.get(2).copied().unwrap_or(0.0);
        Ok(self
            .file
            .potential_j(self.q.as_slice(), z, self.gravity_mps2))
    }

    /// `q''` at `(q, q')` under motor torques `tau_a` (N m, resisting) and
    /// `hand`.
    fn accel(
        &self,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        tau_a: &DVector<f64>,
        hand: &HandForce,
    ) -> Result<DVector<f64>, Error> {
        let n = q.len();
        let (x, j) = self.kinematics(q)?;
        let m = self.file.joint_mass(q.as_slice(), &j);
        // c = M' q' - ½ ∂(q'^T M q')/∂q, each ∂M/∂q_k by a central difference.
        let h = 1e-6;
        let mut m_dot = DMatrix::zeros(n, n);
        let mut half_grad = DVector::zeros(n);
        for k in 0..n {
            let (mut up, mut down) = (q.clone(), q.clone());
            up[k] += h;
            down[k] -= h;
            let dm = (self.mass(&up)? - self.mass(&down)?) / (2.0 * h);
            m_dot += &dm * qd[k];
            half_grad[k] = 0.5 * qd.dot(&(&dm * qd));
        }
        let coriolis = m_dot * qd - half_grad;
        let damping = DVector::from_fn(n, |i, _| self.file.joints.damping_nmsprad[i] * qd[i]);
        let friction = if self.friction {
            DVector::from_fn(n, |i, _| {
                self.file.joints.friction_nm[i] * (qd[i] / FRICTION_SPEED).tanh()
            })
        } else {
            DVector::zeros(n)
        };
        let v = &j * qd;
        let hand_torque = j.transpose() * hand(&x, v.as_slice());
        let rhs = hand_torque - tau_a - coriolis - self.gravity(q, &j) - damping - friction;
        m.cholesky()
            .map(|c| c.solve(&rhs))
            .ok_or_else(|| Error::Pose(q.as_slice().to_vec()))
    }

    /// Advance `dt` (s) in `substeps` fourth-order Runge-Kutta steps with
    /// the motors holding `tau_a` (N m, resisting) throughout.
    pub fn step(
        &mut self,
        tau_a: &[f64],
        hand: &CartesianHand,
        dt: f64,
        substeps: u32,
    ) -> Result<(), Error> {
        self.step_with(tau_a, &|x, v| hand.force(x, v), dt, substeps)
    }

    /// [`step`](Self::step) with the hand's force on the handle (N) as a
    /// function of the handle's position (m) and velocity (m/s).
    pub fn step_with(
        &mut self,
        tau_a: &[f64],
        hand: &HandForce,
        dt: f64,
        substeps: u32,
    ) -> Result<(), Error> {
        let tau = DVector::from_column_slice(tau_a);
        let h = dt / substeps as f64;
        for _ in 0..substeps {
            let (q, qd) = (self.q.clone(), self.qd.clone());
            let k1v = self.accel(&q, &qd, &tau, hand)?;
            let k1x = qd.clone();
            let q2 = &q + &k1x * (h / 2.0);
            let v2 = &qd + &k1v * (h / 2.0);
            let k2v = self.accel(&q2, &v2, &tau, hand)?;
            let q3 = &q + &v2 * (h / 2.0);
            let v3 = &qd + &k2v * (h / 2.0);
            let k3v = self.accel(&q3, &v3, &tau, hand)?;
            let q4 = &q + &v3 * h;
            let v4 = &qd + &k3v * h;
            let k4v = self.accel(&q4, &v4, &tau, hand)?;
            self.q = q + (k1x + &v2 * 2.0 + &v3 * 2.0 + &v4) * (h / 6.0);
            self.qd = qd + (k1v + k2v * 2.0 + k3v * 2.0 + k4v) * (h / 6.0);
        }
        Ok(())
    }

    /// The kinetic energy `½ q'^T M q'` (J).
    pub fn kinetic_j(&self) -> Result<f64, Error> {
        Ok(0.5 * self.qd.dot(&(self.mass(&self.q)? * &self.qd)))
    }
}
