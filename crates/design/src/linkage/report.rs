//! A linkage's workspace design as a report: text for people, JSON for
//! programs.

use super::file::LinkageFile;
use super::proof::WorkspaceDesign;
use serde::Serialize;
use std::fmt;

/// The design over a linkage's workspace, with the recommended stiffness
/// `margin` below the boundary.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LinkageDesign {
    /// The device's name.
    pub name: String,
    /// The human assumption, in words.
    pub human: String,
    /// The least damping every grasp has (N s/m; 0: any passive hand).
    pub min_grasp_nspm: f64,
    /// The servo's period (s).
    pub period_s: f64,
    /// Boxes of joint angles the certificate bounded (for a design over
    /// given poses, the poses).
    pub poses: usize,
    /// Where the design is certified over the whole workspace: the
    /// stiffness the least damped pose found proves (N/m), which the
    /// design is at most `certificate_gap` (relative) below.
    pub found_k_c_npm: Option<f64>,
    /// The certificate's relative gap.
    pub certificate_gap: Option<f64>,
    /// The boundary stiffness (N/m) at `b_c_nspm`.
    pub k_c_npm: f64,
    /// The coupling's damping (N s/m).
    pub b_c_nspm: f64,
    /// The recommended stiffness, `margin` below the boundary (N/m).
    pub recommended_k_c_npm: f64,
    /// The margin, as a fraction of the boundary.
    pub margin: f64,
    /// The binding pose's joint angles (rad) and handle position (m).
    pub binding_q_rad: Vec<f64>,
    /// The handle's position there (m).
    pub binding_position_m: Vec<f64>,
    /// The least damped direction there (unit vector).
    pub binding_direction: Vec<f64>,
    /// The damping along it (N s/m).
    pub binding_damping_nspm: f64,
    /// The mass along it (kg).
    pub binding_mass_kg: f64,
    /// The frequency that binds (Hz), where one does (a bounded grasp).
    pub binding_frequency_hz: Option<f64>,
    /// The lightest and heaviest the handle is over the poses (kg).
    pub mass_range_kg: (f64, f64),
    /// The least and most damped (N s/m).
    pub damping_range_nspm: (f64, f64),
}

impl LinkageDesign {
    /// The report of `design` on `file`.
    pub fn new(file: &LinkageFile, design: &WorkspaceDesign, margin: f64) -> Self {
        let b = &design.binding;
        LinkageDesign {
            name: file.name.clone(),
            human: if let Some(h) = design.human {
                format!(
                    "no stiffer than Z_max = {} + {}/s in any direction (the paper's bound){}",
                    h.damping_nspm,
                    h.stiffness_npm,
                    if design.min_grasp_nspm > 0.0 {
                        format!(", with at least {} N s/m", design.min_grasp_nspm)
                    } else {
                        String::new()
                    }
                )
            } else if design.min_grasp_nspm > 0.0 {
                format!(
                    "a grasp of at least {} N s/m in every direction (a dead-man switch keeps force off without one)",
                    design.min_grasp_nspm
                )
            } else {
                "none: every passive hand (hands off)".to_string()
            },
            min_grasp_nspm: design.min_grasp_nspm,
            period_s: file.period_s,
            poses: design.poses,
            found_k_c_npm: design.certificate.as_ref().map(|c| c.found_k_c_npm),
            certificate_gap: design.certificate.as_ref().map(|c| c.gap),
            k_c_npm: design.k_c_npm,
            b_c_nspm: design.b_c_nspm,
            recommended_k_c_npm: design.k_c_npm * (1.0 - margin),
            margin,
            binding_q_rad: b.pose.q_rad.clone(),
            binding_position_m: b.pose.position_m.clone(),
            binding_direction: b.direction.clone(),
            binding_damping_nspm: b.damping_nspm,
            binding_mass_kg: b.mass_kg,
            binding_frequency_hz: b.frequency_hz,
            mass_range_kg: design.mass_range_kg,
            damping_range_nspm: design.damping_range_nspm,
        }
    }
}

/// A stiffness to four significant figures, however small.
pub fn stiffness(k: f64) -> String {
    if k >= 1000.0 {
        format!("{k:.0}")
    } else {
        let digits = (3 - k.abs().max(1e-12).log10().floor() as i32).clamp(0, 12) as usize;
        format!("{k:.digits$}")
    }
}

fn list(v: &[f64], scale: f64, digits: usize) -> String {
    let items: Vec<String> = v
        .iter()
        .map(|x| format!("{:.*}", digits, x * scale))
        .collect();
    format!("({})", items.join(", "))
}

impl fmt::Display for LinkageDesign {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "Linkage {}, impedance display at T = {} ms; human: {}",
            self.name,
            self.period_s * 1e3,
            self.human
        )?;
        match (self.found_k_c_npm, self.certificate_gap) {
            (Some(found), Some(gap)) => writeln!(
                f,
                "  workspace: every pose inside the limits, by branch and bound over {} box{} \
                 (the least damped pose found proves {} N/m; the certificate is {:.1e} below it)",
                self.poses,
                if self.poses == 1 { "" } else { "es" },
                stiffness(found),
                gap
            )?,
            _ => writeln!(f, "  workspace: {} poses", self.poses)?,
        }
        writeln!(
            f,
            "  the handle weighs {:.1} to {:.1} g, damping {:.4} to {:.4} N s/m (over a grid)",
            self.mass_range_kg.0 * 1e3,
            self.mass_range_kg.1 * 1e3,
            self.damping_range_nspm.0,
            self.damping_range_nspm.1
        )?;
        writeln!(
            f,
            "  proven coupling: k_c = {} N/m at b_c = {} N s/m (the boundary, every pose)",
            stiffness(self.k_c_npm),
            self.b_c_nspm
        )?;
        writeln!(
            f,
            "  recommended: k_c = {} N/m, {:.0}% below the boundary",
            stiffness(self.recommended_k_c_npm),
            self.margin * 100.0
        )?;
        write!(
            f,
            "  binds at q = {} deg, handle at {} mm, direction {}: {:.4} N s/m, {:.1} g",
            list(&self.binding_q_rad, 180.0 / std::f64::consts::PI, 1),
            list(&self.binding_position_m, 1e3, 1),
            list(&self.binding_direction, 1.0, 3),
            self.binding_damping_nspm,
            self.binding_mass_kg * 1e3
        )?;
        match self.binding_frequency_hz {
            Some(hz) => write!(f, ", at {hz:.2} Hz"),
            None => Ok(()),
        }
    }
}
