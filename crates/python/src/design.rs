//! The designer from Python: design, check, verify, the impedance range,
//! the proven region and the host VE's proof, on model files or on a
//! model built from arrays; results as frozen classes and numpy arrays.
//! Every call runs with the GIL released, and bad input raises
//! `ValueError` naming it.

use crate::model::ModelArg;
use numpy::PyArray1;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::f64::consts::PI;
use twoport_control::{AdmittanceGains, Gains, ImpedanceGains};
use twoport_design::analysis::{self, Analysis};
use twoport_design::host_ve::{check_host_ve, HostLoop};
use twoport_design::network::HumanBound;
use twoport_design::verify::{verify_host, Hand};
use twoport_design::{Designer, DeviceModel};

/// A proven virtual coupling: the boundary the designer proved, and the
/// gain it recommends inside it. Its names are those of `twoport design
/// --json`: the impedance display's stiffness `k_c_npm`, the admittance
/// display's mass `m_c_kg` (the other is `None`).
#[pyclass(frozen, get_all, module = "twoport")]
#[derive(Clone)]
pub(crate) struct Design {
    /// "impedance" or "admittance".
    display: String,
    /// The boundary's stiffness (N/m; impedance).
    k_c_npm: Option<f64>,
    /// The boundary's mass (kg; admittance).
    m_c_kg: Option<f64>,
    /// The coupling damping it is proven at (N s/m).
    b_c_nspm: f64,
    /// The recommended stiffness, `margin` below the boundary (N/m).
    recommended_k_c_npm: Option<f64>,
    /// The recommended mass, `margin` above the boundary (kg).
    recommended_m_c_kg: Option<f64>,
    /// The recommended gain's margin inside the boundary (a fraction).
    margin: f64,
    /// The sample period it is proven for (s).
    period_s: f64,
    /// Where the design binds (Hz), if it does.
    binding_frequency_hz: Option<f64>,
    /// The admittance display's regulator `(k_p N/m, b_p N s/m)`.
    regulator: Option<(f64, f64)>,
}

#[pymethods]
impl Design {
    fn __repr__(&self) -> String {
        let limit = match (self.k_c_npm, self.m_c_kg) {
            (Some(k), _) => format!("k_c = {k:.6} N/m"),
            (None, Some(m)) => format!("m_c = {m:.6} kg"),
            (None, None) => "no limit".into(),
        };
        format!(
            "Design({}: {limit} at b_c = {} N s/m, T = {} s)",
            self.display, self.b_c_nspm, self.period_s
        )
    }
}

/// A check of given gains for absolute stability.
#[pyclass(frozen, get_all, module = "twoport")]
pub(crate) struct Check {
    /// Whether the sound (sampled-data) condition holds at every frequency.
    absolutely_stable: bool,
    /// The least of the condition's slack over frequency.
    min_margin: f64,
    /// Where it is least (Hz).
    worst_frequency_hz: f64,
    /// The boundary's stiffness at this damping (N/m; impedance), if any.
    boundary_k_c_npm: Option<f64>,
    /// The boundary's mass at this damping (kg; admittance), if any.
    boundary_m_c_kg: Option<f64>,
    /// How far inside the boundary, as a fraction of its gain.
    gain_margin: Option<f64>,
    /// The pose that binds, on a device of several.
    worst_pose: Option<String>,
}

impl From<twoport_design::designer::CheckReport> for Check {
    fn from(r: twoport_design::designer::CheckReport) -> Self {
        use twoport_design::designer::DisplayKind;
        let impedance = r.context.display == DisplayKind::Impedance;
        Check {
            absolutely_stable: r.check.absolutely_stable,
            min_margin: r.check.min_margin,
            worst_frequency_hz: r.check.worst_frequency_hz,
            boundary_k_c_npm: r.boundary.filter(|_| impedance),
            boundary_m_c_kg: r.boundary.filter(|_| !impedance),
            gain_margin: r.gain_margin,
            worst_pose: r.worst_pose,
        }
    }
}

