//! A linkage at a pose: its Jacobian (the control crate's, the one the
//! board runs), its joint-space mass and damping, and the mass and damping
//! the hand feels at the handle, `M_x = J^-T M_q J^-1`, `D_x = J^-T D_q J^-1`.

use super::file::{Geometry, Inertia, LinkageFile, OnKinematics};
use super::taylor::Taylor;
use super::SerialArmDynamics;
use nalgebra::DMatrix;
use twoport_control::kinematics::{Kinematics, KinematicsFault};

/// The handle's position, the Jacobian, and the Cartesian mass and damping
/// at one pose.
#[derive(Clone, Debug, PartialEq)]
pub struct PoseDynamics {
    /// Joint angles (rad).
    pub q_rad: Vec<f64>,
    /// The handle's position (m).
    pub position_m: Vec<f64>,
    /// `J = ∂x/∂q` (m/rad).
    pub jacobian: DMatrix<f64>,
    /// The mass the hand feels, `J^-T M_q J^-1` (kg).
    pub mass_kg: DMatrix<f64>,
    /// The damping the hand feels, `J^-T D_q J^-1` (N s/m).
    pub damping_nspm: DMatrix<f64>,
}

impl PoseDynamics {
    /// This pose (its angles, position and Jacobian) with another mass
    /// (kg) and damping (N s/m) at the handle: an identified body, or one
    /// of the set a robust design proves.
    pub fn with_body(&self, mass_kg: &DMatrix<f64>, damping_nspm: &DMatrix<f64>) -> Self {
        PoseDynamics {
            mass_kg: mass_kg.clone(),
            damping_nspm: damping_nspm.clone(),
            ..self.clone()
        }
    }
}

/// The handle's position and the Jacobian at `q` for the file's geometry.
pub fn forward(
    geometry: &Geometry,
    q: &[f64],
) -> Result<(Vec<f64>, DMatrix<f64>), KinematicsFault> {
    struct Forward<'a>(&'a [f64]);
    impl OnKinematics for Forward<'_> {
        type Out = Result<(Vec<f64>, DMatrix<f64>), KinematicsFault>;
        fn run<K, const N: usize>(self, k: K) -> Self::Out
        where
            K: Kinematics<f64, N> + Kinematics<Taylor<N>, N>,
        {
            let q: [f64; N] = self.0.try_into().map_err(|_| KinematicsFault::NotFinite)?;
            let j = Kinematics::<f64, N>::forward(&k, &q)?;
            Ok((
                j.position_m.to_vec(),
                DMatrix::from_fn(N, N, |r, c| j.jacobian[r][c]),
            ))
        }
    }
    geometry
        .on_kinematics(Forward(q))
        .map_err(|_| KinematicsFault::NotFinite)?
}

/// The joint angles (rad) that put the handle at `position_m` (m), and
/// the Jacobian there, by Newton's steps from `q_start` (rad); `None`
/// where they do not converge to 1 nm within 50 steps, or the Jacobian
/// turns singular on the way.
pub fn inverse(
    geometry: &Geometry,
    position_m: &[f64],
    q_start: &[f64],
) -> Option<(Vec<f64>, DMatrix<f64>)> {
    let mut q = q_start.to_vec();
    for _ in 0..50 {
        let (x, j) = forward(geometry, &q).ok()?;
        let miss = nalgebra::DVector::from_iterator(
            x.len(),
            position_m.iter().zip(&x).map(|(want, at)| want - at),
        );
        if miss.amax() < 1e-9 {
            return Some((q, j));
        }
        let step = j.lu().solve(&miss)?;
        for (qi, s) in q.iter_mut().zip(step.iter()) {
            *qi += s;
        }
    }
    None
}

