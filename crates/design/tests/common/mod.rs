//! What the design crate's test files share (each uses some).
#![allow(dead_code)]

use twoport_control::teleop::FourChannel;
use twoport_control::Position;
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

/// Two rigid devices of `m_kg` and `b_nspm` each, free of both ends,
/// through `law` (its channel's delay included), each integrated exactly
/// between ticks under its held force, from a stretch of `x0_m` (m):
/// the largest stretch over the first 500 ticks and over the last 500 of
/// `ticks` (or where a device passes 1 m, growing, if it does).
pub fn stepped_rigid_pair<const D: usize>(
    law: &mut FourChannel<f64, D>,
    (m_kg, b_nspm): (f64, f64),
    period_s: f64,
    x0_m: f64,
    ticks: usize,
) -> (f64, f64) {
    let (m, b, t) = (m_kg, b_nspm, period_s);
    let a = (-b * t / m).exp();
    let mut s = [(x0_m, 0.0f64), (0.0, 0.0)];
    let mut prev = [Position::from_m_f64(x0_m).unwrap(), Position::ZERO];
    let mut peaks = (0.0f64, 0.0f64);
    for n in 0..ticks {
        if s.iter().any(|(x, _)| x.abs() > 1.0) {
            return (peaks.0, (s[0].0 - s[1].0).abs());
        }
        let x = s.map(|(x, _)| Position::from_m_f64(x).unwrap());
        let v = [0, 1].map(|i| x[i].nm_from::<f64>(prev[i]) * 1e-9 / t);
        prev = x;
        let f = law.step((x[0], v[0]), (x[1], v[1]), 0.0, 0.0);
        for (st, force) in s.iter_mut().zip([f.master_n, f.slave_n]) {
            // The push is the force's opposite (it resists +x).
            let push = -force;
            let (x0, v0) = *st;
            *st = (
                x0 + m / b * (1.0 - a) * v0 + (t / b - m * (1.0 - a) / (b * b)) * push,
                a * v0 + (1.0 - a) / b * push,
            );
        }
        let stretch = (s[0].0 - s[1].0).abs();
        if n < 500 {
            peaks.0 = peaks.0.max(stretch);
        } else if n >= ticks - 500 {
            peaks.1 = peaks.1.max(stretch);
        }
    }
    peaks
}