#[pymethods]
impl Check {
    fn __repr__(&self) -> String {
        format!(
            "Check(absolutely_stable={}, min_margin={:.6e}, worst at {:.3} Hz)",
            self.absolutely_stable, self.min_margin, self.worst_frequency_hz
        )
    }
}

/// What `verify` (or `host_ve(..., verify=True)`) found: the worst
/// spectral radius of the exact loop over the terminations searched.
#[pyclass(frozen, get_all, module = "twoport")]
pub(crate) struct Verdict {
    /// Whether a termination makes the loop grow.
    unstable: bool,
    /// The worst spectral radius (per tick; per host period for a host
    /// loop).
    spectral_radius: f64,
    /// Its growth rate (1/s; negative decays).
    growth_per_s: f64,
    /// The worst hand: mass (kg), stiffness (N/m), damping (N s/m).
    hand: (f64, f64, f64),
    /// Closed loops evaluated.
    evaluations: usize,
}

impl Verdict {
    /// A search's worst: whether it grows, its radius and rate, the hand.
    fn of(unstable: bool, radius: f64, growth: f64, h: &Hand, evaluations: usize) -> Self {
        Verdict {
            unstable,
            spectral_radius: radius,
            growth_per_s: growth,
            hand: (h.mass_kg, h.stiffness_npm, h.damping_nspm),
            evaluations,
        }
    }
}

#[pymethods]
impl Verdict {
    fn __repr__(&self) -> String {
        format!(
            "Verdict(unstable={}, spectral_radius={:.12}, {} loops)",
            self.unstable, self.spectral_radius, self.evaluations
        )
    }
}

/// The proof of a coupling against a body the host moves.
#[pyclass(frozen, get_all, module = "twoport")]
pub(crate) struct HostCheck {
    /// Whether the two-rate loop is proven.
    proven: bool,
    /// The least of the body's real impedance over what the loop asks
    /// (N s/m).
    min_margin_nspm: f64,
    /// Where (Hz).
    worst_frequency_hz: f64,
    /// The least damping the body needs (N s/m).
    least_damping_nspm: f64,
    /// The VE period and the delay in servo ticks.
    ve_period_ticks: u32,
    delay_ticks: u32,
    /// The search of the exact two-rate loop, where asked for.
    verify: Option<Py<Verdict>>,
}

#[pymethods]
impl HostCheck {
    fn __repr__(&self) -> String {
        format!(
            "HostCheck(proven={}, least_damping_nspm={:.3}, N={}, d={})",
            self.proven, self.least_damping_nspm, self.ve_period_ticks, self.delay_ticks
        )
    }
}

fn value(e: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(e.to_string())
}

fn designer(poses: Vec<DeviceModel>, period: Option<f64>, human: bool) -> Result<Designer, String> {
    Designer::new(poses, period, human.then_some(HumanBound::PAPER)).map_err(|e| e.to_string())
}

fn to_design(
    d: twoport_design::designer::Design,
    display: &str,
    period_s: f64,
) -> Result<Design, String> {
    use twoport_design::designer::Limit;
    let (limit, b_c_nspm) = d
        .coupling
        .ok_or_else(|| d.message.clone().unwrap_or("no coupling is proven".into()))?;
    let recommended = d.recommended();
    let stiffness = d.limit == Limit::Stiffness;
    Ok(Design {
        display: display.into(),
        k_c_npm: stiffness.then_some(limit),
        m_c_kg: (!stiffness).then_some(limit),
        b_c_nspm,
        recommended_k_c_npm: recommended.filter(|_| stiffness),
        recommended_m_c_kg: recommended.filter(|_| !stiffness),
        margin: d.margin,
        period_s,
        binding_frequency_hz: d.binds_at.map(|x| x.frequency_hz),
        regulator: d.regulator.map(|r| (r.kp, r.bp)),
    })
}

