//! A sine experiment on a body of one axis with viscous damping and
//! Coulomb friction, as the joint-loss tests need it: held at 1 kHz by
//! 100 N/m and 1 N s/m on its reading, a 10 Hz sine for 24 periods,
//! integrated in 200 steps a tick. Included with `#[path]` by the
//! identify crate's unit tests and the CLI's, so that both simulate the
//! one body.

// (`crate::log` is the identify crate's module, or the CLI tests'
// import of it.)
use crate::log::{Excitation, Log};

/// The tick (s).
pub const SINE_TICK_S: f64 = 1e-3;
/// Ticks a period of the sine.
pub const SINE_PERIOD_TICKS: usize = 100;
/// Periods played.
pub const SINE_PERIODS: usize = 24;

/// The force the board commanded (N) and the reading (m) each tick, for
/// a body of `mass` (kg) with damping `b` (N s/m) and friction `c` (N,
/// rising over 1 mm/s) read in steps of `quantum` (m), under a sine of
/// `peak` (N).
pub fn sine_body(mass: f64, b: f64, c: f64, quantum: f64, peak: f64) -> (Vec<f64>, Vec<f64>) {
    let (t, period, periods) = (SINE_TICK_S, SINE_PERIOD_TICKS, SINE_PERIODS);
    let sub = 200;
    let (mut x, mut v, mut prev) = (0.0f64, 0.0f64, 0.0f64);
    let (mut force, mut position) = (Vec::new(), Vec::new());
    for n in 0..period * periods {
        let read = (x / quantum).round() * quantum;
        let phase = std::f64::consts::TAU * (n % period) as f64 / period as f64;
        let f = peak * phase.sin() - 100.0 * read - (read - prev) / t;
        prev = read;
        force.push(f);
        position.push(read);
        let h = t / sub as f64;
        for _ in 0..sub {
            v += (f - b * v - c * (v / 1e-3).tanh()) / mass * h;
            x += v * h;
        }
    }
    (force, position)
}

/// [`sine_body`] as the record the board writes of it.
pub fn sine_log(mass: f64, b: f64, c: f64, quantum: f64, peak: f64) -> Log {
    let (force_n, position_m) = sine_body(mass, b, c, quantum, peak);
    Log {
        period_s: SINE_TICK_S,
        force_n,
        position_m,
        load_cell_n: None,
        excitation: Some(Excitation::Periodic {
            period_ticks: SINE_PERIOD_TICKS,
            first: 1,
            last: 1,
        }),
    }
}
