//! A linkage's joint-space mass matrix at a pose, and the mass the hand
//! feels at the handle, `M_x = J^-T M_q J^-1`.

use nalgebra::Matrix3;
use twoport_control::kinematics::{Kinematics, KinematicsFault, SerialArm};
use twoport_control::Real;

/// The PHANToM-type serial arm's masses and inertias (Cavusoglu, Feygin &
/// Tendick 2002, for the PHANToM Premium 1.5), with the motors' rotor
/// inertia reflected through the capstan ratios. SI units: m, kg, kg m².
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SerialArmDynamics {
    /// Upper arm and forearm (m).
    pub l1_m: f64,
    /// Forearm (m).
    pub l2_m: f64,
    /// The forearm's counterweight offset `l3` (m).
    pub l3_m: f64,
    /// Link masses `m_a`, `m_c`, `m_be`, `m_df` (kg).
    pub masses_kg: [f64; 4],
    /// Inertias `[xx, yy, zz]` of links a, c, be, df (kg m²).
    pub inertias_kgm2: [[f64; 3]; 4],
    /// The base's inertia about its axis (kg m²).
    pub base_yy_kgm2: f64,
    /// Each motor's rotor inertia (kg m²).
    pub rotor_kgm2: f64,
    /// Capstan ratios, joint turns per motor turn inverted (motor/joint).
    pub ratios: [f64; 3],
}

impl SerialArmDynamics {
    /// The PHANToM Premium 1.5 as Cavusoglu et al. give it.
    pub fn phantom_premium_1_5() -> Self {
        let e = 1e-4;
        SerialArmDynamics {
            l1_m: 0.215,
            l2_m: 0.170,
            l3_m: 0.0325,
            masses_kg: [0.0202, 0.0249, 0.2359, 0.1906],
            inertias_kgm2: [
                [0.4864 * e, 0.001843 * e, 0.4864 * e],
                [0.959 * e, 0.959 * e, 0.0051 * e],
                [11.09 * e, 10.06 * e, 0.591 * e],
                [7.11 * e, 0.629 * e, 6.246 * e],
            ],
            base_yy_kgm2: 11.87 * e,
            rotor_kgm2: 1.08e-6,
            ratios: [13.3, 11.2, 11.2],
        }
    }

    /// The joint-space mass matrix at `q` (rad), rotors included (kg m²).
    pub fn joint_mass(&self, q: [f64; 3]) -> Matrix3<f64> {
        let m = self.joint_mass_in(q);
        Matrix3::from_fn(|r, c| m[r][c])
    }

    /// [`joint_mass`](Self::joint_mass) in any scalar the kinematics run
    /// in: the workspace proof encloses it over a box of angles.
    pub fn joint_mass_in<R: Real + From<f64>>(&self, q: [R; 3]) -> [[R; 3]; 3] {
        let c = R::from;
        let (l1, l2, l3) = (self.l1_m, self.l2_m, self.l3_m);
        let [ma, mc, _, _] = self.masses_kg;
        let [ia, ic, ibe, idf] = self.inertias_kgm2;
        let (xx, yy, zz) = (0, 1, 2);
        let constant = (4.0 * ia[yy]
            + 4.0 * ia[zz]
            + 8.0 * self.base_yy_kgm2
            + 4.0 * ibe[yy]
            + 4.0 * ibe[zz]
            + 4.0 * ic[yy]
            + 4.0 * ic[zz]
            + 4.0 * idf[yy]
            + 4.0 * idf[zz]
            + 4.0 * l1 * l1 * ma
            + l2 * l2 * ma
            + l1 * l1 * mc
            + 4.0 * l3 * l3 * mc)
            / 8.0;
        let by_2q2 = (4.0 * ibe[yy] - 4.0 * ibe[zz] + 4.0 * ic[yy] - 4.0 * ic[zz]
            + l1 * l1 * (4.0 * ma + mc))
            / 8.0;
        let by_2q3 = (4.0 * ia[yy] - 4.0 * ia[zz] + 4.0 * idf[yy]
            - 4.0 * idf[zz]
            - l2 * l2 * ma
            - 4.0 * l3 * l3 * mc)
            / 8.0;
        let coupled = l1 * (l2 * ma + l3 * mc);
        let m11 = c(constant)
            + c(by_2q2) * (c(2.0) * q[1]).cos()
            + c(by_2q3) * (c(2.0) * q[2]).cos()
            + c(coupled) * q[1].cos() * q[2].sin();
        let m22 = (4.0 * (ibe[xx] + ic[xx] + l1 * l1 * ma) + l1 * l1 * mc) / 4.0;
        let m23 = c(-0.5 * l1 * (l2 * ma + l3 * mc)) * (q[1] - q[2]).sin();
        let m33 = (4.0 * ia[xx] + 4.0 * idf[xx] + l2 * l2 * ma + 4.0 * l3 * l3 * mc) / 4.0;
        let r = self.ratios.map(|n| n * n * self.rotor_kgm2);
        [
            [m11 + c(r[0]), R::ZERO, R::ZERO],
            [R::ZERO, c(m22 + r[1]), m23],
            [R::ZERO, m23, c(m33 + r[2])],
        ]
    }

