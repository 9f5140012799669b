//! Teleoperators from Python: two models, Lawrence's four-channel gains
//! and the channel's delay, proven, designed, and searched on the exact
//! sampled loop.

use crate::model::Pose;
use pyo3::exceptions::{PyAttributeError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use twoport_control::teleop::FourChannelGains;
use twoport_design::designer::{TeleopCheckReport, TeleopDesigner};
use twoport_design::network::HumanBound;
use twoport_design::verify::{verify_law, Hand, TeleopLaw, WaveGains};

/// What `verify_teleop` found: the worst operator and environment of the
/// exact teleoperator loop over those searched.
#[pyclass(frozen, get_all, module = "twoport")]
pub(crate) struct TeleopVerdict {
    /// Whether a passive operator and environment make the loop grow.
    unstable: bool,
    /// The worst spectral radius per tick.
    spectral_radius: f64,
    /// Its frequency (Hz).
    frequency_hz: f64,
    /// The worst operator: mass (kg), stiffness (N/m), damping (N s/m).
    operator: (f64, f64, f64),
    /// The worst environment, the same.
    environment: (f64, f64, f64),
    /// Closed loops evaluated.
    evaluations: usize,
}

#[pymethods]
impl TeleopVerdict {
    fn __repr__(&self) -> String {
        format!(
            "TeleopVerdict(unstable={}, spectral_radius={:.12} at {:.2} Hz, {} loops)",
            self.unstable, self.spectral_radius, self.frequency_hz, self.evaluations
        )
    }
}

fn lumped(h: &Hand) -> (f64, f64, f64) {
    (h.mass_kg, h.stiffness_npm, h.damping_nspm)
}

/// The gains' names, for an error.
fn names(g: &FourChannelGains) -> String {
    let names: Vec<&str> = g.named().iter().map(|(n, _)| *n).collect();
    names.join(", ")
}

/// Lawrence's four-channel gains from Python's keywords.
#[pyclass(frozen, module = "twoport")]
#[derive(Clone, Copy)]
pub(crate) struct TeleopGains(FourChannelGains);

#[pymethods]
impl TeleopGains {
    /// Gains by name (0 where left out), as a teleoperation scene's
    /// `[law.gains]` and the reports name them: the master's coupling to
    /// the slave's motion `k_m_npm` (N/m) and `b_m_nspm` (N s/m), its own
    /// damping `b_local_nspm` (N s/m), the slave's coupling `k_s_npm`,
    /// `b_s_nspm`, and the force channels `c2`, `c3`, `c5`, `c6`.
    /// Position-position is `k_m_npm = k_s_npm`, `b_m_nspm = b_s_nspm` and
    /// nothing else; force reflection is `k_s_npm`, `b_s_nspm`, `c2` and
    /// the master's `b_local_nspm`. Each gain reads back as an attribute.
    #[new]
    #[pyo3(signature = (**gains))]
    fn new(gains: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        let mut g = FourChannelGains::OFF;
        for (name, value) in gains.into_iter().flatten() {
            let name: String = name.extract()?;
            let value: f32 = value.extract()?;
            if !g.set(&name, value) {
                return Err(PyTypeError::new_err(format!(
                    "TeleopGains: no gain `{name}`; the gains are {}",
                    names(&g)
                )));
            }
        }
        Ok(TeleopGains(g))
    }

    fn __getattr__(&self, name: &str) -> PyResult<f32> {
        let found = self.0.named().into_iter().find(|(n, _)| *n == name);
        found.map(|(_, v)| v).ok_or_else(|| {
            PyAttributeError::new_err(format!(
                "TeleopGains has no `{name}`; the gains are {}",
                names(&self.0)
            ))
        })
    }

    fn __repr__(&self) -> String {
        format!("TeleopGains({:?})", self.0)
    }
}

/// The wave-variable channel: its wave impedance `b` (N s/m, > 0) and
/// each side's incoming-wave filter pole `filter_pole` in `[0, 1)` (0:
/// none).
#[pyclass(frozen, module = "twoport")]
#[derive(Clone, Copy)]
pub(crate) struct WaveLaw(WaveGains);

#[pymethods]
impl WaveLaw {
    #[new]
    #[pyo3(signature = (*, b, filter_pole=0.0))]
    fn new(b: f32, filter_pole: f32) -> Self {
        WaveLaw(WaveGains {
            b_nspm: b,
            filter_pole,
        })
    }

    /// The wave impedance (N s/m).
    #[getter]
    fn b(&self) -> f32 {
        self.0.b_nspm
    }

    /// The incoming waves' filter pole.
    #[getter]
    fn filter_pole(&self) -> f32 {
        self.0.filter_pole
    }

    fn __repr__(&self) -> String {
        format!(
            "WaveLaw(b={}, filter_pole={})",
            self.0.b_nspm, self.0.filter_pole
        )
    }
}

/// A teleoperator's law as Python gives it: `TeleopGains` or `WaveLaw`.
#[derive(FromPyObject)]
pub(crate) enum Law {
    Four(TeleopGains),
    Wave(WaveLaw),
}

impl From<Law> for TeleopLaw {
    fn from(l: Law) -> Self {
        match l {
            Law::Four(g) => TeleopLaw::FourChannel(g.0),
            Law::Wave(w) => TeleopLaw::Wave(w.0),
        }
    }
}

impl<'py> IntoPyObject<'py> for Law {
    type Target = PyAny;
    type Output = Bound<'py, PyAny>;
    type Error = PyErr;

    fn into_pyobject(self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        Ok(match self {
            Law::Four(g) => Bound::new(py, g)?.into_any(),
            Law::Wave(w) => Bound::new(py, w)?.into_any(),
        })
    }
}

/// What the designer's proof says of a teleoperator.
#[pyclass(frozen, get_all, module = "twoport")]
pub(crate) struct TeleopCheck {
    /// Absolutely stable for every passive operator (within the human
    /// bound, if asked) and environment.
    proven: bool,
    /// The least slack (positive: no termination closes a pole).
    slack: f64,
    /// Where it is least (Hz).
    frequency_hz: f64,
    /// Whether the slack stays positive toward DC.
    holds_toward_dc: bool,
    /// The spectral radius with both ends let go.
    let_go_radius: f64,
    /// The law proven (or not): `TeleopGains` or `WaveLaw`.
    law: Py<PyAny>,
    /// What the operator feels at the lowest frequency: through free
    /// space the mass (kg) and damping (N s/m), against a rigid wall the
    /// stiffness (N/m).
    felt: Option<(f64, f64, f64)>,
}

#[pymethods]
impl TeleopCheck {
    /// The four-channel gains proven (or not); `None` for a wave channel.
    #[getter]
    fn gains(&self, py: Python<'_>) -> Option<TeleopGains> {
        self.law.extract::<TeleopGains>(py).ok()
    }

    fn __repr__(&self, py: Python<'_>) -> String {
        format!(
            "TeleopCheck(proven={}, slack={:.3e} at {:.2} Hz, {})",
            self.proven,
            self.slack,
            self.frequency_hz,
            self.law
                .bind(py)
                .repr()
                .map(|r| r.to_string())
                .unwrap_or_default()
        )
    }
}

impl TeleopCheck {
    fn of(py: Python<'_>, r: TeleopCheckReport) -> PyResult<Self> {
        let law = match r.law {
            TeleopLaw::FourChannel(g) => Law::Four(TeleopGains(g)),
            TeleopLaw::Wave(w) => Law::Wave(WaveLaw(w)),
        };
        Ok(TeleopCheck {
            proven: r.check.proven,
            slack: r.check.slack,
            frequency_hz: r.check.frequency_hz,
            holds_toward_dc: r.check.holds_toward_dc,
            let_go_radius: r.check.let_go_radius,
            law: law.into_pyobject(py)?.unbind(),
            felt: r
                .felt
                .map(|t| (t.free_mass_kg, t.free_damping_nspm, t.wall_stiffness_npm)),
        })
    }
}

fn designer(
    master: Pose,
    slave: Pose,
    delay: usize,
    human_bound: bool,
) -> PyResult<TeleopDesigner> {
    let (master, slave) = (master.load()?, slave.load()?);
    let human = human_bound.then_some(HumanBound::PAPER);
    TeleopDesigner::new(&master, &slave, delay, human)
        .map_err(|e| PyValueError::new_err(e.to_string()))
}

/// Prove the teleoperator between `master` and `slave` (model files or
/// `Model`s at one period) with `law` (`TeleopGains` or `WaveLaw`), its
/// channel `delay` ticks long each way: absolutely stable for every
/// passive operator (within the human bound if `human_bound`) and every
/// passive environment.
#[pyfunction]
#[pyo3(signature = (master, slave, law, *, delay=0, human_bound=false))]
pub(crate) fn check_teleop(
    py: Python<'_>,
    master: Pose,
    slave: Pose,
    law: Law,
    delay: usize,
    human_bound: bool,
) -> PyResult<TeleopCheck> {
    let d = designer(master, slave, delay, human_bound)?;
    let law = TeleopLaw::from(law);
    let r = py
        .detach(move || d.check_law(law))
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    TeleopCheck::of(py, r)
}

/// The largest gain the proof allows between `master` and `slave`: the
/// stiffest position-position coupling at damping `b` (N s/m), or, with
/// `k` given, force reflection's largest scale `k_f` at the slave's `k`,
/// `b` and the master's `b_m`, or, with `filter_pole` given (and no `b`),
/// the wave channel's largest impedance at that filter. `None` where
/// none is proven.
#[pyfunction]
#[pyo3(signature = (master, slave, *, b=None, k=None, b_m=0.0, filter_pole=None, delay=0, human_bound=false))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn design_teleop(
    py: Python<'_>,
    master: Pose,
    slave: Pose,
    b: Option<f32>,
    k: Option<f32>,
    b_m: f32,
    filter_pole: Option<f32>,
    delay: usize,
    human_bound: bool,
) -> PyResult<Option<TeleopCheck>> {
    let wave = |b_nspm: f64| {
        TeleopLaw::Wave(WaveGains {
            b_nspm: b_nspm as f32,
            filter_pole: filter_pole.unwrap_or(0.0),
        })
    };
    let (law_at, most): (Box<dyn Fn(f64) -> TeleopLaw + Send>, f64) = match (b, k, filter_pole) {
        (None, None, Some(_)) => (Box::new(wave), 1e5),
        (Some(b), None, None) => (
            Box::new(move |x| {
                TeleopLaw::FourChannel(FourChannelGains::position_position(x as f32, b))
            }),
            1e7,
        ),
        (Some(b), Some(k), None) => (
            Box::new(move |x| {
                TeleopLaw::FourChannel(FourChannelGains::position_force(k, b, x as f32, b_m))
            }),
            100.0,
        ),
        _ => {
            return Err(PyValueError::new_err(
                "design_teleop: give b (position-position), b and k (force reflection), \
                 or filter_pole alone (the wave channel's impedance)",
            ))
        }
    };
    let d = designer(master, slave, delay, human_bound)?;
    let found = py.detach(move || d.largest_law(law_at, most));
    match found.map_err(|e| PyValueError::new_err(e.to_string()))? {
        Some((_, r)) => TeleopCheck::of(py, r).map(Some),
        None => Ok(None),
    }
}

/// Search the exact sampled teleoperator between `master` and `slave`
/// (model files or `Model`s at one period) for a passive operator and
/// environment that make it unstable: `law` (`TeleopGains` or
/// `WaveLaw`), its channel `delay` ticks long each way, with the proof's
/// own worst hands where the proof fails.
#[pyfunction]
#[pyo3(signature = (master, slave, law, *, delay=0))]
pub(crate) fn verify_teleop(
    py: Python<'_>,
    master: Pose,
    slave: Pose,
    law: Law,
    delay: usize,
) -> PyResult<TeleopVerdict> {
    let (master, slave) = (master.load()?, slave.load()?);
    let law = TeleopLaw::from(law);
    let r = py
        .detach(move || verify_law(&master, &slave, law, delay))
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    let v = r.verdict;
    Ok(TeleopVerdict {
        unstable: v.unstable,
        spectral_radius: v.spectral_radius,
        frequency_hz: v.frequency_hz,
        operator: lumped(&v.termination.operator),
        environment: lumped(&v.termination.environment),
        evaluations: v.evaluations,
    })
}
