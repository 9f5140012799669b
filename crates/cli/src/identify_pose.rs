//! `twoport identify-pose`: a linkage's sines at one pose (each level a
//! folder of one experiment per Cartesian axis, every axis recorded) to
//! the mass matrix the hand feels there, the joints' damping and friction
//! from the energy the sines dissipate, and the coupling proven on the
//! file's own pose, the identified one and the set.

use crate::args::IdentifyPoseArgs;
use nalgebra::DMatrix;
use serde_json::json;
use std::path::Path;
use twoport_design::linkage::{bounded_workspace_design, LinkageFile, PoseDynamics};
use twoport_design::network::HumanBound;
use twoport_identify::log::Log;
use twoport_identify::pose::{fit::mass, losses, record_file, PoseMeasured, AXES};

pub(crate) fn identify_pose(a: &IdentifyPoseArgs) -> Result<(), String> {
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
    let l = losses::fit(&levels.concat(), &own.jacobian, a.skip).map_err(|e| {
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
    let eig = |m: &DMatrix<f64>| {
        let mut e: Vec<f64> = m.clone().symmetric_eigenvalues().iter().copied().collect();
        e.sort_by(f64::total_cmp);
        e
    };
    let rows = |m: &DMatrix<f64>| -> Vec<Vec<f64>> {
        m.row_iter().map(|r| r.iter().copied().collect()).collect()
    };
    if a.json {
        let v = json!({
            "linkage": a.linkage,
            "pose_rad": a.pose_rad,
            "levels": a.level.iter().zip(&masses).map(|(dir, m)| json!({
                "folder": dir,
                "principal_masses_kg": eig(m),
            })).collect::<Vec<_>>(),
            "mass_kg": rows(top),
            "damping_nspm": rows(&d),
            "least_damping_nspm": rows(&least),
            "joints": {
                "damping_nmsprad": l.damping_nmsprad,
                "damping_sd": &l.sd[..n],
                "friction_nm": l.friction_nm,
                "friction_sd": &l.sd[n..],
                "misfit": l.misfit,
                "unresolved": l.unresolved,
            },
            "experiments": l.experiments.iter().map(|e| json!({
                "power_w": e.power_w,
                "power_sd_w": e.power_sd_w,
                "rate_sq": e.rate_sq,
                "rate_abs": e.rate_abs,
            })).collect::<Vec<_>>(),
            "min_grasp_nspm": a.min_grasp,
            "sigmas": a.sigmas,
            "design_npm": { "file": k_own, "fit": k_fit, "set": k_set },
        });
        say!("{v}\n");
        return Ok(());
    }
    // (An eigenvalue that is zero may round below it: no "-0.0000".)
    let list = |v: &[f64], scale: f64| {
        v.iter()
            .map(|x| format!("{:.4}", if x.abs() < 1e-12 { 0.0 } else { x * scale }))
            .collect::<Vec<_>>()
            .join(", ")
    };
    say!(
        "{} at q = {:?} rad, from {} levels:\n\
         principal masses (g): {} (the file's: {})\n\
         joints' damping (mN m s/rad): {} (+- {})\n\
         joints' friction (mN m): {} (+- {})\n\
         misfit {:.1}% of the power; {} combinations unresolved\n\
         damping at the handle (N s/m): {} (the file's: {}); {} sigma down: {}\n\
         coupling proven at b = 0 for every grasp of at least {} N s/m (paper's bound):\n  \
         the file's pose {:.0} N/m, the fit {:.0} N/m, the set {:.0} N/m (run this one)\n",
        file.name,
        a.pose_rad,
        levels.len(),
        list(&eig(top), 1e3),
        list(&eig(&own.mass_kg), 1e3),
        list(&l.damping_nmsprad, 1e3),
        list(&l.sd[..n], 1e3),
        list(&l.friction_nm, 1e3),
        list(&l.sd[n..], 1e3),
        100.0 * l.misfit,
        l.unresolved,
        list(&eig(&d), 1.0),
        list(&eig(&own.damping_nspm), 1.0),
        a.sigmas,
        list(&eig(&least), 1.0),
        a.min_grasp,
        k_own,
        k_fit,
        k_set,
    );
    Ok(())
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
