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
mod twoport_py {
    #[pymodule_export]
    use super::design::{
        check_admittance, check_impedance, design_admittance, design_impedance, host_ve, region,
        verify, zrange, Check, Design, HostCheck, Verdict,
    };
    #[pymodule_export]
    use super::teleop::{
        check_teleop, design_teleop, verify_teleop, TeleopCheck, TeleopGains, TeleopVerdict,
        WaveLaw,
    };
    #[pymodule_export]
    use super::{board::Board, model::load_device, model::Model, simulate::simulate};
}
