//! Studies over many runs: boundary sweeps, the paper's Table I, the
//! accuracy-vs-time study, the latency that explains a boundary, the passivity layer's table, and their figures.

pub mod accuracy;
pub mod latency;
pub mod passivity;
pub mod plot;
pub mod sweep;
pub mod table1;
