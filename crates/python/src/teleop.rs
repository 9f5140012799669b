//! Teleoperators from Python: two models, Lawrence's four-channel gains
//! and the channel's delay, proven, designed, and searched on the exact
//! sampled loop.

use crate::model::Pose;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use twoport_control::teleop::FourChannelGains;
use twoport_design::designer::{TeleopCheckReport, TeleopDesigner};
use twoport_design::network::HumanBound;
use twoport_design::verify::{verify_four_channel, Hand, TeleopLaw};

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

/// Lawrence's four-channel gains from Python's keywords.
#[pyclass(frozen, get_all, module = "twoport")]
#[derive(Clone, Copy)]
pub(crate) struct TeleopGains {
    /// The master's coupling to the slave's motion (N/m) and its damping
    /// (N s/m), and the master's own damping (N s/m).
    k_m: f32,
    b_m: f32,
    b_local: f32,
    /// The slave's coupling to the master's motion (N/m) and its damping.
    k_s: f32,
    b_s: f32,
    /// The force channels (dimensionless).
    c2: f32,
    c3: f32,
    c5: f32,
    c6: f32,
}

impl From<TeleopGains> for FourChannelGains {
    fn from(g: TeleopGains) -> Self {
        FourChannelGains {
            k_m_npm: g.k_m,
            b_m_nspm: g.b_m,
            b_local_nspm: g.b_local,
            k_s_npm: g.k_s,
            b_s_nspm: g.b_s,
            c2: g.c2,
            c3: g.c3,
            c5: g.c5,
            c6: g.c6,
        }
    }
}

impl From<FourChannelGains> for TeleopGains {
    fn from(g: FourChannelGains) -> Self {
        TeleopGains {
            k_m: g.k_m_npm,
            b_m: g.b_m_nspm,
            b_local: g.b_local_nspm,
            k_s: g.k_s_npm,
            b_s: g.b_s_nspm,
            c2: g.c2,
            c3: g.c3,
            c5: g.c5,
            c6: g.c6,
        }
    }
}

#[pymethods]
impl TeleopGains {
    /// Gains by name (0 where left out). Position-position is `k_m = k_s`,
    /// `b_m = b_s` and nothing else; force reflection is `k_s`, `b_s`,
    /// `c2` and the master's `b_local`.
    #[new]
    #[pyo3(signature = (*, k_m=0.0, b_m=0.0, b_local=0.0, k_s=0.0, b_s=0.0, c2=0.0, c3=0.0, c5=0.0, c6=0.0))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        k_m: f32,
        b_m: f32,
        b_local: f32,
        k_s: f32,
        b_s: f32,
        c2: f32,
        c3: f32,
        c5: f32,
        c6: f32,
    ) -> Self {
        TeleopGains {
            k_m,
            b_m,
            b_local,
            k_s,
            b_s,
            c2,
            c3,
            c5,
            c6,
        }
    }

    fn __repr__(&self) -> String {
        format!(
            "TeleopGains(k_m={}, b_m={}, b_local={}, k_s={}, b_s={}, c2={}, c3={}, c5={}, c6={})",
            self.k_m,
            self.b_m,
            self.b_local,
            self.k_s,
            self.b_s,
            self.c2,
            self.c3,
            self.c5,
            self.c6
        )
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
    /// The gains proven (or not).
    gains: TeleopGains,
    /// What the operator feels at the lowest frequency: through free
    /// space the mass (kg) and damping (N s/m), against a rigid wall the
    /// stiffness (N/m).
    felt: Option<(f64, f64, f64)>,
}

#[pymethods]
impl TeleopCheck {
    fn __repr__(&self) -> String {
        format!(
            "TeleopCheck(proven={}, slack={:.3e} at {:.2} Hz, {})",
            self.proven,
            self.slack,
            self.frequency_hz,
            self.gains.__repr__()
        )
    }
}

