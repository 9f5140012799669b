//! Linkage device files: what a device is (its kind and geometry), what
//! drives it (motors, encoders, transmissions) and its joints, read from
//! TOML and checked field by field.

use super::taylor::Taylor;
use crate::ModelError;
use serde::Deserialize;
use twoport_control::kinematics::{Capstan, Delta, Kinematics, Pantograph, SerialArm};
use twoport_control::linkage::Hardware;
use twoport_control::ParamError;

/// A linkage device file.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LinkageFile {
    /// A human-readable name.
    pub name: String,
    /// Where its numbers come from (a citation, or "estimate").
    pub source: String,
    /// The servo's period (s).
    pub period_s: f64,
    /// Latency from sampling the joints to the torques' change (s): the
    /// servo's computation, a bus's round trip; whole ticks and a part of
    /// one at the period (0 by default).
    #[serde(default)]
    pub latency_s: f64,
    /// The linkage's kind and dimensions.
    pub geometry: Geometry,
    /// Every motor's drive, the same for each joint.
    pub motors: Motors,
    /// Per joint: damping, friction, limits.
    pub joints: Joints,
    /// The moving masses.
    pub inertia: Inertia,
}

/// The linkage's moving masses, besides the rotors (which the motors'
/// `rotor_inertia_kgm2` and `ratios` give).
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Inertia {
    /// A point mass at the handle and each joint's own link inertia about
    /// its axis: `M_q = diag(I_j + n_j² I_rotor) + m_h J^T J`.
    Lumped {
        /// The handle's mass, with the distal links' share (kg).
        handle_mass_kg: f64,
        /// Each joint's link inertia about its axis (kg m²).
        link_inertia_kgm2: Vec<f64>,
    },
    /// The serial arm's links as Cavusoglu, Feygin & Tendick (2002) model
    /// the PHANToM: links a, c, be, df and the base.
    SerialArmLinks {
        /// The forearm's counterweight offset `l3` (m).
        l3_m: f64,
        /// Where link be's centre of mass lies along the upper arm, `l5`
        /// (m, signed: behind the shoulder when negative).
        l5_m: f64,
        /// Where link df's centre of mass lies along the forearm's drive,
        /// `l6` (m, signed).
        l6_m: f64,
        /// Masses of links a, c, be, df (kg).
        masses_kg: [f64; 4],
        /// Inertias `[xx, yy, zz]` of links a, c, be, df (kg m²).
        inertias_kgm2: [[f64; 3]; 4],
        /// The base's inertia about its axis (kg m²).
        base_yy_kgm2: f64,
    },
}

/// A linkage's kind and dimensions (m).
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Geometry {
    /// A capstan or sector drive: handle radius, pulley, sector.
    Capstan {
        /// Handle radius from the sector's axis (m).
        r_h_m: f64,
        /// Motor pulley radius (m).
        r_p_m: f64,
        /// Sector radius (m).
        r_s_m: f64,
    },
    /// The five-bar pantograph.
    Pantograph {
        /// Proximal links (m).
        l_m: f64,
        /// Distal links (m).
        big_l_m: f64,
        /// Distance between the motors (m).
        d_m: f64,
    },
    /// The PHANToM-type serial arm.
    SerialArm {
        /// Upper arm (m).
        l1_m: f64,
        /// Forearm (m).
        l2_m: f64,
    },
    /// The rotary delta.
    Delta {
        /// Base radius (m).
        base_m: f64,
        /// Effector radius (m).
        effector_m: f64,
        /// Upper arms (m).
        upper_m: f64,
        /// Parallelograms (m).
        lower_m: f64,
    },
}

/// The motors and their sensing.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Motors {
    /// Torque constant (N m/A).
    pub torque_constant_nmpa: f64,
    /// Peak torque at the motor (N m).
    pub peak_torque_nm: f64,
    /// Continuous torque at the motor (N m).
    pub continuous_torque_nm: f64,
    /// Encoder counts per motor revolution (after quadrature).
    pub encoder_counts_per_rev: u32,
    /// Rotor inertia (kg m²).
    pub rotor_inertia_kgm2: f64,
    /// Transmission ratio per joint, motor turns per joint turn (1 for a
    /// direct drive; a capstan's is folded into its geometry).
    pub ratios: Vec<f64>,
}

