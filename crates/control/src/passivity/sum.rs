use crate::Real;

/// A running sum that keeps the rounding error of each addition (Kahan
/// summation), so that adding many small terms to a large total loses
/// nothing the total's precision could hold. Four additions per term: on
/// the M4F that is four single-cycle FPU instructions, where an `f64` sum
/// would call the soft-float library. (Neumaier's variant, which also
/// keeps a term larger than the total, cost eleven; a port's energy is a
/// sum of terms far smaller than the total, where the two agree.)
///
/// # Examples
///
/// ```
/// use twoport_control::passivity::CompensatedSum;
///
/// // 1 J, then 10^6 terms of 1 µJ, in f32 (each term is 17 ulps of the
/// // total, so a plain sum rounds every one of them).
/// let mut s = CompensatedSum::<f32>::new();
/// let mut plain = 0.0f32;
/// for x in core::iter::once(1.0f32).chain(core::iter::repeat(1e-6).take(1_000_000)) {
///     s.add(x);
///     plain += x;
/// }
/// let exact = 1.0 + 1e6 * (1e-6f32 as f64);
/// assert!((s.value() as f64 - exact).abs() < 2e-7);
/// assert!((plain as f64 - exact).abs() > 1e-3);
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CompensatedSum<R = f32> {
    sum: R,
    compensation: R,
}

impl<R: Real> CompensatedSum<R> {
    /// Zero.
    pub const fn new() -> Self {
        CompensatedSum {
            sum: R::ZERO,
            compensation: R::ZERO,
        }
    }

    /// Add `x`.
    #[inline]
    pub fn add(&mut self, x: R) {
        let y = x - self.compensation;
        let t = self.sum + y;
        // What the addition lost of `y`, taken off the next term.
        self.compensation = (t - self.sum) - y;
        self.sum = t;
    }

    /// The sum.
    #[inline]
    pub fn value(&self) -> R {
        self.sum
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 10^6 random terms of mixed sign and size in f32: the compensated sum
    /// stays within a few f32 ulps of the f64 sum, where the plain f32 sum
    /// drifts by orders of magnitude more.
    #[test]
    fn tracks_the_f64_sum_where_a_plain_f32_sum_drifts() {
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut s = CompensatedSum::<f32>::new();
        let (mut plain, mut exact) = (0.0f32, 0.0f64);
        for i in 0..1_000_000 {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            let r = (seed >> 40) as f32 / (1u64 << 24) as f32;
            // A steady inflow with a noisy exchange on top, as a port sees.
            let x = 1e-6 + (r - 0.5) * 1e-4 + if i == 0 { 10.0 } else { 0.0 };
            s.add(x);
            plain += x;
            exact += x as f64;
        }
        let err = (s.value() as f64 - exact).abs();
        let plain_err = (plain as f64 - exact).abs();
        assert!(err <= 4.0 * f32::EPSILON as f64 * exact.abs(), "{err:e}");
        assert!(
            plain_err > 100.0 * err,
            "plain {plain_err:e}, compensated {err:e}"
        );
    }
}
