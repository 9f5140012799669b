//! The egui scope: its state apart from its drawing (`app`), the panels
//! (`ui`), the window (`window`) and the sample rings it draws from
//! (`rings`).

pub mod app;
pub mod rings;
#[cfg(feature = "gui")]
pub mod ui;
#[cfg(feature = "gui")]
pub mod window;
