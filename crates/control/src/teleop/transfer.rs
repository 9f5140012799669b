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
    /// Its value at `z`.
    pub fn eval(&self, z: Complex64) -> Complex64 {
        self.tf.eval(z) * z.powi(-(self.delay_ticks as i32))
    }
}

/// `F = Z(z) V`: row 0 the master's force, row 1 the slave's (N, positive
/// resisting the device's positive motion); column 0 the master's
/// velocity, column 1 the slave's (m/s).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TeleopTransfer {
    /// The matrix's terms, `z[row][column]`.
    pub z: [[Delayed; 2]; 2],
}

impl TeleopTransfer {
    /// Its value at `z`.
    pub fn eval(&self, z: Complex64) -> [[Complex64; 2]; 2] {
        self.z.map(|row| row.map(|t| t.eval(z)))
    }
}
