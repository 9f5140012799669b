//! The scope's drawing: small functions, one per panel, over `ScopeState`.
//! Nothing here owns simulation state.

use crate::engine::human::GraspKind;
use crate::scope::app::{list_ports, ScopeState, Speed};
use crate::scope::board::WithBoard;
use crate::scope::board::{BoardChoice, BoardLink};
use crate::scope::rings::{minmax, Edge, Ring};
use crate::scope::signals::{BoardSignal, Signal};
use eframe::egui::{self, Color32, RichText, Ui};
use egui_plot::{Legend, Line, Plot, PlotPoints};
use twoport_control::servo::Gains;

pub use crate::scope::identify_ui::identify_panel;
use crate::scope::log_plot::{curves, decade_label, decades};
pub use crate::scope::log_plot::{log_log, LogCurve};

/// Per-pixel min/max columns of `ring` over `[t0, t1)`, as a polyline that
/// runs down each column: every peak drawn, none aliased away.
fn envelope(ring: &Ring, t0: f64, t1: f64, pixels: usize) -> Vec<[f64; 2]> {
    let cols = minmax(ring.iter(), t0, t1, pixels.max(1));
    let dt = (t1 - t0) / cols.len() as f64;
    let mut pts = Vec::with_capacity(2 * cols.len());
    for (i, c) in cols.iter().enumerate() {
        if let Some((lo, hi)) = c {
            let t = t0 + (i as f64 + 0.5) * dt;
            pts.push([t, *lo]);
            if hi != lo {
                pts.push([t, *hi]);
            }
        }
    }
    pts
}

const COLORS: [Color32; 6] = [
    Color32::from_rgb(31, 119, 180),
    Color32::from_rgb(214, 39, 40),
    Color32::from_rgb(44, 160, 44),
    Color32::from_rgb(255, 127, 14),
    Color32::from_rgb(148, 103, 189),
    Color32::from_rgb(140, 86, 75),
];

/// A plot of a stack on one time axis (`link` names it), with a legend:
/// one y-axis width for all, so their time axes line up; the scope sets
/// the span, so the mouse does not drag or zoom it.
pub fn time_plot<'a>(id: &'a str, height: f32, link: &str) -> Plot<'a> {
    Plot::new(id)
        .height(height)
        .legend(Legend::default())
        .link_axis(egui::Id::unique(link), [true, false])
        .y_axis_min_width(48.0)
        .allow_drag(false)
        .allow_zoom(false)
        .allow_scroll(false)
}

/// One plot of the stack: the named signals over `[t0, t1)`.
fn signal_plot(
    ui: &mut Ui,
    s: &ScopeState,
    (t0, t1): (f64, f64),
    id: &str,
    height: f32,
    signals: &[Signal],
    board: &[BoardSignal],
) {
    let px = ui.available_width().max(1.0) as usize;
    time_plot(id, height, "scope-time").show(ui, |p| {
        p.set_plot_bounds_x(t0..=t1);
        p.set_auto_bounds([false, true]);
        for (i, sig) in signals.iter().enumerate() {
            let pts = envelope(s.ring(*sig), t0, t1, px);
            p.line(Line::new(sig.name(), PlotPoints::from(pts)).color(COLORS[i % 6]));
        }
        if s.board.is_some() {
            for b in board {
                let pts = envelope(s.board_ring(*b), t0, t1, px);
                p.line(Line::new(b.name(), PlotPoints::from(pts)).width(2.0));
            }
        }
    });
}

