//! Teleoperators from Python: two models, Lawrence's four-channel gains
//! and the channel's delay, searched on the exact sampled loop.

use crate::model::Pose;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use twoport_control::teleop::FourChannelGains;
use twoport_design::verify::{verify_four_channel, Hand};

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

/// Search the exact sampled teleoperator between `master` and `slave`
/// (model files or `Model`s at one period) for a passive operator and
/// environment that make it unstable: Lawrence's four-channel law with
/// these gains (N/m, N s/m; the force channels' `c2`, `c3`, `c5`, `c6`
/// dimensionless), its channel `delay` ticks long each way.
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
    let gains = FourChannelGains {
        k_m_npm: k_m,
        b_m_nspm: b_m,
        b_local_nspm: b_local,
        k_s_npm: k_s,
        b_s_nspm: b_s,
        c2,
        c3,
        c5,
        c6,
    };
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