impl LinkageFile {
    /// The joint-space mass matrix at `q` with the rotors reflected
    /// (kg m²), given the Jacobian there.
    pub fn joint_mass(&self, q: &[f64], jacobian: &DMatrix<f64>) -> DMatrix<f64> {
        let n = q.len();
        let rotors = DMatrix::from_fn(n, n, |r, c| {
            if r == c {
                self.motors.ratios[r].powi(2) * self.motors.rotor_inertia_kgm2
            } else {
                0.0
            }
        });
        match (&self.inertia, self.geometry) {
            (
                Inertia::Lumped {
                    handle_mass_kg,
                    link_inertia_kgm2,
                },
                _,
            ) => {
                DMatrix::from_diagonal(&nalgebra::DVector::from_column_slice(link_inertia_kgm2))
                    + rotors
                    + jacobian.transpose() * jacobian * *handle_mass_kg
            }
            (Inertia::SerialArmLinks { .. }, _) => match self.serial_arm_dynamics() {
                Some(arm) => {
                    let m = arm.joint_mass([q[0], q[1], q[2]]);
                    DMatrix::from_fn(3, 3, |r, c| m[(r, c)])
                }
                // (The file's check allows link parameters on a serial arm
                // only.)
                None => rotors,
            },
        }
    }

    /// A serial arm's links and rotors as [`SerialArmDynamics`]; `None`
    /// for a lumped inertia or another geometry.
    pub fn serial_arm_dynamics(&self) -> Option<SerialArmDynamics> {
        match (&self.inertia, self.geometry) {
            (
                Inertia::SerialArmLinks {
                    l3_m,
                    masses_kg,
                    inertias_kgm2,
                    base_yy_kgm2,
                    ..
                },
                Geometry::SerialArm { l1_m, l2_m },
            ) if self.motors.ratios.len() == 3 => Some(SerialArmDynamics {
                l1_m,
                l2_m,
                l3_m: *l3_m,
                masses_kg: *masses_kg,
                inertias_kgm2: *inertias_kgm2,
                base_yy_kgm2: *base_yy_kgm2,
                rotor_kgm2: self.motors.rotor_inertia_kgm2,
                ratios: [0, 1, 2].map(|i| self.motors.ratios[i]),
            }),
            _ => None,
        }
    }

    /// The moving masses' potential energy at `q` (J), with gravity `g`
    /// (m/s²) along `-z` and the handle at height `z_m`: a lumped handle
    /// mass's weight, or the serial arm's links (Cavusoglu, Feygin &
    /// Tendick 2002: centres of mass at `l1` and `l5` along the upper arm,
    /// `l2/2`, `l3` and `l6` along the forearm's parts).
    pub fn potential_j(&self, q: &[f64], z_m: f64, g: f64) -> f64 {
        if let Inertia::Lumped { handle_mass_kg, .. } = &self.inertia {
            return handle_mass_kg * g * z_m;
        }
        self.arm_moments()
            .map_or(0.0, |(up, fore)| g * (up * q[1].sin() - fore * q[2].cos()))
    }

    /// The joint torques gravity asks at `q` (N m), the potential energy's
    /// gradient, given the Jacobian there and gravity `g` (m/s²) along
    /// `-z`.
    pub fn gravity_nm(&self, q: &[f64], jacobian: &DMatrix<f64>, g: f64) -> Vec<f64> {
        let n = q.len();
        match (&self.inertia, self.arm_moments()) {
            (Inertia::Lumped { handle_mass_kg, .. }, _) if jacobian.nrows() == 3 => (0..n)
                .map(|c| handle_mass_kg * g * jacobian[(2, c)])
                .collect(),
            (_, Some((up, fore))) => vec![0.0, g * up * q[1].cos(), g * fore * q[2].sin()],
            _ => vec![0.0; n],
        }
    }

    /// The board's gravity compensation for these moving masses under
    /// `g` (m/s²) along `-z`: a lumped handle's weight, or the serial
    /// arm's two link moments (`G = (0, a cos q2, b sin q3)`).
    pub fn gravity_compensation(&self, g: f64) -> twoport_control::linkage::Gravity {
        use twoport_control::linkage::Gravity;
        match (&self.inertia, self.arm_moments()) {
            (Inertia::Lumped { handle_mass_kg, .. }, _) => Gravity::Handle {
                weight_n: (handle_mass_kg * g) as f32,
            },
            (_, Some((up, fore))) => Gravity::SerialArm {
                upper_nm: (g * up) as f32,
                fore_nm: (g * fore) as f32,
            },
            (_, None) => Gravity::Off,
        }
    }

