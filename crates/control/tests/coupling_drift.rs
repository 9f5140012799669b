//! The impedance coupling's spring acts on positions, so it equals
//! `f = k e + b (e - e_prev)/T` on the position error to f32 rounding for a
//! million ticks (1000 s at 1 kHz) with no error growth; the textbook spring
//! built by summing velocities in f32 is shown to drift on the same path.

use twoport_control::ve::BilateralConstraint;
use twoport_control::{FirstDifference, ImpedanceCoupling, Position};

const K: f32 = 51_000.0;
const B: f32 = 90.0;
const T: f32 = 1.0e-3;
const TICKS: usize = 1_000_000;

/// A device path with large slow motion, fast vibration and a pseudo-random
/// walk, in integer nanometres (an encoder's exact position).
fn path(k: usize) -> Position {
    let t = k as f64 * T as f64;
    let mut h: u64 = (k as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    h ^= h >> 29;
    let jitter = (h % 2001) as i32 - 1000; // +-1 um
    let x = 0.05 * (2.0 * std::f64::consts::PI * 0.7 * t).sin()
        + 0.002 * (2.0 * std::f64::consts::PI * 37.0 * t).sin();
    Position::from_nm((x * 1e9).round() as i32 + jitter)
}

#[test]
fn spring_on_positions_matches_the_formula_for_a_million_ticks_without_drift() {
    let origin = Position::ZERO;
    let mut est = FirstDifference::new(T, path(0)).unwrap();
    let mut c = ImpedanceCoupling::new(K, B, T).unwrap();
    let mut ve = BilateralConstraint::new(origin);
    let (k, b, t) = (K as f64, B as f64, T as f64);
    let mut e_prev = path(0).minus_m(origin) as f64;
    let mut summed_spring = 0.0f32; // k * sum(T v) in f32: the drifting way
    let mut summed_prev = path(0);
    let (mut worst_early, mut worst_late, mut summed_err) = (0.0f64, 0.0f64, 0.0f64);
    for i in 1..TICKS {
        let x = path(i);
        let v = est.step(x);
        let f = c.step(x, v, &mut ve).force_n as f64;
        let e = (x.nm() - origin.nm()) as f64 * 1e-9;
        let f_ref = k * e + b * (e - e_prev) / t;
        // f32 rounding of the two terms (a few ulp of each).
        let scale = (k * e).abs() + (b * (e - e_prev) / t).abs() + 1e-3;
        let rel = (f - f_ref).abs() / scale;
        assert!(rel < 2e-6, "tick {i}: f = {f}, formula {f_ref}");
        if i < 1000 {
            worst_early = worst_early.max(rel);
        }
        if i >= TICKS - 1000 {
            worst_late = worst_late.max(rel);
        }
        e_prev = e;
        summed_spring += K * T * (x.minus_m(summed_prev) / T);
        summed_prev = x;
        summed_err = summed_err.max((summed_spring as f64 - k * e).abs());
    }
    eprintln!("position spring worst rel err: first 1000 ticks {worst_early:e}, last 1000 {worst_late:e}; summed spring max err {summed_err} N");
    // No growth: the error at the end is of the same order as at the start.
    assert!(
        worst_late <= worst_early.max(1e-7) * 4.0,
        "{worst_early:e} -> {worst_late:e}"
    );
    // The velocity-summing spring drifts by orders of magnitude more than
    // the largest rounding error of the position spring (about 1 mN here).
    assert!(summed_err > 0.05, "summed spring error {summed_err} N");
}
