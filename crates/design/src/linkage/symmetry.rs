//! The symmetries the workspace proof may use: a linkage's handle damping
//! and mass have the same eigenvalues at poses that a rigid motion of the
//! whole device maps onto each other, so the proof need search only one
//! pose of each such family. Only exact symmetries of the model the board
//! runs are used (the delta's 120° turns are not: the board holds
//! `sin 120°` in `f32`).

use super::file::{Geometry, Inertia, LinkageFile, RelativeLimit};

impl LinkageFile {
    /// A joint that only turns the whole linkage about a fixed axis (the
    /// serial arm's base, about `z`): at any angle of it the handle's
    /// damping and mass are the same matrices turned (`J = R_z(q_0) J_0`,
    /// and the joint-space damping and mass do not depend on `q_0`), so
    /// their eigenvalues, and the kinematics' refusals, do not depend on
    /// it. `None` where a relative limit ties it to another joint.
    pub fn turning_joint(&self) -> Option<usize> {
        let turning = match self.geometry {
            Geometry::SerialArm { .. } => 0,
            _ => return None,
        };
        let tied = self
            .joints
            .relative
            .iter()
            .any(|r| r.joints.contains(&turning));
        (!tied).then_some(turning)
    }

    /// Two joints a mirror swaps (the delta's second and third legs, which
    /// the plane `y = 0` reflects into each other): the pose with their
    /// angles swapped is the mirror image, its damping and mass the same
    /// matrices reflected. Only where the two joints are alike in every
    /// number the dynamics take (damping, ratio, limits, link inertia) and
    /// no relative limit names either.
    pub fn mirrored_joints(&self) -> Option<[usize; 2]> {
        let pair = match self.geometry {
            Geometry::Delta { .. } => [1, 2],
            _ => return None,
        };
        let [a, b] = pair;
        let alike = |v: &[f64]| v[a] == v[b];
        let j = &self.joints;
        let inertia = match &self.inertia {
            Inertia::Lumped {
                link_inertia_kgm2, ..
            } => alike(link_inertia_kgm2),
            Inertia::SerialArmLinks { .. } => false,
        };
        let tied = j
            .relative
            .iter()
            .any(|r| r.joints.iter().any(|k| pair.contains(k)));
        (inertia
            && !tied
            && alike(&j.damping_nmsprad)
            && alike(&self.motors.ratios)
            && j.limits_rad[a] == j.limits_rad[b])
            .then_some(pair)
    }