/// The plots on one time axis: positions, velocity, forces, energy, and
/// the passivity layer's damping when the scene runs one. The span is
/// found once a frame (a triggered one scans the trigger signal's ring).
pub fn plots(ui: &mut Ui, s: &ScopeState) {
    let layer = s.has_layer();
    let board = s.board.is_some();
    let n = 4.0 + f32::from(u8::from(layer)) + f32::from(u8::from(board));
    let h = ((ui.available_height() - 24.0) / n).max(80.0);
    let span = s.view();
    signal_plot(
        ui,
        s,
        span,
        "positions",
        h,
        &[Signal::HandlePosition, Signal::VePosition],
        &[BoardSignal::Position, BoardSignal::VePosition],
    );
    signal_plot(ui, s, span, "velocity", h, &[Signal::HandleVelocity], &[]);
    signal_plot(
        ui,
        s,
        span,
        "forces",
        h,
        &[
            Signal::HumanForce,
            Signal::CommandedForce,
            Signal::ActuatorForce,
            Signal::VeForce,
            Signal::CouplingForce,
        ],
        &[BoardSignal::Commanded, BoardSignal::Actuator],
    );
    signal_plot(
        ui,
        s,
        span,
        "energy",
        h,
        &[Signal::EnergyIn, Signal::EnergyStored, Signal::LayerEnergy],
        &[],
    );
    if layer {
        signal_plot(
            ui,
            s,
            span,
            "passivity layer",
            h,
            &[Signal::LayerAdded],
            &[],
        );
    }
    if board {
        signal_plot(ui, s, span, "board loop", h, &[], &BoardSignal::TIMING);
    }
}

/// Scene picker, play/pause/step/reset, speed, time and status.
pub fn transport(ui: &mut Ui, s: &mut ScopeState) {
    ui.horizontal_wrapped(|ui| {
        let name = |p: &std::path::Path| {
            p.strip_prefix(&s.scenes_root)
                .unwrap_or(p)
                .display()
                .to_string()
        };
        let mut pick = None;
        egui::ComboBox::from_label("scene")
            .selected_text(name(&s.scene_path))
            .show_ui(ui, |ui| {
                for p in &s.scenes {
                    if ui.selectable_label(*p == s.scene_path, name(p)).clicked() {
                        pick = Some(p.clone());
                    }
                }
            });
        if let Some(p) = pick {
            s.load_scene(&p);
        }
        let play = if s.running { "pause" } else { "play" };
        if ui.button(play).clicked() {
            s.running = !s.running;
        }
        if ui.button("step").clicked() {
            s.running = false;
            s.tick();
        }
        if ui.button("reset").clicked() {
            s.reset();
        }
        speed(ui, s);
        ui.label(format!("t = {:.3} s", s.time_s()));
        if let Some(f) = s.failure() {
            ui.colored_label(Color32::RED, f.to_string());
        }
        if let Some(m) = &s.message {
            ui.colored_label(Color32::from_rgb(200, 120, 0), m.clone());
        }
    });
}

fn speed(ui: &mut Ui, s: &mut ScopeState) {
    let label = match s.speed {
        Speed::Times(1.0) => "real time".to_string(),
        Speed::Times(f) => format!("x {f}"),
        Speed::Fastest => "as fast as possible".to_string(),
    };
    egui::ComboBox::from_label("speed")
        .selected_text(label)
        .show_ui(ui, |ui| {
            for f in [0.1, 0.25, 1.0, 2.0, 5.0] {
                let text = if f == 1.0 {
                    "real time".to_string()
                } else {
                    format!("x {f}")
                };
                ui.selectable_value(&mut s.speed, Speed::Times(f), text);
            }
            ui.selectable_value(&mut s.speed, Speed::Fastest, "as fast as possible");
        });
}

/// The gain sliders and the designer's light.
pub fn gains(ui: &mut Ui, s: &mut ScopeState) {
    ui.heading("Coupling");
    let mut g = s.gains;
    // (Every slider is drawn, whichever changed.)
    let changed = match &mut g {
        Gains::Impedance(g) => [
            slider(ui, &mut g.k_npm, 0.0..=150_000.0, "k_c (N/m)"),
            slider(ui, &mut g.b_nspm, 0.0..=500.0, "b_c (N s/m)"),
        ]
        .contains(&true),
        Gains::Admittance(g) => [
            slider(ui, &mut g.kp_npm, 0.0..=150_000.0, "K_p stiffness (N/m)"),
            slider(ui, &mut g.bp_nspm, 0.0..=1000.0, "K_p damping (N s/m)"),
            ui.add(
                egui::Slider::new(&mut g.m_kg, 0.05..=50.0)
                    .logarithmic(true)
                    .text("m_c (kg)"),
            )
            .changed(),
            slider(ui, &mut g.b_nspm, 1.0..=2000.0, "b_c (N s/m)"),
        ]
        .contains(&true),
    };
    if changed {
        s.set_gains(g);
    }
    light(ui, s);
}

