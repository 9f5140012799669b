//! `twoport identify-pose`: a linkage's sines at one pose (each level a
//! folder of one experiment per Cartesian axis, every axis recorded) to
//! the mass matrix the hand feels there, the joints' damping and friction
//! from the energy the sines dissipate, and the coupling proven on the
//! file's own pose, the identified one and the set.

use crate::args::IdentifyPoseArgs;
use nalgebra::DMatrix;
use serde::Serialize;
use std::fmt;
use std::path::{Path, PathBuf};
use twoport_design::linkage::{bounded_workspace_design, inverse, LinkageFile, PoseDynamics};
use twoport_design::network::HumanBound;
use twoport_identify::log::Log;
use twoport_identify::pose::{fit::mass, losses, record_file, PoseMeasured, AXES};

pub(crate) fn identify_pose(a: &IdentifyPoseArgs) -> Result<PoseIdentified, String> {
    if !(a.min_grasp.is_finite() && a.min_grasp >= 0.0) {
        return Err(format!(
            "--min-grasp {}: must be a finite number >= 0",
            a.min_grasp
        ));
    }
    if !(a.sigmas.is_finite() && a.sigmas >= 0.0) {
        return Err(format!(
            "--sigmas {}: must be a finite number >= 0",
            a.sigmas
        ));
    }
    let file = LinkageFile::load(&a.linkage).map_err(|e| e.to_string())?;
    let n = file.geometry.joints();
    let at = || format!("--pose-rad {:?}", a.pose_rad);
    if a.pose_rad.len() != n || n > AXES.len() {
        return Err(format!(
            "{}: {} has {n} joints; give one angle each",
            at(),
            a.linkage.display()
        ));
    }
    if !file.within_limits(&a.pose_rad) {
        return Err(format!(
            "{}: outside {}'s joint limits",
            at(),
            a.linkage.display()
        ));
    }
    let own = file
        .pose(&a.pose_rad)
        .map_err(|e| format!("{}: {e:?}", at()))?;
    let levels = a
        .level
        .iter()
        .map(|dir| level(dir, n))
        .collect::<Result<Vec<_>, _>>()?;
    let masses = levels
        .iter()
        .zip(&a.level)
        .map(|(l, dir)| {
            PoseMeasured::from_logs(l, a.skip)
                .and_then(|m| mass(&m))
                .map_err(|e| format!("{}: {e}", dir.display()))
        })
        .collect::<Result<Vec<_>, _>>()?;
    // The joints' rates along each orbit, from the file's kinematics.
    let along = |x: &[f64]| inverse(&file.geometry, x, &a.pose_rad).map(|(_, j)| j);
    let l = losses::fit(&levels.concat(), &along, a.skip).map_err(|e| {
        // The experiments count level by level, each axis's in turn.
        format!("the levels {}: {e}", names(&a.level))
    })?;
    let singular = || format!("{}: the Jacobian is singular", at());
    let d = l.damping_nspm(&own.jacobian, 0.0).ok_or_else(singular)?;
    let least = l
        .damping_nspm(&own.jacobian, a.sigmas)
        .ok_or_else(singular)?;
    let top = masses.last().expect("one level or more (clap)");
    let set: Vec<PoseDynamics> = masses.iter().map(|m| own.with_body(m, &least)).collect();
    let design = |poses: &[PoseDynamics]| {
        bounded_workspace_design(&file, poses, 0.0, a.min_grasp, HumanBound::PAPER)
            .map(|d| d.k_c_npm)
            .map_err(|e| e.to_string())
    };
    let (k_own, k_fit, k_set) = (
        design(std::slice::from_ref(&own))?,
        design(&[own.with_body(top, &d)])?,
        design(&set)?,
    );
    Ok(PoseIdentified {
        name: file.name.clone(),
        linkage: a.linkage.clone(),
        pose_rad: a.pose_rad.clone(),
        levels: a
            .level
            .iter()
            .zip(&masses)
            .map(|(dir, m)| Level {
                folder: dir.clone(),
                principal_masses_kg: eig(m),
            })
            .collect(),
        mass_kg: rows(top),
        principal_masses_kg: eig(top),
        file_principal_masses_kg: eig(&own.mass_kg),
        damping_nspm: rows(&d),
        principal_damping_nspm: eig(&d),
        file_principal_damping_nspm: eig(&own.damping_nspm),
        least_damping_nspm: rows(&least),
        least_principal_damping_nspm: eig(&least),
        joints: Joints {
            damping_nmsprad: l.damping_nmsprad.clone(),
            damping_sd: l.sd[..n].to_vec(),
            friction_nm: l.friction_nm.clone(),
            friction_sd: l.sd[n..].to_vec(),
            misfit: l.misfit,
            unresolved: l.unresolved,
        },
        experiments: l
            .experiments
            .iter()
            .map(|e| Experiment {
                power_w: e.power_w,
                power_sd_w: e.power_sd_w,
                rate_sq: e.rate_sq.clone(),
                rate_abs: e.rate_abs.clone(),
            })
            .collect(),
        min_grasp_nspm: a.min_grasp,
        sigmas: a.sigmas,
        design_npm: Designs {
            file: k_own,
            fit: k_fit,
            set: k_set,
        },
    })
}

