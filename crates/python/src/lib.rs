#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

mod board;
mod design;
mod model;
mod simulate;
mod teleop;

use pyo3::prelude::*;

/// twoport: haptic interfaces that are stable by design.
#[pymodule]
#[pyo3(name = "twoport")]
fn twoport_py(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(design::design_impedance, m)?)?;
    m.add_function(wrap_pyfunction!(design::design_admittance, m)?)?;
    m.add_function(wrap_pyfunction!(design::check_impedance, m)?)?;
    m.add_function(wrap_pyfunction!(design::check_admittance, m)?)?;
    m.add_function(wrap_pyfunction!(design::verify, m)?)?;
    m.add_function(wrap_pyfunction!(design::zrange, m)?)?;
    m.add_function(wrap_pyfunction!(design::region, m)?)?;
    m.add_function(wrap_pyfunction!(design::host_ve, m)?)?;
    m.add_function(wrap_pyfunction!(teleop::verify_teleop, m)?)?;
    m.add_function(wrap_pyfunction!(teleop::check_teleop, m)?)?;
    m.add_function(wrap_pyfunction!(teleop::design_teleop, m)?)?;
    m.add_function(wrap_pyfunction!(simulate::simulate, m)?)?;
    m.add_function(wrap_pyfunction!(model::load_device, m)?)?;
    m.add_class::<design::Design>()?;
    m.add_class::<design::Check>()?;
    m.add_class::<design::Verdict>()?;
    m.add_class::<design::HostCheck>()?;
    m.add_class::<teleop::TeleopVerdict>()?;
    m.add_class::<teleop::TeleopGains>()?;
    m.add_class::<teleop::WaveLaw>()?;
    m.add_class::<teleop::TeleopCheck>()?;
    m.add_class::<model::Model>()?;
    m.add_class::<board::Board>()?;
    Ok(())
}
