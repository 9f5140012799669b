#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod engine;
pub mod link;
pub mod pil;
pub mod scope;
pub mod study;

pub use engine::scene::Scene;
pub use engine::sim::{Report, Sample, Simulation};