/// A linear slider over `range`; whether the user moved it.
fn slider(ui: &mut Ui, v: &mut f32, range: std::ops::RangeInclusive<f32>, text: &str) -> bool {
    ui.add(egui::Slider::new(v, range).text(text)).changed()
}

fn light(ui: &mut Ui, s: &ScopeState) {
    let Some(l) = &s.light else {
        ui.label("no designer model for this scene");
        return;
    };
    ui.horizontal(|ui| {
        let (color, text) = if l.proven {
            (
                Color32::from_rgb(30, 170, 60),
                format!(
                    "proven absolutely stable (least margin {:.3} at {:.1} Hz)",
                    l.margin, l.worst_hz
                ),
            )
        } else {
            (
                Color32::from_rgb(210, 40, 40),
                format!("NOT proven stable: worst at {:.1} Hz", l.worst_hz),
            )
        };
        let (rect, _) = ui.allocate_exact_size(egui::vec2(16.0, 16.0), egui::Sense::hover());
        ui.painter().circle_filled(rect.center(), 7.0, color);
        ui.label(RichText::new(text).color(color));
    });
    // How far inside the boundary at this damping: a gain on the boundary
    // is proven and still rings, so the margin is what to read.
    ui.label(match (l.gain_margin, &l.boundary) {
        (Some(g), Some(b)) if g >= 0.0 => format!(
            "gain margin {:.1}%: the boundary at this damping is {b}",
            100.0 * g
        ),
        (Some(g), Some(b)) => format!("{:.1}% past the boundary at this damping, {b}", -100.0 * g),
        _ => "nothing is proven at this damping".to_string(),
    });
}

/// The design bound and the coupling's response (Fig. 8 or 9), live, on
/// log-log axes as the paper's figures: the bound and the coupling span
/// seven decades, and the margin is the gap between them.
pub fn design_panel(ui: &mut Ui, s: &ScopeState) {
    let Some(fig) = s.light.as_ref().and_then(|l| l.figure.as_ref()) else {
        return;
    };
    ui.label(RichText::new(&fig.y_label).small());
    // Framed on the coupling's decades (the last curve) and one below: the
    // bound's dives at the resonances run off the bottom, as in the paper.
    let coupling = fig.curves.last().map(|c| log_log(&c.points));
    let (lo, hi) = coupling
        .iter()
        .flatten()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| {
            (l.min(p[1]), h.max(p[1]))
        });
    let (lo, hi) = if lo.is_finite() {
        (lo, hi)
    } else {
        (-6.0, 0.0)
    };
    let bottom = lo.floor() - 1.0;
    Plot::new("design-bound")
        .height(210.0)
        .include_y(bottom)
        .include_y(hi.ceil() + 0.5)
        .auto_bounds([true, false])
        // The curves rise to the right and dive at the resonances: the
        // lower right is where they leave room for the names.
        .legend(Legend::default().position(egui_plot::Corner::RightBottom))
        .y_axis_min_width(40.0)
        .x_axis_label("frequency (Hz)")
        .x_axis_formatter(|m, _| decade_label(m.value))
        .y_axis_formatter(|m, _| decade_label(m.value))
        .x_grid_spacer(decades)
        .y_grid_spacer(decades)
        // Just below the frame: a dive leaves through the bottom.
        .show(ui, |p| curves(p, "design", fig, bottom - 0.5));
}

/// Grasp and the mouse push.
pub fn hand(ui: &mut Ui, s: &mut ScopeState) {
    ui.heading("Hand");
    let mut g = s.grasp;
    ui.horizontal(|ui| {
        ui.selectable_value(&mut g, None, "script");
        ui.selectable_value(&mut g, Some(GraspKind::HandsOff), "hands off");
        ui.selectable_value(&mut g, Some(GraspKind::Relaxed), "relaxed");
        ui.selectable_value(&mut g, Some(GraspKind::Fingertips), "fingertips");
        ui.selectable_value(&mut g, Some(GraspKind::Maximum), "maximum");
    });
    if g != s.grasp {
        s.set_grasp(g);
    }
    // Drag sideways in the box: 0.2 N per point, released is zero.
    let (rect, resp) =
        ui.allocate_exact_size(egui::vec2(ui.available_width(), 36.0), egui::Sense::drag());
    let push = if resp.dragged() {
        (s.push_n + resp.drag_delta().x as f64 * 0.2).clamp(-60.0, 60.0)
    } else {
        0.0
    };
    if push != s.push_n {
        s.set_push(push);
    }
    ui.painter().rect_filled(
        rect,
        4.0,
        Color32::from_gray(if resp.dragged() { 70 } else { 45 }),
    );
    ui.painter().text(
        rect.center(),
        egui::Align2::CENTER_CENTER,
        format!("drag to push the handle: {:+.1} N", s.push_n),
        egui::FontId::proportional(13.0),
        Color32::WHITE,
    );
}

