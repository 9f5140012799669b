//! `twoport zrange` and `twoport plot`: the impedance range and the
//! paper's figures.

use crate::args::*;
use crate::run::*;
use serde::Serialize;
use std::f64::consts::PI;
use std::fmt;
use std::path::PathBuf;
use twoport_design::analysis::{self, Analysis};
use twoport_design::network::HumanBound;
use twoport_design::DeviceAxis;
use twoport_design::{figures, plot};

pub(crate) fn zrange(
    d: &Display<ZrangeImpedance, ZrangeAdmittance>,
    _: Option<&DeviceAxis>,
) -> Reported {
    let (common, points) = match d {
        Display::Impedance(z) => (&z.gains.common, z.points),
        Display::Admittance(z) => (&z.gains.common, z.points),
    };
    if points < 2 {
        return Err(format!("--points {points}: need at least 2"));
    }
    let s = designer(common, None)?;
    let pose = single(&s, "zrange")?;
    let nyq = pose.plant.nyquist();
    let lo = 2.0 * PI * 0.1;
    let omegas = analysis::log_grid(lo, nyq, points);
    let a = Analysis::on(&pose.plant, &omegas);
    let range = match d {
        Display::Impedance(z) => {
            let (k, b) = (gain("k", z.gains.k)?, gain("b", z.gains.b)?);
            analysis::impedance_range_impedance(&a, k, b)
        }
        Display::Admittance(z) => {
            let g = &z.gains;
            analysis::impedance_range_admittance(
                &a,
                (gain("kp", g.kp)?, gain("bp", g.bp)?),
                (g.m, gain("b", g.b)?),
            )
        }
    }
    .ok_or("the gains do not make a valid coupling")?;
    let pair = |c: num_complex::Complex64| [c.re, c.im];
    reported(ZRange {
        frequency_hz: omegas.iter().map(|w| w / (2.0 * PI)).collect(),
        z_min: range.iter().map(|r| pair(r.0)).collect(),
        z_max: range.iter().map(|r| pair(r.1)).collect(),
    })
}

/// The impedance range over frequency: `Z_min` and `Z_max` (N s/m) as
/// `[re, im]` pairs.
#[derive(Serialize)]
struct ZRange {
    frequency_hz: Vec<f64>,
    z_min: Vec<[f64; 2]>,
    z_max: Vec<[f64; 2]>,
}

impl fmt::Display for ZRange {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{:>12} {:>14} {:>14}",
            "freq (Hz)", "|Z_min| N s/m", "|Z_max| N s/m"
        )?;
        let norm = |z: &[f64; 2]| z[0].hypot(z[1]);
        for ((hz, lo), hi) in self.frequency_hz.iter().zip(&self.z_min).zip(&self.z_max) {
            write!(f, "\n{hz:>12.3} {:>14.4e} {:>14.4e}", norm(lo), norm(hi))?;
        }
        Ok(())
    }
}

pub(crate) fn plot_fig(p: &PlotArgs, _: Option<&DeviceAxis>) -> Reported {
    let s = designer(&p.common, None)?;
    let a = &single(&s, "plot")?.analysis;
    let t = s.period_s();
    let bi = a.impedance_bound(Some(HumanBound::PAPER));
    let (k, b) = analysis::max_stiffness(a, &bi, gain("b-impedance", p.b_impedance)?)
        .map(|k| (k, p.b_impedance))
        .ok_or("no impedance coupling meets the bound at --b-impedance")?;
    let kp = analysis::regulator_tf(k, b, t).map_err(|e| e.to_string())?;
    let ba = a.admittance_bound(&kp, Some(HumanBound::PAPER));
    let m = analysis::min_mass(a, &ba, gain("b-admittance", p.b_admittance)?)
        .ok_or("no admittance coupling meets the bound at --b-admittance")?;
    let fig = match p.figure {
        Fig::Fig8 => figures::fig8(a, k, b),
        Fig::Fig9 => figures::fig9(a, (k, b), (m, p.b_admittance)),
        Fig::Fig10 => figures::fig10(a, (k, b), (k, b), (m, p.b_admittance)),
        Fig::Workspace => return Err("plot workspace takes --device LINKAGE".into()),
    }
    .map_err(|e| e.to_string())?;
    plot::render(&fig, &p.out).map_err(|e| e.to_string())?;
    reported(PaperFigure {
        out: p.out.clone(),
        k_c_npm: k,
        b_c_nspm: b,
        m_c_kg: m,
        b_ca_nspm: p.b_admittance,
    })
}

