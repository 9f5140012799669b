//! A teleoperator's z-domain form: the two-port's impedance matrix.

use crate::{Complex64, ZTransfer};

/// A term `tf(z) z^-delay`: a law's part and the channel's delay.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Delayed {
    /// The law's part.
    pub tf: ZTransfer,
    /// The channel's delay (ticks).
    pub delay_ticks: u32,
}

impl Delayed {
    /// No term.
    pub const ZERO: Delayed = Delayed {
        tf: ZTransfer::gain(0.0),
        delay_ticks: 0,
    };

    /// `tf` with no delay.
    pub const fn now(tf: ZTransfer) -> Self {
        Delayed { tf, delay_ticks: 0 }
    }

    /// Its value at `z`.
    pub fn eval(&self, z: Complex64) -> Complex64 {
        self.tf.eval(z) * z.powi(-(self.delay_ticks as i32))
    }
}

/// A teleoperator's law as a matrix: row 0 the master's force, row 1 the
/// slave's (N, positive resisting the device's positive motion), per
/// column 0 the master's velocity, column 1 the slave's (m/s), and
/// column 2 the force the slave's sensor reads from the environment (N,
/// on the slave along `+x`, as a load cell reads it). Columns 0 and 1
/// are the two-port's impedance matrix `Z(z)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TeleopTransfer {
    /// The matrix's terms, `z[row][column]`.
    pub z: [[Delayed; 3]; 2],
}

impl TeleopTransfer {
    /// Its value at `z`.
    pub fn eval(&self, z: Complex64) -> [[Complex64; 3]; 2] {
        self.z.map(|row| row.map(|t| t.eval(z)))
    }
}
