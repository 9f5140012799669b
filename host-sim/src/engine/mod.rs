//! The simulation engine: the scene, the device's dynamics, the hand, the
//! VEs and the building blocks, the effects, the stability judgement and
//! the loop that runs them around the board's servo. Nothing here draws
//! or studies; `scope` and `study` build on it.

pub mod blocks;
pub mod effects;
pub mod human;
pub mod layer;
pub mod linkage;
pub mod plant;
pub mod scene;
pub mod servo;
pub mod sim;
pub mod stability;
pub mod teleop;
pub mod ve;
pub mod world;