    /// The mass the hand feels at the handle at `q`: `J^-T M_q J^-1` (kg),
    /// or the fault where the pose has no Jacobian.
    pub fn cartesian_mass(&self, q: [f64; 3]) -> Result<Matrix3<f64>, KinematicsFault> {
        let arm = SerialArm::new(self.l1_m as f32, self.l2_m as f32)
            .map_err(|_| KinematicsFault::NotFinite)?;
        let j = Kinematics::<f64, 3>::forward(&arm, &q)?.jacobian;
        let j = Matrix3::from_fn(|r, c| j[r][c]);
        let inv = j.try_inverse().ok_or(KinematicsFault::Singular)?;
        Ok(inv.transpose() * self.joint_mass(q) * inv)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Over the PHANToM's working joint space (the parallelogram's limits
    /// held), the mass at the handle is symmetric and positive definite,
    /// it carries the arm's kinetic energy (`q'^T M_q q' = v^T M_x v` with
    /// `v = J q'`), and its lightest direction weighs about 30 g, the
    /// figure the published parameters give; its off-diagonal terms are
    /// tens of grams.
    #[test]
    fn the_phantoms_handle_mass_over_its_workspace() {
        let d = SerialArmDynamics::phantom_premium_1_5();
        let arm = SerialArm::new(0.215, 0.17).unwrap();
        let (mut lo, mut off) = (f64::INFINITY, 0.0f64);
        let deg = |x: f64| x.to_radians();
        let mut poses = 0;
        for i in 0..7 {
            for j in 0..10 {
                for k in 0..12 {
                    let q = [
                        deg(-45.0 + 15.0 * i as f64),
                        deg(5.0 * j as f64),
                        deg(20.0 + 6.0 * k as f64),
                    ];
                    if q[1] - q[2] > deg(65.0) || q[2] - q[1] > deg(55.0) {
                        continue;
                    }
                    let Ok(m) = d.cartesian_mass(q) else { continue };
                    poses += 1;
                    assert!((m - m.transpose()).norm() < 1e-12 * m.norm(), "{q:?}");
                    let e = m.symmetric_eigenvalues();
                    assert!(e.min() > 0.0, "{q:?}: {e}");
                    lo = lo.min(e.min());
                    off = off
                        .max(m[(0, 1)].abs())
                        .max(m[(0, 2)].abs())
                        .max(m[(1, 2)].abs());
                    let rate = nalgebra::Vector3::new(0.3, -1.1, 0.7);
                    let jac = Kinematics::<f64, 3>::forward(&arm, &q).unwrap().jacobian;
                    let v = Matrix3::from_fn(|r, c| jac[r][c]) * rate;
                    let (joint, handle) = (rate.dot(&(d.joint_mass(q) * rate)), v.dot(&(m * v)));
                    assert!(
                        (joint - handle).abs() < 1e-9 * joint,
                        "{q:?}: {joint} vs {handle}"
                    );
                }
            }
        }
        assert!(poses > 500, "{poses}");
        assert!((0.027..0.034).contains(&lo), "lightest {lo} kg");
        assert!((0.01..0.15).contains(&off), "off-diagonal {off} kg");
    }
}