/// Design the impedance display's coupling for `model` (a `Model`, a
/// model file, a list of them: the poses of one axis, proven together,
/// as `load_device` gives them; or the paper's Excalibur): at damping `b` (N s/m), or the
/// best `(k, b)` pair; for every passive human within the paper's bound
/// (`human=False`: any passive human at all), at `period` (s; the
/// model's by default), `margin` inside the boundary.
#[pyfunction]
#[pyo3(signature = (model=None, b=None, period=None, human=true, margin=0.1))]
pub(crate) fn design_impedance(
    py: Python<'_>,
    model: Option<ModelArg>,
    b: Option<f64>,
    period: Option<f64>,
    human: bool,
    margin: f64,
) -> PyResult<Design> {
    let m = ModelArg::poses(model)?;
    py.detach(move || {
        let d = designer(m, period, human)?;
        let r = d.design_impedance(b, margin).map_err(|e| e.to_string())?;
        to_design(r, "impedance", d.period_s())
    })
    .map_err(value)
}

/// Design the admittance display's coupling mass: at damping `b`, or the
/// best `(m, b)` pair, for the regulator `(kp, bp)` (the impedance
/// design's best pair by default, the paper's eq 30). The model needs a
/// force sensor.
#[pyfunction]
#[pyo3(signature = (model=None, b=None, kp=None, bp=None, period=None, human=true, margin=0.1))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn design_admittance(
    py: Python<'_>,
    model: Option<ModelArg>,
    b: Option<f64>,
    kp: Option<f64>,
    bp: Option<f64>,
    period: Option<f64>,
    human: bool,
    margin: f64,
) -> PyResult<Design> {
    let m = ModelArg::poses(model)?;
    let regulator = match (kp, bp) {
        (Some(kp), Some(bp)) => Some((kp, bp)),
        (None, None) => None,
        _ => return Err(value("kp and bp: give both or neither")),
    };
    py.detach(move || {
        let d = designer(m, period, human)?;
        let r = d
            .design_admittance(regulator, b, margin)
            .map_err(|e| e.to_string())?;
        to_design(r, "admittance", d.period_s())
    })
    .map_err(value)
}

/// Check the impedance coupling `(k, b)` (N/m, N s/m) for absolute
/// stability on `model`.
#[pyfunction]
#[pyo3(signature = (k, b, model=None, period=None, human=true))]
pub(crate) fn check_impedance(
    py: Python<'_>,
    k: f64,
    b: f64,
    model: Option<ModelArg>,
    period: Option<f64>,
    human: bool,
) -> PyResult<Check> {
    let m = ModelArg::poses(model)?;
    py.detach(move || {
        let r = designer(m, period, human)?
            .check_impedance(k, b)
            .map_err(|e| e.to_string())?;
        Ok(Check::from(r))
    })
    .map_err(|e: String| value(e))
}

/// Check the admittance display's coupling of mass `m` (kg) and damping
/// `b` (N s/m) with the regulator `(kp, bp)` for absolute stability on
/// `model` (which needs a force sensor).
#[pyfunction]
#[pyo3(signature = (kp, bp, m, b, model=None, period=None, human=true))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn check_admittance(
    py: Python<'_>,
    kp: f64,
    bp: f64,
    m: f64,
    b: f64,
    model: Option<ModelArg>,
    period: Option<f64>,
    human: bool,
) -> PyResult<Check> {
    let poses = ModelArg::poses(model)?;
    py.detach(move || {
        let r = designer(poses, period, human)?
            .check_admittance((kp, bp), m, b)
            .map_err(|e| e.to_string())?;
        Ok(Check::from(r))
    })
    .map_err(|e: String| value(e))
}

