//! What the design crate's test files share (each uses some).
#![allow(dead_code)]

use twoport_design::DeviceModel;

/// A rigid 1-DOF device, handle and actuator at one point.
pub fn rigid(mass_kg: f64, damping_nspm: f64, delay: u32) -> DeviceModel {
    DeviceModel::from_toml(
        &format!(
            "period_s = 0.001\npeak_force_n = 50.0\ncontinuous_force_n = 20.0\n\
             delay_samples = {delay}\nM = [[{mass_kg}]]\nD = [[{damping_nspm}]]\n\
             K = [[0.0]]\nG = [[1.0, -1.0]]\nC_v = [[1.0], [-1.0]]\n"
        ),
        "rigid",
    )
    .unwrap()
}

/// A 50 g actuator on a 20 kN/m flexure to a 20 g handle, the encoder on
/// the actuator, a load cell on the flexure (its filter at 2,000 rad/s),
/// at 1 kHz.
pub fn flexible(name: &str) -> DeviceModel {
    DeviceModel::from_toml(
        &format!(
            "name = \"{name}\"\nperiod_s = 1e-3\npeak_force_n = 50.0\ncontinuous_force_n = 20.0\n\
             M = [[0.05, 0.0], [0.0, 0.02]]\nD = [[0.8, -0.3], [-0.3, 0.4]]\n\
             K = [[2.0e4, -2.0e4], [-2.0e4, 2.0e4]]\nG = [[0.0, -1.0], [1.0, 0.0]]\n\
             C_v = [[0.0, 1.0], [-1.0, 0.0]]\nload_cell_pole_rad_s = 2000.0\n\
             C_f = [[-2.0e4, 2.0e4]]\n"
        ),
        name,
    )
    .unwrap()
}
