//! The three-axis engine: a scene with `axes = 3`, a plant per axis (one
//! axis model each, optionally coupled), a hand in 3-D, and the board's own
//! three-axis servo on a world (the building blocks, or a constraint). Only
//! what the scene names runs; the one-axis engine's effects are not
//! offered here yet.

pub mod scene;
pub mod sim;

pub use scene::{XyzScene, XyzVe};
pub use sim::{XyzReport, XyzSample, XyzSimulation, XyzWorld};

/// How many axes a scene file declares: its top-level `axes` (1 when
/// absent); `None` when the file cannot be read as TOML (the one-axis
/// reader then says why).
pub fn axes_of(text: &str) -> Option<i64> {
    let table: toml::Table = toml::from_str(text).ok()?;
    Some(
        table
            .get("axes")
            .and_then(toml::Value::as_integer)
            .unwrap_or(1),
    )
}
