//! A device model from Python: a model file's path, or matrices given as
//! arrays (checked as a file's are), or the paper's Excalibur.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use std::fmt::Write;
use std::path::PathBuf;
use twoport_design::DeviceModel;

/// A device model: `M q'' + D q' + K q = G [f_h, f_a]`, read by `C_v`
/// (and `C_f` for a force sensor), sampled every `period_s`. Build one
/// with `Model.load(path)` or `Model.from_arrays(...)`; every designer
/// call takes one where it takes a model file.
#[pyclass(frozen, module = "twoport")]
pub(crate) struct Model {
    pub(crate) inner: DeviceModel,
}

/// A model argument: a `Model`, a model file's path, a list of them (the
/// poses of one axis: a design is proven for all), or None (the paper's
/// Excalibur).
#[derive(FromPyObject)]
pub(crate) enum ModelArg {
    Model(Py<Model>),
    Path(PathBuf),
    Poses(Vec<Pose>),
}

/// One pose in a list of them.
#[derive(FromPyObject)]
pub(crate) enum Pose {
    Model(Py<Model>),
    Path(PathBuf),
}

impl Pose {
    pub(crate) fn load(self) -> PyResult<DeviceModel> {
        match self {
            Pose::Model(m) => Ok(m.get().inner.clone()),
            Pose::Path(p) => load(&p),
        }
    }
}

impl ModelArg {
    /// The poses, the Excalibur for None; a file that is not a model
    /// raises naming it, and so does an empty list.
    pub(crate) fn poses(arg: Option<ModelArg>) -> PyResult<Vec<DeviceModel>> {
        match arg {
            Some(ModelArg::Model(m)) => Ok(vec![m.get().inner.clone()]),
            Some(ModelArg::Path(p)) => Ok(vec![load(&p)?]),
            Some(ModelArg::Poses(v)) if v.is_empty() => Err(PyValueError::new_err(
                "an empty list of poses: give at least one model",
            )),
            Some(ModelArg::Poses(v)) => v.into_iter().map(Pose::load).collect(),
            None => Ok(vec![load(&PathBuf::from(
                twoport_design::model::EXCALIBUR_PATH,
            ))?]),
        }
    }
}

/// A device file's axes, each the list of its poses' models (a design for
/// an axis passes its list): `{"name": ..., "axes": {"x": [Model, ...]}}`.
#[pyfunction]
pub(crate) fn load_device<'py>(
    py: Python<'py>,
    path: PathBuf,
) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
    let d = twoport_design::Device::load(&path)
        .map_err(|e| PyValueError::new_err(format!("{}: {e}", path.display())))?;
    let axes = pyo3::types::PyDict::new(py);
    for a in d.axes {
        let poses = a
            .models
            .into_iter()
            .map(|m| Py::new(py, Model { inner: m }))
            .collect::<PyResult<Vec<_>>>()?;
        axes.set_item(a.name, poses)?;
    }
    let out = pyo3::types::PyDict::new(py);
    out.set_item("name", d.name)?;
    out.set_item("axes", axes)?;
    Ok(out)
}

fn load(path: &std::path::Path) -> PyResult<DeviceModel> {
    DeviceModel::load_or_excalibur(path)
        .map_err(|e| PyValueError::new_err(format!("{}: {e}", path.display())))
}

/// `rows` as a TOML array of arrays (the model file's form).
fn matrix(name: &str, rows: &[Vec<f64>]) -> String {
    let mut s = format!("{name} = [");
    for (i, r) in rows.iter().enumerate() {
        if i > 0 {
            s.push_str(", ");
        }
        s.push('[');
        for (j, v) in r.iter().enumerate() {
            if j > 0 {
                s.push_str(", ");
            }
            // Debug prints a float so that it reads back the same.
            let _ = write!(s, "{v:?}");
        }
        s.push(']');
    }
    s.push_str("]\n");
    s
}

#[pymethods]
impl Model {
    /// Read a model file (TOML).
    #[staticmethod]
    fn load(path: PathBuf) -> PyResult<Model> {
        Ok(Model {
            inner: self::load(&path)?,
        })
    }