impl From<TeleopCheckReport> for TeleopCheck {
    fn from(r: TeleopCheckReport) -> Self {
        TeleopCheck {
            proven: r.check.proven,
            slack: r.check.slack,
            frequency_hz: r.check.frequency_hz,
            holds_toward_dc: r.check.holds_toward_dc,
            let_go_radius: r.check.let_go_radius,
            // (Python proves four-channel laws only.)
            gains: match r.law {
                TeleopLaw::FourChannel(g) => g.into(),
                TeleopLaw::Wave(_) => FourChannelGains::OFF.into(),
            },
            felt: r
                .felt
                .map(|t| (t.free_mass_kg, t.free_damping_nspm, t.wall_stiffness_npm)),
        }
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
/// `Model`s at one period) with `gains`, its channel `delay` ticks long
/// each way: absolutely stable for every passive operator (within the
/// human bound if `human_bound`) and every passive environment.
#[pyfunction]
#[pyo3(signature = (master, slave, gains, *, delay=0, human_bound=false))]
pub(crate) fn check_teleop(
    py: Python<'_>,
    master: Pose,
    slave: Pose,
    gains: TeleopGains,
    delay: usize,
    human_bound: bool,
) -> PyResult<TeleopCheck> {
    let d = designer(master, slave, delay, human_bound)?;
    py.detach(move || d.check(gains.into()))
        .map(TeleopCheck::from)
        .map_err(|e| PyValueError::new_err(e.to_string()))
}

/// The stiffest proven position-position coupling at damping `b`
/// (N s/m) between `master` and `slave`, or, with `k` given, the largest
/// proven force-reflection scale `k_f` at the slave's `k`, `b` and the
/// master's `b_m`; `None` where none is proven.
#[pyfunction]
#[pyo3(signature = (master, slave, *, b, k=None, b_m=0.0, delay=0, human_bound=false))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn design_teleop(
    py: Python<'_>,
    master: Pose,
    slave: Pose,
    b: f32,
    k: Option<f32>,
    b_m: f32,
    delay: usize,
    human_bound: bool,
) -> PyResult<Option<TeleopCheck>> {
    let d = designer(master, slave, delay, human_bound)?;
    let found = py.detach(move || match k {
        None => d.largest(|x| FourChannelGains::position_position(x as f32, b), 1e7),
        Some(k) => d.largest(
            |x| FourChannelGains::position_force(k, b, x as f32, b_m),
            100.0,
        ),
    });
    found
        .map(|f| f.map(|(_, r)| r.into()))
        .map_err(|e| PyValueError::new_err(e.to_string()))
}

/// Search the exact sampled teleoperator between `master` and `slave`
/// (model files or `Model`s at one period) for a passive operator and
/// environment that make it unstable: Lawrence's four-channel law with
/// these gains (N/m, N s/m; the force channels' `c2`, `c3`, `c5`, `c6`
/// dimensionless), its channel `delay` ticks long each way, with the
/// proof's own worst hands where the proof fails.
/// Position-position is `k_m = k_s`, `b_m = b_s` and nothing else; force
/// reflection is `k_s`, `b_s`, `c2` and the master's `b_local`.
#[pyfunction]
#[pyo3(signature = (master, slave, *, k_m=0.0, b_m=0.0, b_local=0.0, k_s=0.0, b_s=0.0, c2=0.0, c3=0.0, c5=0.0, c6=0.0, delay=0))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn verify_teleop(
    py: Python<'_>,
    master: Pose,
    slave: Pose,
    k_m: f32,
    b_m: f32,
    b_local: f32,
    k_s: f32,
    b_s: f32,
    c2: f32,
    c3: f32,
    c5: f32,
    c6: f32,
    delay: usize,
) -> PyResult<TeleopVerdict> {
    let (master, slave) = (master.load()?, slave.load()?);
    let gains = TeleopGains::new(k_m, b_m, b_local, k_s, b_s, c2, c3, c5, c6).into();
    let r = py
        .detach(move || verify_four_channel(&master, &slave, gains, delay))
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
