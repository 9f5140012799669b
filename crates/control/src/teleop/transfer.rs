//! A teleoperator's z-domain form: the two-port's impedance matrix.

use crate::{Complex64, ZTransfer};

/// A term `tf(z^s) z^-delay`: a law's part, in steps of `s` ticks (a
/// channel's round trip is one), and the channel's delay.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Delayed {
    /// The law's part, in powers of `z^-s`.
    pub tf: ZTransfer,
    /// Its step `s` (ticks; 1 for a law's own).
    pub stride_ticks: u32,
    /// The channel's delay (ticks).
    pub delay_ticks: u32,
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
        Delayed {
            tf,
            stride_ticks: 1,
            delay_ticks,
        }
    }

    /// Its value at `z`.
    pub fn eval(&self, z: Complex64) -> Complex64 {
        self.tf.eval(z.powi(self.stride_ticks as i32)) * z.powi(-(self.delay_ticks as i32))
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
