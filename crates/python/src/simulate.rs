//! The simulator from Python: a scene file run headless (with `--set`
//! overrides), its signals as numpy arrays and its report as a dict.

use host_sim::{Report, Sample, Scene, Simulation};
use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;

/// Every tick's signals, one vector per field (per-axis fields flat,
/// `axes` values a tick).
#[derive(Default)]
struct Trace {
    t_s: Vec<f64>,
    handle_m: Vec<f64>,
    handle_mps: Vec<f64>,
    human_n: Vec<f64>,
    commanded_n: Vec<f64>,
    actuator_n: Vec<f64>,
    ve_m: Vec<f64>,
    coupling_n: Vec<f64>,
    energy_in_j: Vec<f64>,
}

impl Trace {
    fn push<const N: usize>(&mut self, s: &Sample<N>) {
        self.t_s.push(s.t_s);
        self.handle_m.extend(s.handle_m);
        self.handle_mps.extend(s.handle_mps);
        self.human_n.extend(s.human_n);
        self.commanded_n.extend(s.commanded_n);
        self.actuator_n.extend(s.actuator_n);
        self.ve_m.extend(s.ve_m);
        self.coupling_n.extend(s.coupling_n);
        self.energy_in_j.push(s.energy_in_j);
    }
}

fn run<const N: usize>(scene: Scene) -> Result<(Report, Trace), String> {
    let mut sim = Simulation::<N>::with_axes(scene).map_err(|e| e.to_string())?;
    let mut trace = Trace::default();
    let report = sim.run(|s| trace.push(s));
    Ok((report, trace))
}

/// Run the scene file `scene` headless, `set` overriding its fields as
/// `host-sim run --set` does (e.g. `["coupling.k_npm=40000"]`), and
/// return `(signals, report)`: the signals a dict of numpy arrays (`t_s`,
/// `energy_in_j` one value a tick; `handle_m`, `handle_mps`, `human_n`,
/// `commanded_n`, `actuator_n`, `ve_m`, `coupling_n` as (ticks, axes)),
/// the report a dict (stable, reason, peak_force_n, energy_in_j, ...).
/// The run releases the GIL.
#[pyfunction]
#[pyo3(signature = (scene, set=Vec::new()))]
pub(crate) fn simulate<'py>(
    py: Python<'py>,
    scene: PathBuf,
    set: Vec<String>,
) -> PyResult<(Bound<'py, PyDict>, Bound<'py, PyDict>)> {
    let (report, trace, axes) = py
        .detach(move || {
            let s = Scene::load(&scene, &set).map_err(|e| e.to_string())?;
            if s.plant.linkage.is_some() {
                return Err(format!(
                    "{}: a linkage scene; run it with host-sim",
                    scene.display()
                ));
            }
            match s.axis_count() {
                1 => run::<1>(s).map(|(r, t)| (r, t, 1)),
                3 => run::<3>(s).map(|(r, t)| (r, t, 3)),
                n => Err(format!("{}: {n} axes; 1 or 3 run here", scene.display())),
            }
        })
        .map_err(PyValueError::new_err)?;
    let ticks = trace.t_s.len();
    let signals = PyDict::new(py);
    signals.set_item("t_s", PyArray1::from_vec(py, trace.t_s))?;
    signals.set_item("energy_in_j", PyArray1::from_vec(py, trace.energy_in_j))?;
    let per_axis = |v: Vec<f64>| -> PyResult<Bound<'py, PyArray2<f64>>> {
        PyArray1::from_vec(py, v).reshape([ticks, axes])
    };
    signals.set_item("handle_m", per_axis(trace.handle_m)?)?;
    signals.set_item("handle_mps", per_axis(trace.handle_mps)?)?;
    signals.set_item("human_n", per_axis(trace.human_n)?)?;
    signals.set_item("commanded_n", per_axis(trace.commanded_n)?)?;
    signals.set_item("actuator_n", per_axis(trace.actuator_n)?)?;
    signals.set_item("ve_m", per_axis(trace.ve_m)?)?;
    signals.set_item("coupling_n", per_axis(trace.coupling_n)?)?;
    let r = PyDict::new(py);
    r.set_item("scene", &report.scene)?;
    r.set_item("stable", report.stable)?;
    r.set_item("reason", &report.reason)?;
    r.set_item("peak_force_n", report.peak_force_n)?;
    r.set_item("energy_in_j", report.energy_in_j)?;
    r.set_item("sim_seconds", report.sim_seconds)?;
    r.set_item("realtime_factor", report.realtime_factor)?;
    r.set_item("late_rms_n", report.late_rms_n.clone())?;
    Ok((signals, r))
}
