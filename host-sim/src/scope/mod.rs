//! The egui scope: its state apart from its drawing (`app`), the panels
//! (`ui`), the window (`window`), the sample rings it draws from (`rings`)
//! of the signals it records (`signals`), and its link to a board of any
//! number of axes (`board`); for a three-axis scene, the world's state
//! (`world`) and view (`world_ui`); for a scene with an identification
//! experiment, its fit (`identify`) and panel (`identify_ui`); for a
//! teleoperation scene, both devices' state (`teleop`) and view
//! (`teleop_ui`); and the
//! figures on log-log axes the design and identification panels draw
//! (`log_plot`).

pub mod app;
pub mod board;
pub mod identify;
#[cfg(feature = "gui")]
pub mod identify_ui;
#[cfg(feature = "gui")]
pub mod log_plot;
pub mod pace;
pub mod rings;
pub mod signals;
pub mod teleop;
#[cfg(feature = "gui")]
pub mod teleop_ui;
#[cfg(feature = "gui")]
pub mod ui;
#[cfg(feature = "gui")]
pub mod window;
pub mod world;
#[cfg(feature = "gui")]
pub mod world_ui;
