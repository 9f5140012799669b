//! The `twoport` root package: it exists to own the cross-crate integration
//! tests in `tests/` and the criterion benchmarks in `benches/`. The code lives
//! in the member crates; this re-exports them for the tests.

pub use twoport_control as control;
