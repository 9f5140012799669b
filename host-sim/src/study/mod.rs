//! Studies over many runs: boundary sweeps, the paper's Table I, the
//! accuracy-vs-time study, and their figures.

pub mod accuracy;
pub mod plot;
pub mod sweep;
pub mod table1;
