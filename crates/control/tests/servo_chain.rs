//! Whole ticks of the displays, as the board runs them: the admittance
//! display's sensor-to-actuator response equals the composition of its laws'
//! z-domain forms, and every sensor fault gives zero force in the same tick.

use twoport_control::servo::{LawsRef, SensorFrame};
use twoport_control::ve::{CursorMass, VeTransfer, VirtualEnvironment};
use twoport_control::{
    AdmittanceGains, Complex64, Faults, ImpedanceGains, Position, SafetyConfig, Servo, SineProbe,
};

mod common;

use common::{encoder, wall, T};

/// Device held still, load cell 20 +- 5 N into a wall: the actuator force
/// per measured force is `-K_p T/(1 - z^-1) / (Z_cA + Z_wall)`.
#[test]
fn admittance_display_tick_matches_its_composed_z_domain_form() {
    for p in [1usize, 10, 100, 400, 1000, 1999] {
        let mut s = Servo::new(
            [AdmittanceGains::new(51_000.0, 90.0, 5.0, 500.0).into()],
            [encoder()],
            [SafetyConfig::excalibur()],
            wall(20_000.0),
        )
        .unwrap();
        s.enable().unwrap();
        let th = 2.0 * std::f64::consts::PI * p as f64 / 4000.0;
        let mut probe = SineProbe::new(th.cos(), th.sin());
        for k in 0..7000u32 {
            let f = (20.0 + 5.0 * probe.excitation()) as f32;
            let out = s.tick(&SensorFrame::held(k, [0], [f]));
            assert!(out.faults.is_empty());
            if k >= 3000 {
                probe.record(f as f64, out.actuator_force_n[0] as f64);
            } else {
                probe.skip();
            }
        }
        let z = Complex64::new(th.cos(), th.sin());
        let LawsRef::Admittance {
            coupling,
            regulator,
        } = s.laws(0).unwrap()
        else {
            panic!("an admittance servo");
        };
        let kp = regulator.tf().eval(z);
        let integ = T as f64 / (1.0 - z.inv());
        let zw = match s.world().tf() {
            VeTransfer::Impedance(t) => t.eval(z),
            VeTransfer::Admittance(_) => unreachable!(),
        };
        let want = -kp * integ / (coupling.tf().eval(z) + zw);
        let got = probe.response();
        assert!(
            (got - want).norm() <= 1e-4 * want.norm(),
            "bin {p}: measured {got}, composed {want}"
        );
    }
}

/// Each bad sensor reading: zero force that very tick, latched afterwards
/// with good readings, and back (ramping in) only after `clear`.
#[test]
fn bad_sensor_readings_give_zero_force_in_the_same_tick() {
    let bad: [(&str, SensorFrame, Faults); 4] = [
        (
            "NaN load cell",
            SensorFrame::held(0, [0], [f32::NAN]),
            Faults::SENSOR_NOT_FINITE,
        ),
        (
            "infinite load cell",
            SensorFrame::held(0, [0], [f32::NEG_INFINITY]),
            Faults::SENSOR_NOT_FINITE,
        ),
        (
            "load cell at rail",
            SensorFrame::held(0, [0], [1.0e4]),
            Faults::SENSOR_OUT_OF_RANGE,
        ),
        (
            "encoder wider than 16 bits",
            SensorFrame::held(0, [0x1_0000], [20.0]),
            Faults::ENCODER_INVALID,
        ),
    ];
    for (what, mut bad_frame, fault) in bad {
        let mut s = Servo::new(
            [AdmittanceGains::new(51_000.0, 90.0, 5.0, 500.0).into()],
            [encoder()],
            [SafetyConfig::excalibur()],
            CursorMass::new(0.25, T, Position::ZERO).unwrap(),
        )
        .unwrap();
        s.enable().unwrap();
        let mut tick = 0;
        // Push 20 N for half a second: the regulator is working.
        let mut last = 0.0;
        for _ in 0..500 {
            last = s
                .tick(&SensorFrame::held(tick, [0], [20.0]))
                .actuator_force_n[0];
            tick += 1;
        }
        assert!(last.abs() > 1.0, "{what}: regulator idle ({last} N)");
        bad_frame.tick = tick;
        tick += 1;
        let out = s.tick(&bad_frame);
        assert_eq!(out.actuator_force_n[0], 0.0, "{what}");
        assert!(out.faults.contains(fault), "{what}: {}", out.faults);
        for _ in 0..20 {
            let out = s.tick(&SensorFrame::held(tick, [0], [20.0]));
            tick += 1;
            assert_eq!(out.actuator_force_n[0], 0.0, "{what}: latched");
        }
        assert!(s.enable().is_err());
        s.clear();
        let out = s.tick(&SensorFrame::held(tick, [0], [20.0]));
        assert!(out.faults.is_empty(), "{what}: {}", out.faults);
        // Re-aligned: the position command restarts at the device, so the
        // first force after clear is small and ramped.
        assert!(out.actuator_force_n[0].abs() < 1.0, "{what}: {out:?}");
    }
}

/// The impedance display renders a wall: pressing 2 mm in gives the series
/// stiffness of coupling and wall in the steady state.
#[test]
fn impedance_display_renders_the_series_of_coupling_and_wall() {
    let mut s = Servo::new(
        [ImpedanceGains::new(51_000.0, 90.0).into()],
        [encoder()],
        [SafetyConfig::excalibur()],
        wall(20_000.0),
    )
    .unwrap();
    s.enable().unwrap();
    let mut out = Default::default();
    for k in 0..3000u32 {
        // Move to +2 mm (2000 counts) over the first second, then hold.
        let raw = k.min(1000) * 2;
        out = s.tick(&SensorFrame::held(k, [raw], [0.0]));
    }
    let series = 1.0 / (1.0 / 51_000.0 + 1.0 / 20_000.0);
    let want = series * 2e-3;
    assert!(
        ((out.actuator_force_n[0] as f64) - want).abs() < 1e-3 * want,
        "{} N vs {want} N",
        out.actuator_force_n[0]
    );
    assert!(s.world().position().nm() > 0);
}
