//! `host-sim scope` (and no subcommand): the scope window, or a headless
//! run of its scene where no window can open.

use crate::run::{run, RunArgs, SceneArgs};
use clap::Args;
use host_sim::Error;
use std::path::PathBuf;

/// The scope: the default when no subcommand is given.
#[derive(Args, Clone)]
pub(crate) struct ScopeArgs {
    /// The scene to open.
    #[arg(long, default_value = "scenes/stiff_wall.toml")]
    pub(crate) scene: PathBuf,
    /// Save the window to this PNG at --exit-after (and at half that time
    /// to NAME.first.png), then close.
    #[arg(long, requires = "exit_after")]
    pub(crate) screenshot: Option<PathBuf>,
    /// Close after this many seconds.
    #[arg(long)]
    pub(crate) exit_after: Option<f64>,
    /// Run the scene headless even where a display exists.
    #[arg(long)]
    pub(crate) headless: bool,
    /// Open a device the PC drives, by name (haply-2diy, falcon, touch),
    /// and watch it in board mode (the scene must have its axes, e.g.
    /// scenes/linkages/falcon_wall.toml).
    #[arg(long)]
    pub(crate) device: Option<String>,
    /// Where the device is: its serial port (a Touch: its name in Touch
    /// Setup, empty for the default one).
    #[arg(long, requires = "device", default_value = "")]
    pub(crate) device_path: String,
    /// The file the device needs: a Falcon's firmware, a Touch's HD
    /// library where it is not the system's.
    #[arg(long, requires = "device")]
    pub(crate) device_file: Option<PathBuf>,
}

/// The scope, or where no window can open, a headless run of its scene.
pub(crate) fn scope(a: &ScopeArgs) -> Result<(), Error> {
    if let Some(t) = a.exit_after {
        if !(t.is_finite() && t > 0.0) {
            return Err(err!(
                "--exit-after {t}: must be a positive number of seconds"
            ));
        }
    }
    let why_headless = if a.headless {
        Some("--headless".to_string())
    } else {
        open_window(a)?
    };
    let Some(why_headless) = why_headless else {
        return Ok(()); // the window ran and closed
    };
    if a.screenshot.is_some() {
        return Err(err!("--screenshot needs a window: {why_headless}"));
    }
    if let Some(d) = &a.device {
        return Err(err!(
            "--device {d}: the scope watches a device in its window: {why_headless}"
        ));
    }
    eprintln!(
        "host-sim: {why_headless}; running {} headless instead",
        a.scene.display()
    );
    if host_sim::engine::teleop::TeleopScene::is_teleop(&a.scene)? {
        return crate::teleop::teleop(&crate::teleop::TeleopArgs::of(a.scene.clone()));
    }
    run(&RunArgs {
        scene: SceneArgs {
            scene: a.scene.clone(),
            sets: Vec::new(),
            json: false,
        },
        duration: None,
        csv: None,
        png: None,
    })
}

/// The scope window; `Ok(Some(why))` where none can open.
#[cfg(feature = "gui")]
pub(crate) fn open_window(a: &ScopeArgs) -> Result<Option<String>, Error> {
    if !host_sim::scope::window::display_available() {
        return Ok(Some(
            "no display (DISPLAY and WAYLAND_DISPLAY are unset)".to_string(),
        ));
    }
    let script = host_sim::scope::window::Script {
        screenshot: a.screenshot.clone(),
        exit_after_s: a.exit_after,
        device: a
            .device
            .clone()
            .map(|d| (d, a.device_path.clone(), a.device_file.clone())),
    };
    match host_sim::scope::window::run(&a.scene, script) {
        Ok(shots) => {
            for p in shots {
                eprintln!("host-sim: saved {}", p.display());
            }
            Ok(None)
        }
        Err(e @ Error::NoWindow(_)) => Ok(Some(e.to_string())),
        Err(e) => Err(e),
    }
}

/// Built without the `gui` feature: there is no window to open.
#[cfg(not(feature = "gui"))]
pub(crate) fn open_window(_: &ScopeArgs) -> Result<Option<String>, Error> {
    Ok(Some("built without the `gui` feature".to_string()))
}
