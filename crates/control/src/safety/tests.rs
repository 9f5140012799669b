//! The layer through every fault, limit and ramp.
use super::*;

fn cfg() -> SafetyConfig {
    SafetyConfig {
        heartbeat_timeout_ticks: 5,
        require_dead_man: true,
        ..SafetyConfig::excalibur()
    }
}

fn ok_inputs(tick: u32) -> SafetyInputs {
    SafetyInputs {
        tick,
        dead_man_closed: true,
        velocity_mps: 0.0,
        sensor_faults: Faults::NONE,
    }
}

/// Enabled, past the ramp, heartbeat fresh, at tick `*t`.
fn running(t: &mut u32) -> SafetyLayer {
    let mut s = SafetyLayer::new(cfg()).unwrap();
    s.enable().unwrap();
    for _ in 0..cfg().ramp_ticks {
        s.heartbeat();
        s.step(&ok_inputs(*t), 10.0);
        *t += 1;
    }
    assert_eq!(s.step(&ok_inputs(*t), 10.0).force_n, 10.0);
    *t += 1;
    s
}

/// Each fault path: zero force in the tick it appears, latched (zero
/// force, reported) while the condition is gone, until `clear`.
#[test]
fn every_fault_gives_zero_force_at_once_and_latches() {
    type Inject = fn(&mut SafetyInputs, &mut f32);
    let cases: [(Faults, Inject); 7] = [
        (Faults::SENSOR_NOT_FINITE, |i, _| i.velocity_mps = f32::NAN),
        (Faults::SENSOR_OUT_OF_RANGE, |i, _| {
            i.sensor_faults = Faults::SENSOR_OUT_OF_RANGE
        }),
        (Faults::ENCODER_INVALID, |i, _| {
            i.sensor_faults = Faults::ENCODER_INVALID
        }),
        (Faults::VELOCITY_LIMIT, |i, _| i.velocity_mps = -1.5),
        (Faults::DEAD_MAN, |i, _| i.dead_man_closed = false),
        (Faults::MISSED_TICK, |i, _| i.tick += 1),
        (Faults::COMMAND_NOT_FINITE, |_, f| *f = f32::INFINITY),
    ];
    for (fault, inject) in cases {
        let mut t = 0;
        let mut s = running(&mut t);
        let (mut i, mut f) = (ok_inputs(t), 50.0);
        inject(&mut i, &mut f);
        let out = s.step(&i, f);
        assert_eq!(out.force_n, 0.0, "{fault}");
        assert!(out.faults.contains(fault), "{fault}: got {}", out.faults);
        assert_eq!(s.first_fault(), fault);
        t = i.tick + 1;
        for _ in 0..50 {
            s.heartbeat();
            let out = s.step(&ok_inputs(t), 50.0);
            t += 1;
            assert_eq!(out.force_n, 0.0, "{fault} must stay latched");
            assert!(out.faults.contains(fault));
        }
        assert_eq!(s.enable(), Err(s.faults()));
        s.clear();
        s.heartbeat();
        let out = s.step(&ok_inputs(t), 50.0);
        assert!(out.faults.is_empty(), "{fault}: {}", out.faults);
        assert!(
            out.force_n > 0.0 && out.force_n < 50.0,
            "ramps in after clear"
        );
    }
}

/// With a 5-tick timeout, five ticks after a heartbeat still run; the
/// sixth gives zero force and the fault.
#[test]
fn heartbeat_loss_trips_after_the_timeout() {
    let mut t = 0;
    let mut s = running(&mut t);
    s.heartbeat();
    let timeout = cfg().heartbeat_timeout_ticks;
    for n in 1..=timeout + 1 {
        let out = s.step(&ok_inputs(t), 10.0);
        t += 1;
        let lost = out.faults.contains(Faults::HEARTBEAT_LOST);
        assert_eq!(lost, n > timeout, "tick {n} after the heartbeat");
        assert_eq!(out.force_n == 0.0, lost);
    }
}

#[test]
fn ramp_in_is_bounded_by_elapsed_fraction_of_peak() {
    let c = cfg();
    let mut s = SafetyLayer::new(c).unwrap();
    s.enable().unwrap();
    for n in 1..=c.ramp_ticks + 10 {
        s.heartbeat();
        let out = s.step(&ok_inputs(n), 1.0e6);
        let bound = c.peak_force_n * (n.min(c.ramp_ticks) as f32 / c.ramp_ticks as f32);
        assert!(
            out.force_n <= bound * (1.0 + 1e-6),
            "tick {n}: {}",
            out.force_n
        );
        assert!(out.limited);
        if n >= c.ramp_ticks {
            assert_eq!(out.force_n, c.peak_force_n);
        }
    }
}

#[test]
fn disabled_gives_zero_and_enable_is_refused_while_latched() {
    let mut s = SafetyLayer::new(cfg()).unwrap();
    assert_eq!(s.step(&ok_inputs(0), 80.0).force_n, 0.0);
    s.trip(Faults::HEARTBEAT_LOST);
    assert_eq!(s.enable(), Err(Faults::HEARTBEAT_LOST));
    s.clear();
    assert_eq!(s.enable(), Ok(()));
}

/// Held at peak, the force folds back to the continuous rating once the
/// I^2 t budget is spent (2 s at 200 N from cold), and the RMS over a
/// long run stays at the continuous rating.
#[test]
fn thermal_budget_folds_back_to_continuous() {
    let c = SafetyConfig::excalibur();
    let mut s = SafetyLayer::new(c).unwrap();
    s.enable().unwrap();
    let (mut sum_sq, mut fold_tick) = (0.0f64, None);
    let n = 20_000u32;
    for k in 0..n {
        let f = s.step(&ok_inputs(k), 500.0).force_n;
        if fold_tick.is_none() && k > c.ramp_ticks && f < c.peak_force_n {
            fold_tick = Some(k);
        }
        sum_sq += (f as f64) * (f as f64);
    }
    let fold_s = fold_tick.expect("must fold back") as f32 * c.period_s;
    assert!((fold_s - 2.05).abs() < 0.1, "folded at {fold_s} s");
    let rms_tail = {
        let mut s2 = s;
        let mut acc = 0.0f64;
        for k in n..n + 10_000 {
            let f = s2.step(&ok_inputs(k), 500.0).force_n as f64;
            acc += f * f;
        }
        (acc / 10_000.0).sqrt()
    };
    assert!(
        rms_tail <= c.continuous_force_n as f64 * 1.01,
        "rms {rms_tail}"
    );
    assert!(sum_sq > 0.0);
}

#[test]
fn refuses_bad_config_naming_the_field() {
    let e = SafetyLayer::new(SafetyConfig {
        continuous_force_n: 300.0,
        ..SafetyConfig::excalibur()
    })
    .unwrap_err();
    assert_eq!(e.name, "safety.continuous_force_n (N)");
    let e = SafetyLayer::new(SafetyConfig {
        max_velocity_mps: f32::NAN,
        ..SafetyConfig::excalibur()
    })
    .unwrap_err();
    assert!(e.name.starts_with("safety.max_velocity_mps"));
}