/// The joints' own losses and limits, at the joint (the angle the
/// kinematics takes; a motor's own are reflected through `ratios`).
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Joints {
    /// Viscous damping per joint (N m s/rad).
    pub damping_nmsprad: Vec<f64>,
    /// Coulomb friction per joint (N m).
    pub friction_nm: Vec<f64>,
    /// `[low, high]` per joint (rad).
    pub limits_rad: Vec<[f64; 2]>,
    /// Limits on the difference of two joints, `q[j] - q[i]` (a
    /// parallelogram's), none by default.
    #[serde(default)]
    pub relative: Vec<RelativeLimit>,
}

/// A limit on `q[j] - q[i]` for `joints = [i, j]`.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RelativeLimit {
    /// `[i, j]`, counted from 0.
    pub joints: [usize; 2],
    /// `[low, high]` (rad).
    pub rad: [f64; 2],
}

/// What to do with a geometry's kinematics, whatever its joint count.
pub trait OnKinematics {
    /// The result.
    type Out;
    /// Run with the kinematics of `N` joints, which answer in `f64` and
    /// over a box of poses in [`Taylor`] arithmetic.
    fn run<K, const N: usize>(self, k: K) -> Self::Out
    where
        K: Kinematics<f64, N> + Kinematics<Taylor<N>, N>;
}

impl Geometry {
    /// `job` run on this geometry's kinematics (its lengths in `f32`, as
    /// the board holds them), or why the kinematics refuse the lengths.
    pub fn on_kinematics<J: OnKinematics>(&self, job: J) -> Result<J::Out, ParamError> {
        let f = |x: f64| x as f32;
        Ok(match *self {
            Geometry::Capstan {
                r_h_m,
                r_p_m,
                r_s_m,
            } => job.run::<_, 1>(Capstan::new(f(r_h_m), f(r_p_m), f(r_s_m))?),
            Geometry::Pantograph { l_m, big_l_m, d_m } => {
                job.run::<_, 2>(Pantograph::new(f(l_m), f(big_l_m), f(d_m))?)
            }
            Geometry::SerialArm { l1_m, l2_m } => {
                job.run::<_, 3>(SerialArm::new(f(l1_m), f(l2_m))?)
            }
            Geometry::Delta {
                base_m,
                effector_m,
                upper_m,
                lower_m,
            } => job.run::<_, 3>(Delta::new(
                f(base_m),
                f(effector_m),
                f(upper_m),
                f(lower_m),
            )?),
        })
    }

    /// How many joints (and Cartesian axes) the kind has.
    pub fn joints(&self) -> usize {
        match self {
            Geometry::Capstan { .. } => 1,
            Geometry::Pantograph { .. } => 2,
            Geometry::SerialArm { .. } | Geometry::Delta { .. } => 3,
        }
    }

    /// Build the kind's kinematics, to check its dimensions as the board
    /// will.
    fn check(&self) -> Result<(), String> {
        struct Build;
        impl OnKinematics for Build {
            type Out = ();
            fn run<K, const N: usize>(self, _: K) -> Self::Out
            where
                K: Kinematics<f64, N> + Kinematics<Taylor<N>, N>,
            {
            }
        }
        let r = self.on_kinematics(Build);
        r.map_err(|e| {
            let field = e
                .name
                .trim_start_matches("kinematics.")
                .split(' ')
                .next()
                .unwrap_or(e.name);
            format!("geometry.{field} = {} {}", e.value, e.problem)
        })
    }
}

use crate::field::{non_negative as at_least_zero, positive};