/// A symmetric matrix's eigenvalues, least first.
fn eig(m: &DMatrix<f64>) -> Vec<f64> {
    let mut e: Vec<f64> = m.clone().symmetric_eigenvalues().iter().copied().collect();
    e.sort_by(f64::total_cmp);
    e
}

/// A matrix as its rows.
fn rows(m: &DMatrix<f64>) -> Vec<Vec<f64>> {
    m.row_iter().map(|r| r.iter().copied().collect()).collect()
}

/// What `identify-pose` found at one pose of a linkage.
#[derive(Serialize)]
pub(crate) struct PoseIdentified {
    /// The linkage's name, and its file.
    name: String,
    linkage: PathBuf,
    pose_rad: Vec<f64>,
    levels: Vec<Level>,
    /// The mass matrix the hand feels (the highest level's), by rows.
    mass_kg: Vec<Vec<f64>>,
    principal_masses_kg: Vec<f64>,
    file_principal_masses_kg: Vec<f64>,
    /// The damping at the handle, by rows, and its eigenvalues in the
    /// file; the set's (sigmas down).
    damping_nspm: Vec<Vec<f64>>,
    principal_damping_nspm: Vec<f64>,
    file_principal_damping_nspm: Vec<f64>,
    least_damping_nspm: Vec<Vec<f64>>,
    least_principal_damping_nspm: Vec<f64>,
    joints: Joints,
    experiments: Vec<Experiment>,
    min_grasp_nspm: f64,
    sigmas: f64,
    /// The coupling proven on the file's pose, the fit and the set.
    design_npm: Designs,
}

/// One level's mass.
#[derive(Serialize)]
struct Level {
    folder: PathBuf,
    principal_masses_kg: Vec<f64>,
}

/// The joints' losses and their standard deviations.
#[derive(Serialize)]
struct Joints {
    damping_nmsprad: Vec<f64>,
    damping_sd: Vec<f64>,
    friction_nm: Vec<f64>,
    friction_sd: Vec<f64>,
    /// The fraction of the power the losses do not explain.
    misfit: f64,
    /// Combinations of the losses the experiments cannot tell apart.
    unresolved: usize,
}

/// One experiment's dissipated power and the rates it is fitted on.
#[derive(Serialize)]
struct Experiment {
    power_w: f64,
    power_sd_w: f64,
    rate_sq: Vec<f64>,
    rate_abs: Vec<f64>,
}

/// The coupling (N/m) proven on the file's pose, the fit and the set.
#[derive(Serialize)]
struct Designs {
    file: f64,
    fit: f64,
    set: f64,
}

impl fmt::Display for PoseIdentified {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        // (An eigenvalue that is zero may round below it: no "-0.0000".)
        let list = |v: &[f64], scale: f64| {
            v.iter()
                .map(|x| format!("{:.4}", if x.abs() < 1e-12 { 0.0 } else { x * scale }))
                .collect::<Vec<_>>()
                .join(", ")
        };
        let j = &self.joints;
        write!(
            f,
            "{} at q = {:?} rad, from {} levels:\n\
             principal masses (g): {} (the file's: {})\n\
             joints' damping (mN m s/rad): {} (+- {})\n\
             joints' friction (mN m): {} (+- {})\n\
             misfit {:.1}% of the power; {} combinations unresolved\n\
             damping at the handle (N s/m): {} (the file's: {}); {} sigma down: {}\n\
             coupling proven at b = 0 for every grasp of at least {} N s/m (paper's bound):\n  \
             the file's pose {:.0} N/m, the fit {:.0} N/m, the set {:.0} N/m (run this one)",
            self.name,
            self.pose_rad,
            self.levels.len(),
            list(&self.principal_masses_kg, 1e3),
            list(&self.file_principal_masses_kg, 1e3),
            list(&j.damping_nmsprad, 1e3),
            list(&j.damping_sd, 1e3),
            list(&j.friction_nm, 1e3),
            list(&j.friction_sd, 1e3),
            100.0 * j.misfit,
            j.unresolved,
            list(&self.principal_damping_nspm, 1.0),
            list(&self.file_principal_damping_nspm, 1.0),
            self.sigmas,
            list(&self.least_principal_damping_nspm, 1.0),
            self.min_grasp_nspm,
            self.design_npm.file,
            self.design_npm.fit,
            self.design_npm.set,
        )
    }
}

/// One level's records of `n` axes: `[pushed][axis]`, each read from
/// its [`record_file`] in `dir`.
fn level(dir: &Path, n: usize) -> Result<Vec<Vec<Log>>, String> {
    (0..n)
        .map(|pushed| {
            (0..n)
                .map(|axis| {
                    let name = record_file(pushed, axis).expect("three axes at most");
                    let path = dir.join(name);
                    let text = std::fs::read_to_string(&path)
                        .map_err(|e| format!("{}: {e}", path.display()))?;
                    Log::from_csv(&text, &path.display().to_string()).map_err(|e| e.to_string())
                })
                .collect()
        })
        .collect()
}

/// The folders' names, listed.
fn names(dirs: &[std::path::PathBuf]) -> String {
    dirs.iter()
        .map(|d| d.display().to_string())
        .collect::<Vec<_>>()
        .join(", ")
}
