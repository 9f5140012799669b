//! An impedance-display servo tick for your own device: a 0.25 kg handle
//! with a 14-bit encoder of 10 µm counts, a 10 N actuator, a spring wall
//! behind the coupling twoport-design proved for it. The "device" here is a
//! unit mass moved by hand toward the wall; on a board the frame comes from
//! the timers and the force goes to the PWM.

use twoport_control::ve::{Solid, UnilateralWall};
use twoport_control::{Encoder, ImpedanceGains, Position, SafetyConfig, SensorFrame, Servo};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let t = 1e-3;
    let encoder = Encoder::new(14, 10_000_000, 0, Position::ZERO).map_err(|e| format!("{e:?}"))?;
    let safety = SafetyConfig::new(t, 10.0, 4.0);
    // A wall 1 mm ahead, 2 MN/m: stiffer than the coupling, which bounds it.
    let wall_at = Position::from_m(1e-3).ok_or("wall position")?;
    let wall = UnilateralWall::new(2.0e6, 50.0, wall_at, Solid::Above, t, Position::ZERO)?;
    // twoport design impedance --model models/capstan.toml: 27,885 N/m at 147.9 N s/m.
    let mut servo = Servo::new(
        [ImpedanceGains::new(27_800.0, 148.0).into()],
        [encoder],
        [safety],
        wall,
    )?;
    servo
        .enable()
        .map_err(|f| format!("refused to enable: {f:?}"))?;
    for tick in 0..400u32 {
        // The hand pushes the handle 1.2 mm in 0.2 s (0.2 mm into the wall).
        let x_m = 1.2e-3 * (tick as f64 * t as f64 / 0.2).min(1.0);
        let raw = ((x_m / 10e-6).round() as u32) & 0x3fff;
        let frame = SensorFrame::held(tick, [raw], [0.0]);
        let [force_n] = servo.tick(&frame).actuator_force_n;
        if tick % 50 == 0 {
            println!(
                "t = {:.3} s  x = {x_m:.4} m  force = {:.2} N",
                tick as f32 * t,
                force_n
            );
        }
    }
    Ok(())
}