    /// The serial arm's first moments of mass about the shoulder (kg m):
    /// the upper arm's, `l1 m_a + l5 m_be + l1 m_c/2`, whose height goes as
    /// `sin q2`, and the forearm's, `l2 m_a/2 + l3 m_c - l6 m_df`, whose
    /// depth goes as `cos q3`. `None` but for a serial arm's links.
    fn arm_moments(&self) -> Option<(f64, f64)> {
        match (&self.inertia, self.geometry) {
            (
                Inertia::SerialArmLinks {
                    l3_m,
                    l5_m,
                    l6_m,
                    masses_kg: [ma, mc, mbe, mdf],
                    ..
                },
                Geometry::SerialArm { l1_m, l2_m },
            ) => Some((
                l1_m * ma + l5_m * mbe + 0.5 * l1_m * mc,
                0.5 * l2_m * ma + l3_m * mc - l6_m * mdf,
            )),
            _ => None,
        }
    }

    /// The arm drawn at `q` (rad): polylines through its joints to the
    /// handle (m, the kinematics' frame). A serial arm: base, elbow,
    /// handle. A delta: each leg's motor, elbow and its parallelogram's end
    /// at the effector, and the effector to the handle. A pantograph: each
    /// motor, elbow and the handle. A capstan: the handle alone.
    pub fn skeleton(&self, q: &[f64]) -> Vec<Vec<[f64; 3]>> {
        let (c, s) = (|a: f64| a.cos(), |a: f64| a.sin());
        match self.geometry {
            Geometry::SerialArm { l1_m, l2_m } if q.len() == 3 => {
                let r1 = l1_m * c(q[1]);
                let elbow = [c(q[0]) * r1, s(q[0]) * r1, l1_m * s(q[1])];
                let r2 = l2_m * s(q[2]);
                let hand = [
                    elbow[0] + c(q[0]) * r2,
                    elbow[1] + s(q[0]) * r2,
                    elbow[2] - l2_m * c(q[2]),
                ];
                vec![vec![[0.0; 3], elbow, hand]]
            }
            Geometry::Delta {
                base_m,
                effector_m,
                upper_m,
                ..
            } if q.len() == 3 => {
                let Ok((x, _)) = forward(&self.geometry, q) else {
                    return Vec::new();
                };
                (0..3)
                    .map(|i| {
                        let a = i as f64 * std::f64::consts::TAU / 3.0;
                        let (dx, dy) = (c(a), s(a));
                        let r = base_m + upper_m * c(q[i]);
                        vec![
                            [base_m * dx, base_m * dy, 0.0],
                            [r * dx, r * dy, -upper_m * s(q[i])],
                            [x[0] + effector_m * dx, x[1] + effector_m * dy, x[2]],
                            [x[0], x[1], x[2]],
                        ]
                    })
                    .collect()
            }
            Geometry::Pantograph { l_m, d_m, .. } if q.len() == 2 => {
                let Ok((x, _)) = forward(&self.geometry, q) else {
                    return Vec::new();
                };
                let hand = [x[0], x[1], 0.0];
                vec![
                    vec![[0.0; 3], [l_m * c(q[0]), l_m * s(q[0]), 0.0], hand],
                    vec![
                        [d_m, 0.0, 0.0],
                        [d_m + l_m * c(q[1]), l_m * s(q[1]), 0.0],
                        hand,
                    ],
                ]
            }
            _ => match forward(&self.geometry, q) {
                Ok((x, _)) => vec![vec![[x[0], 0.0, 0.0]]],
                Err(_) => Vec::new(),
            },
        }
    }

    /// The joint-space damping (N m s/rad).
    pub fn joint_damping(&self) -> DMatrix<f64> {
        DMatrix::from_diagonal(&nalgebra::DVector::from_column_slice(
            &self.joints.damping_nmsprad,
        ))
    }

