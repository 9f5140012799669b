//! What the design crate's test files share.

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