/// Search the exact sampled loop for a passive hand and VE that make the
/// impedance coupling `(k, b)` (or, with `m`, the admittance coupling of
/// mass `m` kg and damping `b` with the regulator `(kp, bp)`) unstable:
/// independent of the proof.
#[pyfunction]
#[pyo3(signature = (k=None, b=0.0, model=None, period=None, human=true, m=None, kp=None, bp=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn verify(
    py: Python<'_>,
    k: Option<f64>,
    b: f64,
    model: Option<ModelArg>,
    period: Option<f64>,
    human: bool,
    m: Option<f64>,
    kp: Option<f64>,
    bp: Option<f64>,
) -> PyResult<Verdict> {
    let gains = match (k, m, kp, bp) {
        (Some(k), None, None, None) => Gains::from(ImpedanceGains::new(k as f32, b as f32)),
        (None, Some(m), Some(kp), Some(bp)) => Gains::from(AdmittanceGains::new(
            kp as f32, bp as f32, m as f32, b as f32,
        )),
        _ => {
            return Err(value(
                "give k (impedance display) or m, kp and bp (admittance display)",
            ))
        }
    };
    let model = ModelArg::poses(model)?;
    py.detach(move || {
        let r = designer(model, period, human)?
            .verify(&gains)
            .map_err(|e| e.to_string())?;
        let v = r.verdict;
        Ok(Verdict::of(
            v.unstable,
            v.spectral_radius,
            v.growth_per_s,
            &v.termination.hand,
            v.evaluations,
        ))
    })
    .map_err(|e: String| value(e))
}

/// The impedance range the hand feels with the impedance coupling `(k,
/// b)` (or, with `m`, `kp` and `bp`, the admittance coupling of mass `m`
/// and damping `b` with that regulator), from 0.1 Hz to Nyquist at
/// `points` frequencies: a dict of numpy arrays `frequency_hz`, `z_min`,
/// `z_max` (complex, N s/m).
#[pyfunction]
#[pyo3(signature = (k=None, b=0.0, model=None, period=None, points=200, m=None, kp=None, bp=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn zrange<'py>(
    py: Python<'py>,
    k: Option<f64>,
    b: f64,
    model: Option<ModelArg>,
    period: Option<f64>,
    points: usize,
    m: Option<f64>,
    kp: Option<f64>,
    bp: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let admittance = match (k, m, kp, bp) {
        (Some(_), None, None, None) => None,
        (None, Some(m), Some(kp), Some(bp)) => Some((m, kp, bp)),
        _ => {
            return Err(value(
                "give k (impedance display) or m, kp and bp (admittance display)",
            ))
        }
    };
    let k = k.unwrap_or(0.0);
    if points < 2 {
        return Err(value(format!("points {points}: need at least 2")));
    }
    let m = ModelArg::poses(model)?;
    let (freq, range) = py
        .detach(move || {
            if m.len() > 1 {
                return Err("zrange draws one pose: give one model".to_string());
            }
            let d = designer(m, period, true)?;
            let pose = &d.poses()[0];
            let omegas = analysis::log_grid(2.0 * PI * 0.1, pose.plant.nyquist(), points);
            let a = Analysis::on(&pose.plant, &omegas);
            let r = match admittance {
                None => analysis::impedance_range_impedance(&a, k, b),
                Some((m, kp, bp)) => analysis::impedance_range_admittance(&a, (kp, bp), (m, b)),
            }
            .ok_or_else(|| format!("b {b}: not a valid coupling with these gains"))?;
            let f: Vec<f64> = omegas.iter().map(|w| w / (2.0 * PI)).collect();
            Ok::<_, String>((f, r))
        })
        .map_err(value)?;
    let out = PyDict::new(py);
    out.set_item("frequency_hz", PyArray1::from_vec(py, freq))?;
    out.set_item("z_min", PyArray1::from_iter(py, range.iter().map(|r| r.0)))?;
    out.set_item("z_max", PyArray1::from_iter(py, range.iter().map(|r| r.1)))?;
    Ok(out)
}

