//! The egui scope: its state apart from its drawing (`app`), the panels
//! (`ui`), the window (`window`) and the sample rings it draws from
//! (`rings`) of the signals it records (`signals`); for a three-axis scene, the world's state (`world`) and view
//! (`world_ui`).

pub mod app;
pub mod rings;
pub mod signals;
#[cfg(feature = "gui")]
pub mod ui;
#[cfg(feature = "gui")]
pub mod window;
pub mod world;
#[cfg(feature = "gui")]
pub mod world_ui;