/// The list `name` has an entry for each of `n` joints.
fn count(name: &str, len: usize, n: usize) -> Result<(), String> {
    if len == n {
        Ok(())
    } else {
        Err(format!(
            "{name} has {len} entries: a {n}-joint linkage needs {n}"
        ))
    }
}

/// Whether `[lo, hi]` is a range: finite, low below high.
fn range(name: &str, [lo, hi]: [f64; 2]) -> Result<(), String> {
    if lo.is_finite() && hi.is_finite() && lo < hi {
        Ok(())
    } else {
        Err(format!(
            "{name} = [{lo}, {hi}]: must be finite, low below high"
        ))
    }
}

impl Motors {
    /// The motors' fields, for `n` joints.
    fn check(&self, n: usize) -> Result<(), String> {
        let m = self;
        positive("motors.torque_constant_nmpa", m.torque_constant_nmpa)?;
        positive("motors.peak_torque_nm", m.peak_torque_nm)?;
        positive("motors.continuous_torque_nm", m.continuous_torque_nm)?;
        if m.continuous_torque_nm > m.peak_torque_nm {
            return Err(format!(
                "motors.continuous_torque_nm = {} exceeds motors.peak_torque_nm = {}",
                m.continuous_torque_nm, m.peak_torque_nm
            ));
        }
        if m.encoder_counts_per_rev == 0 {
            return Err("motors.encoder_counts_per_rev = 0: must be at least 1".into());
        }
        at_least_zero("motors.rotor_inertia_kgm2", m.rotor_inertia_kgm2)?;
        count("motors.ratios", m.ratios.len(), n)?;
        for (i, r) in m.ratios.iter().enumerate() {
            positive(&format!("motors.ratios[{i}]"), *r)?;
        }
        Ok(())
    }
}

impl Joints {
    /// The joints' losses and limits, for `n` joints.
    fn check(&self, n: usize) -> Result<(), String> {
        let j = self;
        count("joints.damping_nmsprad", j.damping_nmsprad.len(), n)?;
        count("joints.friction_nm", j.friction_nm.len(), n)?;
        count("joints.limits_rad", j.limits_rad.len(), n)?;
        for (i, d) in j.damping_nmsprad.iter().enumerate() {
            at_least_zero(&format!("joints.damping_nmsprad[{i}]"), *d)?;
        }
        for (i, f) in j.friction_nm.iter().enumerate() {
            at_least_zero(&format!("joints.friction_nm[{i}]"), *f)?;
        }
        for (i, lim) in j.limits_rad.iter().enumerate() {
            range(&format!("joints.limits_rad[{i}]"), *lim)?;
        }
        for (r, lim) in j.relative.iter().enumerate() {
            let [a, b] = lim.joints;
            if a >= n || b >= n || a == b {
                return Err(format!(
                    "joints.relative[{r}].joints = [{a}, {b}]: two different joints below {n}"
                ));
            }
            range(&format!("joints.relative[{r}].rad"), lim.rad)?;
        }
        Ok(())
    }
}

impl Inertia {
    /// The masses and inertias, for `geometry`'s `n` joints.
    fn check(&self, geometry: &Geometry, n: usize) -> Result<(), String> {
        match self {
            Inertia::Lumped {
                handle_mass_kg,
                link_inertia_kgm2,
            } => {
                at_least_zero("inertia.handle_mass_kg", *handle_mass_kg)?;
                count("inertia.link_inertia_kgm2", link_inertia_kgm2.len(), n)?;
                for (i, x) in link_inertia_kgm2.iter().enumerate() {
                    at_least_zero(&format!("inertia.link_inertia_kgm2[{i}]"), *x)?;
                }
            }
            Inertia::SerialArmLinks {
                l3_m,
                l5_m,
                l6_m,
                masses_kg,
                inertias_kgm2,
                base_yy_kgm2,
            } => {
                if !matches!(geometry, Geometry::SerialArm { .. }) {
                    return Err("inertia.kind = \"serial_arm_links\": only for geometry.kind = \"serial_arm\"".into());
                }
                at_least_zero("inertia.l3_m", *l3_m)?;
                for (name, x) in [("inertia.l5_m", l5_m), ("inertia.l6_m", l6_m)] {
                    if !x.is_finite() {
                        return Err(format!("{name} = {x}: must be finite"));
                    }
                }
                at_least_zero("inertia.base_yy_kgm2", *base_yy_kgm2)?;
                for (i, m) in masses_kg.iter().enumerate() {
                    at_least_zero(&format!("inertia.masses_kg[{i}]"), *m)?;
                }
                for (i, row) in inertias_kgm2.iter().enumerate() {
                    for (k, x) in row.iter().enumerate() {
                        at_least_zero(&format!("inertia.inertias_kgm2[{i}][{k}]"), *x)?;
                    }
                }
            }
        }
        Ok(())
    }
}