/// One of the paper's figures written, and the couplings it drew.
#[derive(Serialize)]
struct PaperFigure {
    out: PathBuf,
    /// The impedance coupling drawn.
    k_c_npm: f64,
    b_c_nspm: f64,
    /// The admittance coupling drawn.
    m_c_kg: f64,
    b_ca_nspm: f64,
}

impl fmt::Display for PaperFigure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "wrote {} (k_c = {:.0} N/m, b_c = {} N s/m, m_c = {:.3} kg, b_cA = {} N s/m)",
            self.out.display(),
            self.k_c_npm,
            self.b_c_nspm,
            self.m_c_kg,
            self.b_ca_nspm
        )
    }
}

/// Poses per joint on a workspace map's grid, by joint count.
const MAP_PER_JOINT: [usize; 3] = [41, 41, 15];

/// `plot workspace --device LINKAGE`: the stiffness each pose proves on
/// its own, over the workspace (a 3-DOF linkage seen from above), the
/// pose that binds `design`'s proof marked.
pub(crate) fn plot_workspace(p: &PlotArgs) -> Reported {
    use twoport_design::linkage::{certified_design, workspace_design, LinkageFile};
    let path = p
        .common
        .device
        .as_ref()
        .ok_or("plot workspace: give --device LINKAGE")?;
    let file = LinkageFile::load(path).map_err(|e| e.to_string())?;
    let grasp = match (p.min_grasp, p.common.no_human) {
        (Some(g), _) => g,
        (None, true) => 0.0,
        (None, false) => {
            return Err(format!(
                "--device {}: give --no-human (every passive hand) or --min-grasp B",
                path.display()
            ))
        }
    };
    let n = file.geometry.joints();
    // The certified design (its binding pose is the mark) and a grid to
    // draw.
    let whole = certified_design(&file, 0.0, grasp, None).map_err(|e| e.to_string())?;
    let mut poses = file.workspace(MAP_PER_JOINT[n - 1]);
    poses.push(whole.binding.pose.clone());
    let at = |x: &[f64]| {
        let mm = |i: usize| x.get(i).copied().unwrap_or(0.0) * 1e3;
        (mm(0), mm(1))
    };
    let points = poses
        .iter()
        .filter_map(|pose| {
            let one = workspace_design(&file, std::slice::from_ref(pose), 0.0, grasp).ok()?;
            let (x, y) = at(&pose.position_m);
            Some((x, y, one.k_c_npm))
        })
        .collect();
    let hand = if grasp > 0.0 {
        format!("every grasp of at least {grasp} N s/m")
    } else {
        "every passive hand".to_string()
    };
    let map = plot::Map {
        title: format!("{}: proven k_c, {hand}", file.name),
        x_label: "x (mm)".into(),
        y_label: if n == 1 { "".into() } else { "y (mm)".into() },
        value_label: "k_c (N/m), b_c = 0".into(),
        points,
        mark: Some(at(&whole.binding.pose.position_m)),
    };
    plot::render_map(&map, &p.out).map_err(|e| e.to_string())?;
    reported(WorkspaceMap {
        out: p.out.clone(),
        poses: poses.len(),
        k_c_npm: whole.k_c_npm,
        min_grasp_nspm: grasp,
    })
}

/// A workspace map written, and the stiffness the whole workspace proves.
#[derive(Serialize)]
struct WorkspaceMap {
    out: PathBuf,
    /// Poses drawn.
    poses: usize,
    /// The certified stiffness over the whole workspace, at b_c = 0.
    k_c_npm: f64,
    /// The least grasp proven for (0: every passive hand).
    min_grasp_nspm: f64,
}

impl fmt::Display for WorkspaceMap {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "wrote {} ({} poses; the whole workspace is proven at k_c = {} N/m)",
            self.out.display(),
            self.poses,
            twoport_design::linkage::stiffness(self.k_c_npm)
        )
    }
}