    /// The file cut to one pose of each symmetric family: the turning
    /// joint held at its range's middle, and the mirrored pair ordered
    /// (`q_b <= q_a`). Every pose of `self` has its damping's and mass's
    /// eigenvalues at some pose of the result, and every pose of the
    /// result is one of `self`'s.
    pub fn fundamental_domain(&self) -> LinkageFile {
        let mut out = self.clone();
        if let Some(k) = self.turning_joint() {
            let [lo, hi] = self.joints.limits_rad[k];
            let mid = 0.5 * lo + 0.5 * hi;
            out.joints.limits_rad[k] = [mid, mid];
        }
        if let Some([a, b]) = self.mirrored_joints() {
            let [lo, hi] = self.joints.limits_rad[a];
            out.joints.relative.push(RelativeLimit {
                joints: [a, b],
                rad: [lo - hi, 0.0],
            });
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linkage::test_files::shipped;

    fn eigenvalues(file: &LinkageFile, q: &[f64]) -> Option<(Vec<f64>, Vec<f64>)> {
        let p = file.pose(q).ok()?;
        let mut d: Vec<f64> = p
            .damping_nspm
            .symmetric_eigenvalues()
            .iter()
            .copied()
            .collect();
        let mut m: Vec<f64> = p.mass_kg.symmetric_eigenvalues().iter().copied().collect();
        d.sort_by(f64::total_cmp);
        m.sort_by(f64::total_cmp);
        Some((d, m))
    }

    fn close(a: &[f64], b: &[f64]) -> bool {
        a.iter()
            .zip(b)
            .all(|(x, y)| (x - y).abs() <= 1e-9 * x.abs().max(y.abs()))
    }

    /// The PHANToM's base angle changes no eigenvalue, nor whether the
    /// kinematics answer; the delta's mirror image has the same ones. The
    /// other shipped linkages claim no symmetry.
    #[test]
    fn the_symmetries_claimed_hold_at_sampled_poses() {
        let arm = shipped("phantom_premium_1_5");
        assert_eq!(arm.turning_joint(), Some(0));
        for q in arm.workspace(6).iter().map(|p| p.q_rad.clone()) {
            let base = eigenvalues(&arm, &q).unwrap();
            for q0 in [-1.0, -0.3, 0.2, 0.9] {
                let turned = eigenvalues(&arm, &[q0, q[1], q[2]]).unwrap();
                assert!(
                    close(&base.0, &turned.0) && close(&base.1, &turned.1),
                    "{q:?}"
                );
            }
        }
        let delta = shipped("falcon_like");
        assert_eq!(delta.mirrored_joints(), Some([1, 2]));
        for q in delta.workspace(6).iter().map(|p| p.q_rad.clone()) {
            let (a, b) = (
                eigenvalues(&delta, &q),
                eigenvalues(&delta, &[q[0], q[2], q[1]]),
            );
            let (a, b) = (a.unwrap(), b.unwrap());
            assert!(close(&a.0, &b.0) && close(&a.1, &b.1), "{q:?}");
        }
        for name in ["haply_2diy", "hapkit"] {
            let f = shipped(name);
            assert_eq!((f.turning_joint(), f.mirrored_joints()), (None, None));
            assert_eq!(f.fundamental_domain(), f);
        }
    }

    /// A relative limit on the turning joint, or legs that differ, keep
    /// the whole box.
    #[test]
    fn a_symmetry_is_used_only_where_the_file_keeps_it() {
        let mut arm = shipped("phantom_premium_1_5");
        arm.joints.relative.push(RelativeLimit {
            joints: [0, 1],
            rad: [-2.0, 2.0],
        });
        assert_eq!(arm.turning_joint(), None);
        let mut delta = shipped("falcon_like");
        delta.joints.damping_nmsprad[2] *= 1.5;
        assert_eq!(delta.mirrored_joints(), None);
        let mut delta = shipped("falcon_like");
        delta.joints.limits_rad[1][1] = 1.1;
        assert_eq!(delta.fundamental_domain(), delta);
    }

    /// Files that keep no symmetry (a relative limit on the PHANToM's base,
    /// a delta with one leg damped more) are certified over their whole
    /// box: no pose of a grid or of 300 random ones is less damped than
    /// the certificate, which is within the tolerance of a pose found.
    #[test]
    #[cfg_attr(debug_assertions, ignore = "release only (CI runs it)")]
    fn a_file_without_a_symmetry_is_certified_over_its_whole_box() {
        let mut arm = shipped("phantom_premium_1_5");
        arm.joints.relative.push(RelativeLimit {
            joints: [0, 2],
            rad: [-1.0, 3.0],
        });
        let mut delta = shipped("falcon_like");
        delta.joints.damping_nmsprad[2] *= 1.5;
        let mut rnd = crate::test_rng::uniform(0x2545_f491_4f6c_dd1du64);
        for file in [arm, delta] {
            assert_eq!(file.fundamental_domain(), file);
            let c = crate::linkage::least_damping(&file).unwrap();
            assert!(c.gap <= crate::linkage::TOLERANCE, "{}: {c:?}", file.name);
            let mut qs: Vec<Vec<f64>> = file.workspace(9).into_iter().map(|p| p.q_rad).collect();
            for _ in 0..300 {
                qs.push(
                    file.joints
                        .limits_rad
                        .iter()
                        .map(|[lo, hi]| lo + (hi - lo) * rnd())
                        .collect(),
                );
            }
            for q in qs.iter().filter(|q| file.within_limits(q)) {
                if let Some((d, _)) = eigenvalues(&file, q) {
                    assert!(
                        d[0] >= c.bound,
                        "{}: {} < {} at {q:?}",
                        file.name,
                        d[0],
                        c.bound
                    );
                }
            }
        }
    }
}