/// Wall position and stiffness, when the VE is a wall.
pub fn wall(ui: &mut Ui, s: &mut ScopeState) {
    let Some((mut x, mut k)) = s.wall else {
        return;
    };
    ui.heading("Wall");
    let a = ui
        .add(egui::Slider::new(&mut x, -0.05..=0.05).text("surface (m)"))
        .changed();
    let b = ui
        .add(
            egui::Slider::new(&mut k, 1e3..=1e7)
                .logarithmic(true)
                .text("stiffness (N/m)"),
        )
        .changed();
    if a || b {
        s.set_wall(x, k);
    }
}

/// Trigger, freeze and the visible span.
pub fn trigger(ui: &mut Ui, s: &mut ScopeState) {
    ui.heading("Trigger");
    ui.horizontal(|ui| {
        ui.checkbox(&mut s.trigger.enabled, "on");
        egui::ComboBox::from_label("signal")
            .selected_text(s.trigger.signal.name())
            .show_ui(ui, |ui| {
                for sig in Signal::ALL {
                    ui.selectable_value(&mut s.trigger.signal, sig, sig.name());
                }
            });
    });
    ui.horizontal(|ui| {
        ui.add(egui::DragValue::new(&mut s.trigger.level).speed(0.01))
            .on_hover_text("level, in the signal's unit");
        ui.selectable_value(&mut s.trigger.edge, Edge::Rising, "rising");
        ui.selectable_value(&mut s.trigger.edge, Edge::Falling, "falling");
    });
    ui.horizontal(|ui| {
        let mut frozen = s.is_frozen();
        if ui.checkbox(&mut frozen, "freeze").changed() {
            s.set_frozen(frozen);
        }
        ui.add(
            egui::Slider::new(&mut s.window_s, 0.05..=20.0)
                .logarithmic(true)
                .text("span (s)"),
        );
    });
}

/// Board mode: port, connect, and what the board says.
pub fn board(ui: &mut Ui, s: &mut ScopeState, link: &mut BoardChoice) {
    ui.heading("Board");
    if let Some(b) = &s.board {
        let how = if b.lockstep {
            "lockstep: this simulation is its plant"
        } else {
            "free running on its own sensors"
        };
        ui.label(format!("connected: {} ({how})", b.port));
        if let Some(m) = board_state(ui, b) {
            s.tell_board(m);
        }
        let Some(b) = &s.board else { return };
        if let Some(t) = &b.telemetry {
            ui.label(format!(
                "tick {}  loop {} cycles ({} / {} / {})",
                t.tick, t.loop_cycles, t.stage_cycles[0], t.stage_cycles[1], t.stage_cycles[2]
            ));
            let misses = format!(
                "deadline misses {}  worst jitter {} cycles",
                t.deadline_misses, t.worst_jitter_cycles
            );
            if t.deadline_misses > 0 {
                ui.colored_label(Color32::RED, misses);
            } else {
                ui.label(misses);
            }
        }
        if let Some(r) = &b.reply {
            ui.label(format!("last gain request: {r}"));
        }
        if ui.button("disconnect").clicked() {
            s.disconnect();
        }
        return;
    }
    if let Some((port, lockstep)) = board_choice(ui, link) {
        s.connect(&port, lockstep);
    }
}

