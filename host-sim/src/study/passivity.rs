//! What the passivity layer buys and costs: each scene of a folder run with
//! the layer off, on, and at the scene's passive reference settings.

use super::table1::case_files;
use crate::Error;
use crate::{Scene, Simulation};
use std::path::Path;

/// One run's outcome.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Outcome {
    /// Stable by the simulator's criterion.
    pub stable: bool,
    /// Why not, when not.
    pub reason: Option<String>,
    /// RMS oscillatory force over the two halves of the final quiet
    /// second (N).
    pub late_rms_n: [f64; 2],
    /// Largest delivered force (N).
    pub peak_force_n: f64,
}

/// One scene's row.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Row {
    /// The scene file's stem.
    pub scene: String,
    /// The layer off.
    pub off: Outcome,
    /// The layer on.
    pub on: Outcome,
    /// Energy the layer dissipated (J).
    pub dissipated_j: f64,
    /// Ticks on which it acted.
    pub active_ticks: u64,
    /// RMS of the delivered force's difference between the layer on and
    /// the passive reference, over the run (N).
    pub force_error_rms_n: f64,
    /// RMS of the reference's delivered force (N), to scale that error.
    pub reference_force_rms_n: f64,
}

fn outcome(r: &crate::engine::sim::Report) -> Outcome {
    Outcome {
        stable: r.stable,
        reason: r.reason.clone(),
        late_rms_n: r.late_rms_n[0],
        peak_force_n: r.peak_force_n,
    }
}

/// Run the scene at `path` with `sets`, returning the report and the
/// delivered force of every tick.
fn run(path: &Path, sets: &[String]) -> Result<(crate::engine::sim::Report, Vec<f64>), Error> {
    let scene = Scene::load(path, sets)?;
    let mut forces = Vec::new();
    let report = Simulation::new(scene)?.run(|s| forces.push(s.actuator_n[0]));
    Ok((report, forces))
}

/// One scene: off, on, reference. An error if the scene has no
/// `[passivity]` table.
pub fn row(path: &Path) -> Result<Row, Error> {
    let scene = Scene::load(path, &[])?;
    let spec = scene.passivity.ok_or(format!(
        "{}: no [passivity] table to compare",
        path.display()
    ))?;
    let off_set = ["passivity.enabled=false".to_string()];
    let (off, _) = run(path, &off_set)?;
    let (on, on_f) = run(path, &["passivity.enabled=true".to_string()])?;
    let mut ref_sets = off_set.to_vec();
    ref_sets.extend(spec.reference.iter().cloned());
    let (_, ref_f) = run(path, &ref_sets)?;
    // A run that failed stops early: compare what both have.
    let n = on_f.len().min(ref_f.len()).max(1);
    let err2: f64 = on_f.iter().zip(&ref_f).map(|(a, b)| (a - b).powi(2)).sum();
    let ref2: f64 = ref_f.iter().take(n).map(|b| b * b).sum();
    let p = on.passivity.clone();
    Ok(Row {
        scene: path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default(),
        off: outcome(&off),
        on: outcome(&on),
        dissipated_j: p.as_ref().map_or(0.0, |p| p.dissipated_j),
        active_ticks: p.as_ref().map_or(0, |p| p.active_ticks),
        force_error_rms_n: (err2 / n as f64).sqrt(),
        reference_force_rms_n: (ref2 / n as f64).sqrt(),
    })
}

/// Every scene in `folder`; `step` is called after each.
pub fn table(folder: &Path, step: &mut dyn FnMut()) -> Result<Vec<Row>, Error> {
    case_files(folder)?
        .iter()
        .map(|f| {
            let r = row(f);
            step();
            r
        })
        .collect()
}

/// The rows as a Markdown table.
pub fn markdown(rows: &[Row]) -> String {
    let verdict = |o: &Outcome| {
        if o.stable {
            format!("stable ({:.2} N late RMS)", o.late_rms_n[1])
        } else {
            format!(
                "**unstable**: {}",
                o.reason
                    .as_deref()
                    .unwrap_or("")
                    .split(':')
                    .next()
                    .unwrap_or("")
            )
        }
    };
    let mut s = String::from(
        "| scene | layer off | layer on | dissipated | active ticks | force error vs passive reference | reference force |\n\
         | --- | --- | --- | --- | --- | --- | --- |\n",
    );
    for r in rows {
        s += &format!(
            "| {} | {} | {} | {:.3} J | {} | {:.2} N RMS | {:.2} N RMS |\n",
            r.scene,
            verdict(&r.off),
            verdict(&r.on),
            r.dissipated_j,
            r.active_ticks,
            r.force_error_rms_n,
            r.reference_force_rms_n
        );
    }
    s
}
