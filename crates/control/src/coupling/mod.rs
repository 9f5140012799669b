//! The two virtual couplings of the paper (eqs 20, 21), each implemented once
//! for both VE causalities (Fig. 7) through the exact loop solve of
//! [`crate::ve::Port`].

mod admittance;
mod impedance;

pub use admittance::{AdmittanceCoupling, AdmittanceStep};
pub use impedance::{ImpedanceCoupling, ImpedanceStep};