    /// A model from its matrices (any sequence of rows: lists or numpy
    /// arrays), checked as a model file is; an error names the field.
    #[staticmethod]
    #[allow(clippy::too_many_arguments)]
    #[pyo3(signature = (M, D, K, G, C_v, *, period_s, peak_force_n, continuous_force_n,
                        C_f=None, load_cell_pole_rad_s=None, delay_samples=None,
                        latency_s=None, name="a model from arrays".to_string()))]
    #[allow(non_snake_case)]
    fn from_arrays(
        M: Vec<Vec<f64>>,
        D: Vec<Vec<f64>>,
        K: Vec<Vec<f64>>,
        G: Vec<Vec<f64>>,
        C_v: Vec<Vec<f64>>,
        period_s: f64,
        peak_force_n: f64,
        continuous_force_n: f64,
        C_f: Option<Vec<Vec<f64>>>,
        load_cell_pole_rad_s: Option<f64>,
        delay_samples: Option<u32>,
        latency_s: Option<f64>,
        name: String,
    ) -> PyResult<Model> {
        // TOML has no NaN of its own: name a number that is not one here.
        let scalars = [
            ("period_s", Some(period_s)),
            ("peak_force_n", Some(peak_force_n)),
            ("continuous_force_n", Some(continuous_force_n)),
            ("load_cell_pole_rad_s", load_cell_pole_rad_s),
            ("latency_s", latency_s),
        ];
        for (n, v) in scalars {
            if let Some(v) = v.filter(|v| !v.is_finite()) {
                return Err(PyValueError::new_err(format!(
                    "{name}: {n} = {v}: not a finite number"
                )));
            }
        }
        let matrices = [("M", &M), ("D", &D), ("K", &K), ("G", &G), ("C_v", &C_v)];
        for (n, m) in matrices
            .iter()
            .copied()
            .chain(C_f.as_ref().map(|c| ("C_f", c)))
        {
            for (i, r) in m.iter().enumerate() {
                if let Some((j, v)) = r.iter().enumerate().find(|(_, v)| !v.is_finite()) {
                    return Err(PyValueError::new_err(format!(
                        "{name}: {n}[{i}][{j}] = {v}: not a finite number"
                    )));
                }
            }
        }
        let mut t = format!(
            "name = {name:?}\nperiod_s = {period_s:?}\npeak_force_n = {peak_force_n:?}\ncontinuous_force_n = {continuous_force_n:?}\n"
        );
        if let Some(p) = load_cell_pole_rad_s {
            let _ = writeln!(t, "load_cell_pole_rad_s = {p:?}");
        }
        if let Some(d) = delay_samples {
            let _ = writeln!(t, "delay_samples = {d}");
        }
        if let Some(l) = latency_s {
            let _ = writeln!(t, "latency_s = {l:?}");
        }
        for (n, m) in matrices {
            t += &matrix(n, m);
        }
        if let Some(c) = &C_f {
            t += &matrix("C_f", c);
        }
        DeviceModel::from_toml(&t, &name)
            .map(|inner| Model { inner })
            .map_err(|e| PyValueError::new_err(e.to_string()))
    }

    /// The model's name.
    #[getter]
    fn name(&self) -> String {
        self.inner.name.clone()
    }

    /// Its sample period (s).
    #[getter]
    fn period_s(&self) -> f64 {
        self.inner.period_s
    }

    /// Its degrees of freedom.
    /// Latency from sampling to the force's change (s), beyond
    /// `delay_samples` whole ticks.
    #[getter]
    fn latency_s(&self) -> f64 {
        self.inner.latency_s
    }

    #[getter]
    fn dof(&self) -> usize {
        self.inner.dof()
    }

    fn __repr__(&self) -> String {
        format!(
            "Model({:?}: {} DOF, T = {} s)",
            self.inner.name,
            self.inner.dof(),
            self.inner.period_s
        )
    }
}
