//! The scope's window (eframe): a frame advances the simulation by the wall
//! time since the last one, then draws. With `--screenshot` it saves the
//! window twice (half-way and at `--exit-after`) and closes.

use crate::scope::app::ScopeState;
use crate::Error;
use eframe::egui;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// What a scripted run does (CI, documentation).
#[derive(Clone, Debug, Default)]
pub struct Script {
    /// Save the window here at the end, and at half-time beside it with
    /// `.first` before the extension.
    pub screenshot: Option<PathBuf>,
    /// Close after this many seconds of wall time.
    pub exit_after_s: Option<f64>,
    /// A device the PC drives to open at the start, free running: its
    /// name, where it is, the file it needs.
    pub device: Option<(String, String, Option<PathBuf>)>,
}

/// The first screenshot's path: `out.png` -> `out.first.png`.
pub fn first_shot_path(p: &Path) -> PathBuf {
    let stem = p.file_stem().map(|s| s.to_string_lossy().to_string());
    let ext = p.extension().map(|s| s.to_string_lossy().to_string());
    p.with_file_name(format!(
        "{}.first.{}",
        stem.unwrap_or_else(|| "screenshot".into()),
        ext.unwrap_or_else(|| "png".into())
    ))
}

/// A scripted run's clock and the screenshots it has taken.
struct Shots {
    script: Script,
    started: Instant,
    last_frame: Instant,
    shots: u32,
    saved: Arc<Mutex<Vec<Result<PathBuf, Error>>>>,
}

fn save_png(img: &egui::ColorImage, path: &Path) -> Result<PathBuf, Error> {
    let [w, h] = img.size;
    let bytes: Vec<u8> = img.pixels.iter().flat_map(|c| c.to_array()).collect();
    image::save_buffer(path, &bytes, w as u32, h as u32, image::ColorType::Rgba8)
        .map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(path.to_path_buf())
}

impl Shots {
    fn new(script: Script) -> Self {
        Shots {
            script,
            started: Instant::now(),
            last_frame: Instant::now(),
            shots: 0,
            saved: Arc::new(Mutex::new(Vec::new())),
        }
    }

    /// Wall time (s) since the last frame.
    fn frame(&mut self) -> f64 {
        let now = Instant::now();
        let dt = (now - self.last_frame).as_secs_f64();
        self.last_frame = now;
        dt
    }

    fn shoot(&mut self, ctx: &egui::Context, path: PathBuf) {
        let saved = self.saved.clone();
        ctx.request_screenshot(move |img| {
            let r = save_png(&img, &path);
            if let Ok(mut v) = saved.lock() {
                v.push(r);
            }
        });
        self.shots += 1;
    }

    fn scripted(&mut self, ctx: &egui::Context) {
        let Some(exit) = self.script.exit_after_s else {
            return;
        };
        let t = self.started.elapsed().as_secs_f64();
        if let Some(out) = self.script.screenshot.clone() {
            if self.shots == 0 && t >= 0.5 * exit {
                self.shoot(ctx, first_shot_path(&out));
            } else if self.shots == 1 && t >= exit {
                self.shoot(ctx, out);
            }
            let done = self.saved.lock().map(|v| v.len()).unwrap_or(0);
            if done >= 2 {
                ctx.send_viewport_cmd(egui::ViewportCommand::Close);
            }
        } else if t >= exit {
            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
        }
    }
}

/// What a window shows: a state that advances by the wall time, and
/// its drawing.
trait View {
    /// Advance by `dt_s` (s) of wall time.
    fn advance(&mut self, dt_s: f64);
    /// Draw into `ui`.
    fn draw(&mut self, ui: &mut egui::Ui);
}

/// One device's scope, and the board it may drive.
struct DeviceView {
    state: ScopeState,
    link: crate::scope::board::BoardChoice,
}

impl View for DeviceView {
    fn advance(&mut self, dt_s: f64) {
        self.state.advance(dt_s);
    }
    fn draw(&mut self, ui: &mut egui::Ui) {
        crate::scope::ui::scope(ui, &mut self.state, &mut self.link);
    }
}

