//! A teleoperator's z-domain form: the two-port's impedance matrix.

use crate::{Complex64, ZTransfer};

/// A polynomial in `z^-1` of at most four terms, `Σ c_i z^-p_i`: sparse,
/// since a channel's delay puts a term many ticks from the others.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sparse {
    /// The terms' coefficients (0 for an unused term).
    pub coef: [f64; 4],
    /// Their powers of `z^-1` (ticks).
    pub power: [u32; 4],
}

impl Sparse {
    /// The biquad's coefficients `c` at powers `shift + stride i`.
    pub const fn spread(c: [f64; 3], stride: u32, shift: u32) -> Self {
        Sparse {
            coef: [c[0], c[1], c[2], 0.0],
            power: [shift, shift + stride, shift + 2 * stride, 0],
        }
    }

    /// Its value at `z^-1 = zinv`.
    pub fn eval(&self, zinv: Complex64) -> Complex64 {
        self.coef
            .iter()
            .zip(self.power)
            .filter(|(c, _)| **c != 0.0)
            .map(|(c, p)| zinv.powi(p as i32) * *c)
            .fold(Complex64::new(0.0, 0.0), |a, b| a + b)
    }

    /// Whether every coefficient is zero.
    pub fn is_zero(&self) -> bool {
        self.coef.iter().all(|c| *c == 0.0)
    }

    /// The highest power with a coefficient (ticks).
    pub fn degree(&self) -> u32 {
        self.coef
            .iter()
            .zip(self.power)
            .filter(|(c, _)| **c != 0.0)
            .map(|(_, p)| p)
            .max()
            .unwrap_or(0)
    }
}

/// A law's term: a ratio of two [`Sparse`] polynomials in `z^-1`. Most
/// are a biquad `tf(z^s) z^-delay` (a law's own part in steps of `s`
/// ticks, then the channel's delay); a filtered wave channel is not.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Delayed {
    /// The numerator.
    pub num: Sparse,
    /// The denominator.
    pub den: Sparse,
}

impl Delayed {
    /// No term.
    pub const ZERO: Delayed = Delayed::now(ZTransfer::gain(0.0));

    /// `tf` with no delay.
    pub const fn now(tf: ZTransfer) -> Self {
        Delayed::after(tf, 0)
    }

    /// `tf` after `delay_ticks`.
    pub const fn after(tf: ZTransfer, delay_ticks: u32) -> Self {
        Delayed::strided(tf, 1, delay_ticks)
    }

    /// `tf(z^stride)` after `delay_ticks`.
    pub const fn strided(tf: ZTransfer, stride_ticks: u32, delay_ticks: u32) -> Self {
        Delayed {
            num: Sparse::spread(tf.num, stride_ticks, delay_ticks),
            den: Sparse::spread(tf.den, stride_ticks, 0),
        }
    }

    /// Its value at `z`.
    pub fn eval(&self, z: Complex64) -> Complex64 {
        let zinv = z.inv();
        self.num.eval(zinv) / self.den.eval(zinv)
    }
}

/// A teleoperator's law as a matrix: row 0 the master's force, row 1 the
/// slave's (N, positive resisting the device's positive motion), per
/// column 0 the master's velocity, column 1 the slave's (m/s), column 2
/// the force the slave's sensor reads from the environment (N, on the
/// slave along `+x`, as a load cell reads it), and column 3 the force the
/// master's sensor reads from the operator (N, on the master along `+x`).
/// Columns 0 and 1 are the two-port's impedance matrix `Z(z)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TeleopTransfer {
    /// The matrix's terms, `z[row][column]`.
    pub z: [[Delayed; 4]; 2],
}

impl TeleopTransfer {
    /// Its value at `z`.
    pub fn eval(&self, z: Complex64) -> [[Complex64; 4]; 2] {
        self.z.map(|row| row.map(|t| t.eval(z)))
    }
}
