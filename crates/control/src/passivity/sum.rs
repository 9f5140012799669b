use crate::Real;

/// A running sum that keeps the rounding error of each addition
/// (Neumaier's variant of Kahan summation, renormalised after each term), so that adding many small
/// terms to a large total loses nothing the total's precision could hold.
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
        let t = self.sum + x;
        // Whichever operand is larger was kept exactly; the error of the
        // addition is what the smaller one lost.
        let lost = if self.sum.abs() >= x.abs() {
            (self.sum - t) + x
        } else {
            (x - t) + self.sum
        };
        // Fold the compensation back after every term, so that it stays
        // below an ulp of the sum: left to grow, it becomes a plain sum of
        // its own and rounds each error it takes (a pair of f32s kept as
        // one number of twice the precision).
        let c = self.compensation + lost;
        self.sum = t + c;
        self.compensation = c - (self.sum - t);
    }

    /// The sum.
    #[inline]
    pub fn value(&self) -> R {
        self.sum + self.compensation
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