/// The scope of a scene of two or three axes: the world view.
impl<const N: usize> View for crate::scope::world::WorldState<N> {
    fn advance(&mut self, dt_s: f64) {
        crate::scope::world::WorldState::advance(self, dt_s);
    }
    fn draw(&mut self, ui: &mut egui::Ui) {
        crate::scope::world_ui::world(ui, self);
    }
}

/// The scope of a teleoperation scene: both devices.
impl View for crate::scope::teleop::TeleopState {
    fn advance(&mut self, dt_s: f64) {
        crate::scope::teleop::TeleopState::advance(self, dt_s);
    }
    fn draw(&mut self, ui: &mut egui::Ui) {
        crate::scope::teleop_ui::teleop(ui, self);
    }
}

/// The window: each frame advances the view by the wall time since the
/// last, draws it, and takes the script's screenshots.
struct App<V> {
    view: V,
    shots: Shots,
}

impl<V: View> eframe::App for App<V> {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        let ctx = ui.ctx().clone();
        self.view.advance(self.shots.frame());
        self.view.draw(ui);
        self.shots.scripted(&ctx);
        ctx.request_repaint();
    }
}

/// Whether a window can open here: an X11 or Wayland display is named.
pub fn display_available() -> bool {
    ["DISPLAY", "WAYLAND_DISPLAY"]
        .iter()
        .any(|v| std::env::var_os(v).is_some_and(|s| !s.is_empty()))
}

/// Open the scripted device, if any, on `state`.
fn open_device(
    state: &mut impl crate::scope::board::WithBoard,
    device: Option<(String, String, Option<PathBuf>)>,
) {
    if let Some((name, path, file)) = device {
        state.connect_device(&name, &path, file.as_deref());
    }
}

/// Open the scope on `scene` (the world view for a scene of two or three
/// axes);
/// returns the screenshots saved.
pub fn run(scene: &Path, script: Script) -> Result<Vec<PathBuf>, Error> {
    let shots = Shots::new(script);
    let saved = shots.saved.clone();
    if crate::engine::teleop::TeleopScene::is_teleop(scene)? {
        if shots.script.device.is_some() {
            return Err(Error::Sim(format!(
                "{}: a teleoperation scene runs two simulated devices; a device the PC drives opens on a one-device scene",
                scene.display()
            )));
        }
        let state = crate::scope::teleop::TeleopState::open(scene)?;
        return show(Box::new(App { view: state, shots }), saved);
    }
    let parsed = crate::Scene::load(scene, &[])?;
    let device = shots.script.device.clone();
    if device.is_some() && parsed.axes < 2 {
        return Err(Error::Sim(format!(
            "{}: a device the PC drives needs a scene of its axes (scenes/linkages/)",
            scene.display()
        )));
    }
    let app: Box<dyn eframe::App> = if parsed.axes == 3 {
        let mut state = crate::scope::world::WorldState::<3>::new(parsed)?;
        open_device(&mut state, device);
        Box::new(App { view: state, shots })
    } else if parsed.axes == 2 {
        let mut state = crate::scope::world::WorldState::<2>::new(parsed)?;
        open_device(&mut state, device);
        Box::new(App { view: state, shots })
    } else {
        let view = DeviceView {
            state: ScopeState::open(scene)?,
            link: crate::scope::board::BoardChoice::default(),
        };
        Box::new(App { view, shots })
    };
    show(app, saved)
}

/// Show `app` in the scope's window until it closes; the screenshots it
/// saved.
fn show(
    app: Box<dyn eframe::App>,
    saved: Arc<Mutex<Vec<Result<PathBuf, Error>>>>,
) -> Result<Vec<PathBuf>, Error> {
    let options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_inner_size([1280.0, 860.0])
            .with_title("twoport scope"),
        ..Default::default()
    };
    eframe::run_native("twoport scope", options, Box::new(|_cc| Ok(app)))
        .map_err(|e| Error::NoWindow(e.to_string()))?;
    let v = saved.lock().map(|v| v.clone()).unwrap_or_default();
    v.into_iter().collect()
}
