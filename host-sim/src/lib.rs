#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

/// An [`Error::Pil`] with a `format!` message.
macro_rules! pil_err {
    ($($t:tt)*) => {
        $crate::Error::Pil(format!($($t)*))
    };
}

/// An [`Error::Sim`] with a `format!` message.
macro_rules! sim_err {
    ($($t:tt)*) => {
        $crate::Error::Sim(format!($($t)*))
    };
}

pub mod emulate;
pub mod engine;
mod error;
pub mod link;
pub mod pil;
pub mod scope;
pub mod study;

pub use engine::scene::Scene;
pub use engine::sim::{Report, Sample, Simulation};
pub use error::Error;