/// The proven region: at each of `points` dampings log-spaced from
/// `b_from` to `b_to` (N s/m), the stiffest proven impedance coupling, or
/// with the regulator `(kp, bp)` the lightest proven admittance coupling
/// mass; a dict of numpy arrays `b_nspm` and `k_max_npm` (or `m_min_kg`)
/// (a damping with no proven coupling has no row).
#[pyfunction]
#[pyo3(signature = (model=None, b_from=10.0, b_to=1000.0, points=32, period=None, human=true, kp=None, bp=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn region<'py>(
    py: Python<'py>,
    model: Option<ModelArg>,
    b_from: f64,
    b_to: f64,
    points: usize,
    period: Option<f64>,
    human: bool,
    kp: Option<f64>,
    bp: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let regulator = match (kp, bp) {
        (Some(kp), Some(bp)) => Some((kp, bp)),
        (None, None) => None,
        _ => {
            return Err(value(
                "kp and bp: give both (the admittance display) or neither",
            ))
        }
    };
    let m = ModelArg::poses(model)?;
    let rows = py
        .detach(move || {
            let d = designer(m, period, human)?;
            match regulator {
                Some(r) => d.region_admittance(r, (b_from, b_to), points),
                None => d.region_impedance((b_from, b_to), points),
            }
            .map(|r| r.rows)
            .map_err(|e| e.to_string())
        })
        .map_err(value)?;
    let out = PyDict::new(py);
    out.set_item("b_nspm", PyArray1::from_iter(py, rows.iter().map(|r| r.0)))?;
    let limit = if regulator.is_some() {
        "m_min_kg"
    } else {
        "k_max_npm"
    };
    out.set_item(limit, PyArray1::from_iter(py, rows.iter().map(|r| r.1)))?;
    Ok(out)
}

/// Prove the impedance coupling `(k, b)` against a body the host
/// simulates (`body`: mass kg, damping N s/m) at `ve_rate` (Hz), answering
/// `host_delay` (s) after the force it reads; with `verify=True`, also
/// search the exact two-rate loop for a hand that makes it grow.
#[pyfunction]
#[pyo3(signature = (k, b, body, model=None, ve_rate=1000.0, host_delay=0.002, period=None, human=true, verify=false))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn host_ve(
    py: Python<'_>,
    k: f64,
    b: f64,
    body: (f64, f64),
    model: Option<ModelArg>,
    ve_rate: f64,
    host_delay: f64,
    period: Option<f64>,
    human: bool,
    verify: bool,
) -> PyResult<HostCheck> {
    let m = ModelArg::poses(model)?;
    let (c, v, n, d) = py
        .detach(move || {
            let des = designer(m, period, human)?;
            let t = des.period_s();
            let (n, d) = HostLoop::ticks_at(t, ve_rate, host_delay).map_err(|e| match e {
                twoport_design::Error::HostRate { .. } => format!(
                    "ve_rate {ve_rate} Hz: the servo's {} Hz is not a whole multiple of it",
                    1.0 / t
                ),
                other => other.to_string(),
            })?;
            let host = HostLoop::new(t, n, d, (body.0, body.1, 0.0)).map_err(|e| e.to_string())?;
            let human = human.then_some(HumanBound::PAPER);
            // The worst pose's proof, and the worst pose's search.
            let mut c: Option<twoport_design::host_ve::HostCheck> = None;
            let mut v: Option<twoport_design::verify::HostVerdict> = None;
            for pose in des.poses() {
                let p =
                    check_host_ve(&pose.plant, k, b, human, &host).map_err(|e| e.to_string())?;
                if c.is_none_or(|c| p.min_margin_nspm < c.min_margin_nspm) {
                    c = Some(p);
                }
                if verify {
                    let r = verify_host(&pose.model, t, (k, b), human, &host)
                        .map_err(|e| e.to_string())?;
                    if v.as_ref()
                        .is_none_or(|v| r.spectral_radius > v.spectral_radius)
                    {
                        v = Some(r);
                    }
                }
            }
            let c = c.ok_or("no pose")?;
            Ok::<_, String>((c, v, host.ve_period_ticks, host.delay_ticks))
        })
        .map_err(value)?;
    let verify = match v {
        Some(v) => Some(Py::new(
            py,
            Verdict::of(
                v.unstable,
                v.spectral_radius,
                v.growth_per_s,
                &v.hand,
                v.evaluations,
            ),
        )?),
        None => None,
    };
    Ok(HostCheck {
        proven: c.proven,
        min_margin_nspm: c.min_margin_nspm,
        worst_frequency_hz: c.worst_frequency_hz,
        least_damping_nspm: c.least_damping_nspm,
        ve_period_ticks: n,
        delay_ticks: d,
        verify,
    })
}
