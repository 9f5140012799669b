//! The tests' random numbers: xorshift64, the same sequence for the same
//! seed on every machine.

/// Uniform draws in `[0, 1)` from `seed` (not zero).
pub(crate) fn uniform(mut seed: u64) -> impl FnMut() -> f64 {
    move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    }
}
