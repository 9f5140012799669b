//! What accuracy costs in time: every integrator at every sub-step count,
//! with the board's f32 controller and with the same laws in f64, on a
//! linear scene (reference: exact ZOH, which is exact there) and on a
//! nonlinear one (reference: RK4 at a 1 us step), error against cost. The
//! references run the f64 controller, so the f32 rows show the board's
//! rounding as an error floor.

use crate::engine::plant::Method;
use crate::engine::scene::Precision;
use crate::Error;
use crate::{Scene, Simulation};
use std::path::Path;
use std::time::Instant;

/// One cell of the study.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Cell {
    /// Scene label.
    pub scene: String,
    /// Integrator.
    pub method: String,
    /// Sub-steps per 1 ms tick.
    pub substeps: u32,
    /// The controller's float type, `"f32"` (the board's) or `"f64"`.
    pub controller: String,
    /// Max handle-position error over the run, relative to the reference's
    /// peak displacement; `None` when the run did not finish.
    pub error: Option<f64>,
    /// Wall time per simulated millisecond (ns), best of three.
    pub ns_per_sim_ms: f64,
    /// Why the run failed, or the integrator's stability warning.
    pub note: Option<String>,
}

/// Sub-step counts studied.
pub const SUBSTEPS: [u32; 9] = [1, 2, 4, 8, 16, 32, 64, 128, 256];
/// Methods studied.
pub const METHODS: [Method; 4] = [
    Method::ExactZoh,
    Method::SemiImplicitEuler,
    Method::Rk4,
    Method::Euler,
];

/// Controller float types studied.
pub const CONTROLLERS: [Precision; 2] = [Precision::F32, Precision::F64];

fn with(scene: &Scene, method: Method, substeps: u32, controller: Precision) -> Scene {
    let mut s = scene.clone();
    s.integrator.method = method;
    s.integrator.substeps = substeps;
    s.integrator.on_linear = true;
    s.integrator.controller = controller;
    s
}

/// Handle path and the best wall time of three runs.
fn path(scene: &Scene) -> Result<(Vec<f64>, f64, Option<String>), Error> {
    let mut best = f64::INFINITY;
    let mut out = (Vec::new(), None);
    for _ in 0..3 {
        let mut sim = Simulation::new(scene.clone())?;
        let mut xs = Vec::with_capacity(sim.total_ticks() as usize);
        let t0 = Instant::now();
        let r = sim.run(|s| xs.push(s.handle_m[0]));
        best = best.min(t0.elapsed().as_secs_f64());
        let note = r.reason.clone().or(r.integrator_warning.clone());
        out = (xs, note);
        if r.reason.is_some() {
            break; // a failed run is not timed further
        }
    }
    Ok((out.0, best, out.1))
}

/// Run the study on one scene against `reference`.
pub fn study(label: &str, scene: &Scene, reference: (Method, u32)) -> Result<Vec<Cell>, Error> {
    let (want, _, _) = path(&with(scene, reference.0, reference.1, Precision::F64))?;
    let peak = want.iter().fold(0.0f64, |m, x| m.max(x.abs())).max(1e-12);
    let sim_ms = scene.duration_s * 1e3;
    let mut cells = Vec::new();
    for method in METHODS {
        for n in SUBSTEPS {
            if method == Method::ExactZoh && n > 16 {
                continue; // exact already; more sub-steps only cost
            }
            for controller in CONTROLLERS {
                let (got, wall, note) = path(&with(scene, method, n, controller))?;
                let error = (got.len() == want.len())
                    .then(|| {
                        got.iter()
                            .zip(&want)
                            .map(|(a, b)| (a - b).abs())
                            .fold(0.0, f64::max)
                            / peak
                    })
                    .filter(|e| e.is_finite());
                cells.push(Cell {
                    scene: label.to_string(),
                    method: method.name().to_string(),
                    substeps: n,
                    controller: controller.name().to_string(),
                    error,
                    ns_per_sim_ms: wall * 1e9 / sim_ms,
                    note,
                });
            }
        }
    }
    Ok(cells)
}

/// A scene of the study and its converged reference.
pub struct StudyScene {
    /// Label for the table.
    pub label: String,
    /// The scene.
    pub scene: Scene,
    /// Reference method and sub-steps.
    pub reference: (Method, u32),
}

/// The two scenes of the study, from the repository root.
pub fn scenes(root: &Path) -> Result<Vec<StudyScene>, Error> {
    let load = |f: &str, sets: &[&str]| {
        let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
        let mut s = Scene::load(&root.join(f), &sets).map_err(|e| e.to_string())?;
        s.plant.model = root.join("models/excalibur.toml");
        Ok::<Scene, Error>(s)
    };
    Ok(vec![
        StudyScene {
            label: "linear: table1/impedance_bilateral_maximum (5-DOF, 5.5 s)".into(),
            scene: load("scenes/table1/impedance_bilateral_maximum.toml", &[])?,
            reference: (Method::ExactZoh, 1),
        },
        StudyScene {
            label: "nonlinear: stiff_wall + 2 N Coulomb friction (3 s)".into(),
            scene: load(
                "scenes/stiff_wall.toml",
                &["duration_s=3", "effects.coulomb.force_n=2.0"],
            )?,
            reference: (Method::Rk4, 1000),
        },
    ])
}

/// The study as a markdown table.
pub fn markdown(cells: &[Cell]) -> String {
    let mut s = String::from(
        "| scene | method | sub-steps | controller | max error / peak | ns per simulated ms | note |\n| --- | --- | --- | --- | --- | --- | --- |\n",
    );
    for c in cells {
        let err = c.error.map_or("diverged".into(), |e| format!("{e:.2e}"));
        let note = c.note.clone().unwrap_or_default().replace('|', "/");
        s += &format!(
            "| {} | {} | {} | {} | {} | {:.0} | {} |\n",
            c.scene, c.method, c.substeps, c.controller, err, c.ns_per_sim_ms, note
        );
    }
    s
}