    /// Whether `q` is inside the joint limits and the relative ones.
    pub fn within_limits(&self, q: &[f64]) -> bool {
        let j = &self.joints;
        q.iter()
            .zip(&j.limits_rad)
            .all(|(x, [lo, hi])| (lo..=hi).contains(&x))
            && j.relative.iter().all(|r| {
                let d = q[r.joints[1]] - q[r.joints[0]];
                (r.rad[0]..=r.rad[1]).contains(&d)
            })
    }

    /// The linkage at `q` (rad), or the kinematics' fault there.
    pub fn pose(&self, q: &[f64]) -> Result<PoseDynamics, KinematicsFault> {
        let (position_m, jacobian) = forward(&self.geometry, q)?;
        let inv = jacobian
            .clone()
            .try_inverse()
            .ok_or(KinematicsFault::Singular)?;
        let cart = |m: DMatrix<f64>| {
            let x = inv.transpose() * m * &inv;
            // Symmetric to rounding; make it exactly so.
            (&x + x.transpose()) * 0.5
        };
        Ok(PoseDynamics {
            q_rad: q.to_vec(),
            position_m,
            mass_kg: cart(self.joint_mass(q, &jacobian)),
            damping_nspm: cart(self.joint_damping()),
            jacobian,
        })
    }

    /// Poses on a grid of `per_joint` angles across each joint's limits,
    /// inside the relative limits, where the kinematics answer (a pose it
    /// faults at is one the board refuses too).
    pub fn workspace(&self, per_joint: usize) -> Vec<PoseDynamics> {
        let n = self.geometry.joints();
        let per = per_joint.max(2);
        let mut poses = Vec::new();
        let mut idx = vec![0usize; n];
        loop {
            let q: Vec<f64> = idx
                .iter()
                .zip(&self.joints.limits_rad)
                .map(|(&i, [lo, hi])| lo + (hi - lo) * i as f64 / (per - 1) as f64)
                .collect();
            if self.within_limits(&q) {
                if let Ok(p) = self.pose(&q) {
                    poses.push(p);
                }
            }
            let mut d = 0;
            loop {
                if d == n {
                    return poses;
                }
                idx[d] += 1;
                if idx[d] < per {
                    break;
                }
                idx[d] = 0;
                d += 1;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The arm drawn is the arm the kinematics solve: it ends at the
    /// handle, and each link has its file's length, at every pose of each
    /// shipped linkage's grid (the delta's parallelograms and the
    /// pantograph's distal links included, which the drawing does not
    /// take from the solve), to 1 µm (the kinematics hold their lengths in
    /// f32, as the board does).
    #[test]
    fn the_skeleton_is_the_kinematics() {
        let dist = |a: &[f64; 3], b: &[f64; 3]| {
            ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
        };
        for name in crate::linkage::test_files::SHIPPED {
            let file = crate::linkage::test_files::shipped(name);
            let poses = file.workspace(5);
            assert!(poses.len() > 3, "{name}");
            for p in poses {
                let sk = file.skeleton(&p.q_rad);
                let end = *sk[0].last().unwrap();
                for (i, x) in p.position_m.iter().enumerate() {
                    assert!(
                        (end[i] - x).abs() < 1e-6,
                        "{name}: {end:?} vs {:?}",
                        p.position_m
                    );
                }
                let lengths: Vec<f64> = match file.geometry {
                    Geometry::SerialArm { l1_m, l2_m } => vec![l1_m, l2_m],
                    Geometry::Delta {
                        upper_m, lower_m, ..
                    } => vec![upper_m, lower_m],
                    Geometry::Pantograph { l_m, big_l_m, .. } => vec![l_m, big_l_m],
                    Geometry::Capstan { .. } => vec![],
                };
                for line in &sk {
                    for (k, want) in lengths.iter().enumerate() {
                        let got = dist(&line[k], &line[k + 1]);
                        assert!(
                            (got - want).abs() < 1e-6,
                            "{name}: link {k} is {got} m, not {want}"
                        );
                    }
                }
            }
        }
    }
}
