//! The z-domain form every discrete law exposes, so that the designer
//! analyses exactly the law the board runs.

use num_complex::Complex64;

/// A rational transfer function in `z^-1` of order at most two:
///
/// `H(z) = (b0 + b1 z^-1 + b2 z^-2) / (1 + a1 z^-1 + a2 z^-2)`
///
/// Coefficients are f64 computed from the law's own f32 parameters; the
/// units are those of the law's output per unit of its input (stated on each
/// law's `tf`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ZTransfer {
    /// Numerator `[b0, b1, b2]`.
    pub num: [f64; 3],
    /// Denominator `[1, a1, a2]` (always normalised so that `den[0] = 1`).
    pub den: [f64; 3],
}

impl ZTransfer {
    /// The constant gain `g`.
    pub const fn gain(g: f64) -> Self {
        ZTransfer {
            num: [g, 0.0, 0.0],
            den: [1.0, 0.0, 0.0],
        }
    }

    /// `(b0 + b1 z^-1) / (1 + a1 z^-1)`.
    pub const fn first_order(num: [f64; 2], a1: f64) -> Self {
        ZTransfer {
            num: [num[0], num[1], 0.0],
            den: [1.0, a1, 0.0],
        }
    }

    /// `H(z)` at a complex `z` (not a root of the denominator).
    pub fn eval(&self, z: Complex64) -> Complex64 {
        let zi = z.inv();
        let n = Complex64::new(self.num[0], 0.0) + zi * (self.num[1] + zi * self.num[2]);
        let d = Complex64::new(self.den[0], 0.0) + zi * (self.den[1] + zi * self.den[2]);
        n / d
    }

    /// `H(e^{jθ})` for the normalised frequency `θ = ωT` (rad per sample),
    /// given `cos θ` and `sin θ` (no_std has no trigonometry).
    pub fn eval_unit(&self, cos_theta: f64, sin_theta: f64) -> Complex64 {
        self.eval(Complex64::new(cos_theta, sin_theta))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integrator_at_dc_side_and_nyquist() {
        // T/(1 - z^-1) at z = -1 is T/2.
        let h = ZTransfer::first_order([1.0e-3, 0.0], -1.0);
        let v = h.eval(Complex64::new(-1.0, 0.0));
        assert!((v.re - 0.5e-3).abs() < 1e-15 && v.im.abs() < 1e-15);
        // Near DC it grows like 1/(jω).
        let th: f64 = 1e-4;
        let v = h.eval_unit(th.cos(), th.sin());
        assert!((v.norm() - 1.0e-3 / th).abs() / (1.0e-3 / th) < 1e-3);
    }
}