impl LinkageFile {
    /// The delay from sampling to the torques at the file's period: whole
    /// ticks and a fraction of one.
    pub fn lag(&self) -> crate::model::Lag {
        crate::model::Lag::of(self.latency_s, self.period_s)
    }

    /// Parse and check a linkage file's text; `source` names it in errors.
    ///
    /// # Examples
    ///
    /// ```
    /// use twoport_design::linkage::LinkageFile;
    /// let text = include_str!("../../../../models/linkages/hapkit.toml");
    /// let hapkit = LinkageFile::from_toml(text, "hapkit.toml")?;
    /// assert_eq!(hapkit.geometry.joints(), 1);
    /// let bad = text.replace("r_p_m = 0.005", "r_p_m = -0.005");
    /// let e = LinkageFile::from_toml(&bad, "hapkit.toml").unwrap_err();
    /// assert_eq!(e.to_string(), "hapkit.toml: geometry.r_p_m = -0.005 must be finite and > 0");
    /// # Ok::<(), twoport_design::ModelError>(())
    /// ```
    pub fn from_toml(text: &str, source: &str) -> Result<Self, ModelError> {
        let file: LinkageFile = crate::model::parse(text, source)?;
        file.check().map_err(|message| ModelError {
            source: source.to_string(),
            message,
        })?;
        Ok(file)
    }

    /// Read and check a linkage file.
    /// Whether the file at `path` is a linkage file (it has a
    /// `[geometry]` table) rather than a device of Cartesian axes.
    pub fn is_linkage(path: &std::path::Path) -> bool {
        std::fs::read_to_string(path)
            .ok()
            .and_then(|t| t.parse::<toml::Table>().ok())
            .is_some_and(|t| t.contains_key("geometry"))
    }

    /// The linkage file at `path`, checked.
    pub fn load(path: &std::path::Path) -> Result<Self, ModelError> {
        let (text, source) = crate::model::read(path)?;
        Self::from_toml(&text, &source)
    }

    /// The drive train as a board of `N` joints holds it (f32), or `None`
    /// where the file has another number of joints.
    pub fn hardware<const N: usize>(&self) -> Option<Hardware<N>> {
        if self.geometry.joints() != N {
            return None;
        }
        let m = &self.motors;
        Some(Hardware {
            counts_per_rev: m.encoder_counts_per_rev as f32,
            ratios: core::array::from_fn(|i| m.ratios[i] as f32),
            limits_rad: core::array::from_fn(|i| self.joints.limits_rad[i].map(|x| x as f32)),
            peak_torque_nm: m.peak_torque_nm as f32,
            continuous_torque_nm: m.continuous_torque_nm as f32,
        })
    }

