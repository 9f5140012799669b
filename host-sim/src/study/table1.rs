//! The paper's Table I: every VE state and grasp at the theoretical gains,
//! then the boundaries swept as the paper did.

use super::sweep::marginal;
use crate::Error;
use crate::{Scene, Simulation};
use std::path::{Path, PathBuf};
use twoport_control::servo::Display;

/// One case of the table.
#[derive(Clone, Debug, PartialEq)]
pub struct Case {
    /// The scene file's stem, e.g. `impedance_bilateral_maximum`.
    pub case: String,
    /// Its display.
    pub display: Display,
    /// Whether it is stable at the theoretical gains.
    pub stable_at_theoretical_gains: bool,
    /// The swept boundary: the greatest stable `k_cI` (N/m) or the least
    /// stable `m_cA` (kg); `None` where the sweep found none.
    pub marginal: Option<f64>,
}

/// The whole table.
#[derive(Clone, Debug, PartialEq)]
pub struct Table1 {
    /// Each case, by file name.
    pub cases: Vec<Case>,
    /// The impedance display's boundary over its cases (N/m).
    pub impedance_boundary_k: Option<f64>,
    /// The admittance display's boundary over its cases (kg).
    pub admittance_boundary_m: Option<f64>,
}

impl Table1 {
    /// Whether every case is stable at the theoretical gains.
    pub fn all_stable(&self) -> bool {
        self.cases.iter().all(|c| c.stable_at_theoretical_gains)
    }
}

/// The `.toml` scenes in `folder`, sorted.
pub fn case_files(folder: &Path) -> Result<Vec<PathBuf>, Error> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(folder)
        .map_err(|e| format!("{}: {e}", folder.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    files.sort();
    if files.is_empty() {
        return Err(sim_err!("{}: no scenes", folder.display()));
    }
    Ok(files)
}

/// Run the table over the scenes in `folder`, each with the overrides
/// `sets`; `step` is called after each case.
pub fn table1(folder: &Path, sets: &[String], step: &mut dyn FnMut()) -> Result<Table1, Error> {
    let mut cases = Vec::new();
    let (mut k_bound, mut m_bound) = (f64::INFINITY, 0.0f64);
    for f in case_files(folder)? {
        let scene = Scene::load(&f, sets)?;
        let display = scene.display;
        let report = Simulation::new(scene)?.run(|_| {});
        let m = match display {
            Display::Impedance => {
                marginal(&f, sets, "coupling.k", (51_000.0, 2.0e6), 0.005, &mut || {}).ok()
            }
            Display::Admittance => {
                marginal(&f, sets, "coupling.m", (5.0, 0.01), 0.005, &mut || {}).ok()
            }
        };
        match (display, m) {
            (Display::Impedance, Some(k)) => k_bound = k_bound.min(k),
            (Display::Admittance, Some(mm)) => m_bound = m_bound.max(mm),
            _ => {}
        }
        cases.push(Case {
            case: f
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default(),
            display,
            stable_at_theoretical_gains: report.stable,
            marginal: m,
        });
        step();
    }
    Ok(Table1 {
        cases,
        impedance_boundary_k: k_bound.is_finite().then_some(k_bound),
        admittance_boundary_m: (m_bound > 0.0).then_some(m_bound),
    })
}
