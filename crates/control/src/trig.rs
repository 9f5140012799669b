//! `sin` and `cos` together in f32 arithmetic, for the kinematics in the
//! board's tick: libm's `sinf` and `cosf` reduce and evaluate in f64,
//! which the Cortex-M4F's FPU does not have (about a thousand instructions
//! a call in software).

/// `(sin x, cos x)` for `x` in rad, to within 2 units in the last place of
/// f32 for `|x| <= 100` (joint angles are a few rad). The argument is
/// reduced by the nearest multiple of π/2 in three parts (Cody and Waite),
/// and each function is a polynomial on `[-π/4, π/4]` (Cephes' `sinf` and
/// `cosf` coefficients). NaN gives NaN.
#[inline]
pub(crate) fn sin_cos_f32(x: f32) -> (f32, f32) {
    let half = if x < 0.0 { -0.5 } else { 0.5 };
    let quadrant = (x * core::f32::consts::FRAC_2_PI + half) as i32;
    let k = quadrant as f32;
    let r = ((x - k * 1.570_312_5) - k * 4.837_513e-4) - k * 7.549_79e-8;
    let r2 = r * r;
    let s = r + r * r2 * (-1.666_665_5e-1 + r2 * (8.332_161e-3 + r2 * -1.951_529_6e-4));
    let c =
        1.0 - 0.5 * r2 + r2 * r2 * (4.166_664_6e-2 + r2 * (-1.388_731_6e-3 + r2 * 2.443_315_7e-5));
    match quadrant & 3 {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against f64's `sin` and `cos` over ±100 rad: within 2.5e-7 of
    /// each (2 ulp of 1), and NaN through.
    #[test]
    fn sin_cos_matches_f64() {
        let mut worst = 0.0f64;
        for i in -200_000..=200_000 {
            let x = i as f32 * 5e-4;
            let (s, c) = sin_cos_f32(x);
            let xf = x as f64;
            worst = worst
                .max((s as f64 - xf.sin()).abs())
                .max((c as f64 - xf.cos()).abs());
        }
        assert!(worst < 2.5e-7, "{worst}");
        let (s, c) = sin_cos_f32(f32::NAN);
        assert!(s.is_nan() && c.is_nan());
        assert_eq!(sin_cos_f32(0.0), (0.0, 1.0));
    }
}