/// The connect controls: a serial port (listed, or a path) and lockstep;
/// the port and mode to connect to when the button is pressed.
pub fn board_choice(ui: &mut Ui, link: &mut BoardChoice) -> Option<(String, bool)> {
    let port = &mut link.port;
    ui.horizontal(|ui| {
        egui::ComboBox::from_label("serial port")
            .selected_text(if port.is_empty() {
                "port"
            } else {
                port.as_str()
            })
            .show_ui(ui, |ui| {
                for p in list_ports() {
                    ui.selectable_value(port, p.clone(), p);
                }
            });
        ui.text_edit_singleline(port)
            .on_hover_text("or a path, e.g. the pty QEMU prints");
    });
    ui.checkbox(&mut link.lockstep, "lockstep (processor in the loop)")
        .on_hover_text(
            "the board takes its sensors from this simulation; off for a board on a real device",
        );
    (ui.button("connect").clicked() && !link.port.is_empty())
        .then(|| (link.port.clone(), link.lockstep))
}

/// The controls for a device the PC drives (`twoport devices`): its
/// name, where it is (a serial port; a Touch: its Touch Setup name) and
/// the file it needs; what to open when the button is pressed.
pub fn device_choice(ui: &mut Ui, link: &mut BoardChoice) -> Option<(String, String, String)> {
    ui.horizontal(|ui| {
        egui::ComboBox::from_label("device")
            .selected_text(if link.device.is_empty() {
                "a device the PC drives"
            } else {
                link.device.as_str()
            })
            .show_ui(ui, |ui| {
                for d in ["haply-2diy", "falcon", "touch"] {
                    ui.selectable_value(&mut link.device, d.to_string(), d);
                }
            });
        ui.label("at");
        ui.text_edit_singleline(&mut link.port).on_hover_text(
            "its serial port; a Touch: its name in Touch Setup (empty: the default)",
        );
        ui.label("file");
        ui.text_edit_singleline(&mut link.file)
            .on_hover_text("a Falcon's firmware; a Touch's HD library where not the system's");
    });
    (ui.button("open device").clicked() && !link.device.is_empty())
        .then(|| (link.device.clone(), link.port.clone(), link.file.clone()))
}

/// The board's state machine: its mode, calibration and latched faults by
/// name, and the buttons that move it; what a button asks the board.
pub fn board_state(ui: &mut Ui, b: &BoardLink) -> Option<twoport_link::Message> {
    use twoport_control::Faults;
    use twoport_link::{BoardMode, Message};
    let st = b.status.unwrap_or_default();
    let mode = b.telemetry.map_or(st.mode, |t| t.mode);
    let colour = match mode {
        BoardMode::Armed => Color32::GREEN,
        BoardMode::Homing => Color32::YELLOW,
        BoardMode::Identifying => Color32::LIGHT_BLUE,
        BoardMode::Disarmed => Color32::GRAY,
    };
    ui.colored_label(
        colour,
        format!(
            "{mode:?}, {}",
            if st.calibrated {
                "calibrated"
            } else {
                "not calibrated: home first"
            }
        ),
    );
    let faults = b.faults.unwrap_or(st.faults);
    if faults != 0 {
        ui.colored_label(Color32::RED, format!("faults: {}", Faults(faults)));
        if st.first_fault != 0 {
            ui.label(format!("first: {}", Faults(st.first_fault)));
        }
    }
    if let Some(r) = &b.refusal {
        ui.colored_label(Color32::RED, r);
    }
    let mut say = None;
    ui.horizontal(|ui| {
        if ui.button("home").clicked() {
            say = Some(Message::Home);
        }
        if ui
            .button("arm")
            .on_hover_text("needs calibration, proven gains, the dead-man closed and no fault")
            .clicked()
        {
            say = Some(Message::Arm);
        }
        if ui.button("disarm").clicked() {
            say = Some(Message::Disarm);
        }
        if faults != 0 && ui.button("clear faults").clicked() {
            say = Some(Message::ClearFaults);
        }
    });
    say
}

/// The whole window.
pub fn scope(ui: &mut Ui, s: &mut ScopeState, link: &mut BoardChoice) {
    egui::Panel::top("transport").show(ui, |ui| transport(ui, s));
    egui::Panel::right("controls")
        .min_size(330.0)
        .show(ui, |ui| {
            egui::ScrollArea::vertical().show(ui, |ui| {
                gains(ui, s);
                design_panel(ui, s);
                ui.separator();
                identify_panel(ui, s);
                hand(ui, s);
                wall(ui, s);
                ui.separator();
                trigger(ui, s);
                ui.separator();
                board(ui, s, link);
            });
        });
    egui::CentralPanel::default().show(ui, |ui| plots(ui, s));
}
