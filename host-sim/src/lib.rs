#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

pub mod accuracy;
pub mod app;
pub mod blocks;
pub mod human;
pub mod pil;
pub mod plant;
pub mod plot;
pub mod scene;
pub mod scope;
pub mod sim;
pub mod stability;
#[cfg(feature = "gui")]
pub mod ui;
pub mod ve;
#[cfg(feature = "gui")]
pub mod window;

pub use scene::Scene;
pub use sim::{Report, Sample, Simulation};