    fn check(&self) -> Result<(), String> {
        positive("period_s", self.period_s)?;
        at_least_zero("latency_s", self.latency_s)?;
        if self.latency_s > crate::model::MAX_LATENCY_S {
            return Err(format!(
                "latency_s = {}: at most {} s",
                self.latency_s,
                crate::model::MAX_LATENCY_S
            ));
        }
        self.geometry.check()?;
        let n = self.geometry.joints();
        self.motors.check(n)?;
        self.joints.check(n)?;
        self.inertia.check(&self.geometry, n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const HAPKIT: &str = include_str!("../../../../models/linkages/hapkit.toml");
    const HAPLY: &str = include_str!("../../../../models/linkages/haply_2diy.toml");
    const PHANTOM: &str = include_str!("../../../../models/linkages/phantom_premium_1_5.toml");
    const FALCON: &str = include_str!("../../../../models/linkages/falcon_like.toml");

    fn refused(text: &str, from: &str, to: &str) -> String {
        assert!(text.contains(from), "{from}");
        LinkageFile::from_toml(&text.replacen(from, to, 1), "x.toml")
            .unwrap_err()
            .to_string()
    }

    #[test]
    fn the_shipped_linkages_load() {
        let h = LinkageFile::from_toml(HAPKIT, "hapkit.toml").unwrap();
        assert!(matches!(h.geometry, Geometry::Capstan { .. }));
        let p = LinkageFile::from_toml(HAPLY, "haply_2diy.toml").unwrap();
        assert_eq!(p.geometry.joints(), 2);
        assert_eq!(p.motors.encoder_counts_per_rev, 13_824);
        let a = LinkageFile::from_toml(PHANTOM, "phantom.toml").unwrap();
        assert!(matches!(a.inertia, Inertia::SerialArmLinks { .. }));
        assert_eq!(a.joints.relative.len(), 1);
        let f = LinkageFile::from_toml(FALCON, "falcon.toml").unwrap();
        assert!(matches!(f.geometry, Geometry::Delta { .. }));
    }

    #[test]
    fn bad_fields_are_named() {
        assert_eq!(
            refused(HAPLY, "l_m = 0.07", "l_m = 0.0"),
            "x.toml: geometry.l_m = 0 must be finite and > 0"
        );
        assert_eq!(
            refused(HAPLY, "ratios = [1.0, 1.0]", "ratios = [1.0]"),
            "x.toml: motors.ratios has 1 entries: a 2-joint linkage needs 2"
        );
        assert!(refused(HAPKIT, "kind = \"capstan\"", "kind = \"gantry\"")
            .contains("unknown variant `gantry`"));
        assert!(refused(HAPKIT, "period_s", "perod_s").starts_with("x.toml: line "));
        assert!(refused(
            HAPLY,
            "continuous_torque_nm = 0.1",
            "continuous_torque_nm = 9.0"
        )
        .contains("exceeds motors.peak_torque_nm"));
        assert_eq!(
            refused(PHANTOM, "l5_m = -0.0368", "l5_m = nan"),
            "x.toml: inertia.l5_m = NaN: must be finite"
        );
        assert_eq!(
            refused(PHANTOM, "joints = [1, 2]", "joints = [1, 3]"),
            "x.toml: joints.relative[0].joints = [1, 3]: two different joints below 3"
        );
        assert_eq!(
            refused(
                PHANTOM,
                "rad = [-1.1345, 0.9599]",
                "rad = [0.9599, -1.1345]"
            ),
            "x.toml: joints.relative[0].rad = [0.9599, -1.1345]: must be finite, low below high"
        );
        assert_eq!(
            refused(HAPLY, "handle_mass_kg = 0.02", "handle_mass_kg = -0.02"),
            "x.toml: inertia.handle_mass_kg = -0.02 must be finite and >= 0"
        );
        assert_eq!(
            refused(
                HAPLY,
                "link_inertia_kgm2 = [2.0e-5, 2.0e-5]",
                "link_inertia_kgm2 = [2.0e-5]"
            ),
            "x.toml: inertia.link_inertia_kgm2 has 1 entries: a 2-joint linkage needs 2"
        );
        assert!(refused(
            FALCON,
            "kind = \"lumped\"\nhandle_mass_kg = 0.06",
            "kind = \"serial_arm_links\"\nhandle_mass_kg = 0.06"
        )
        .contains("inertia"));
        assert!(refused(HAPKIT, "[inertia]", "[inertial]").contains("inertia"));
    }
}
