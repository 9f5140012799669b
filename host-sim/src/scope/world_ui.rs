//! The world view of a scene of three axes (two: the top alone): a top
//! (x-y) and a side (x-z) projection with the blocks, the cursor and the held block, a linkage's
//! arm, the grab
//! button, each axis's force on one time axis (and the board's, in board
//! mode), and the board panel. Dragging in a projection drags the hand
//! along its two axes.

use crate::scope::board::WithBoard;
use crate::scope::ui;
use crate::scope::world::WorldState;
use eframe::egui::{self, Color32, Pos2, Rect, Sense, Stroke, Ui, Vec2};
use egui_plot::{Legend, Line, Plot, PlotPoints};
use twoport_link::Message;

/// The whole view.
pub fn world<const N: usize>(ui: &mut Ui, s: &mut WorldState<N>) {
    ui.heading(s.name().to_string());
    status(ui, s);
    board(ui, s);
    ui.horizontal(|ui| {
        let w = (ui.available_width() / 2.0 - 8.0).max(100.0);
        projection(ui, s, [0, 1], "top: x right, y up", w);
        if N == 3 {
            projection(ui, s, [0, 2], "side: x right, z up", w);
        }
    });
    forces(ui, s);
}

fn status<const N: usize>(ui: &mut Ui, s: &mut WorldState<N>) {
    ui.horizontal(|ui| {
        let t = s.last.map_or(0.0, |l| l.t_s);
        ui.label(format!("t = {t:.2} s"));
        let c = s.cursor_m();
        ui.label(format!(
            "cursor ({:.1}, {:.1}, {:.1}) mm",
            c[0] * 1e3,
            c[1] * 1e3,
            c[2] * 1e3
        ));
        let label = match s.held() {
            Some(i) => format!("let go of block {i}"),
            None => "grab".to_string(),
        };
        if ui.button(label).clicked() {
            s.toggle_grab();
        }
        if let Some(why) = &s.stopped {
            ui.label(why.clone());
        }
    });
}

/// Board mode: connect a board of the scene's axes, or open a device the
/// PC drives; its state and buttons (calibrate where the world's cursor
/// starts, a device at its image's rest pose, then arm), disconnect.
fn board<const N: usize>(ui: &mut Ui, s: &mut WorldState<N>) {
    ui.horizontal(|ui| {
        let Some(b) = &s.board else {
            ui.label("board:");
            if let Some((port, lockstep)) = ui::board_choice(ui, &mut s.link) {
                s.connect(&port, lockstep);
            }
            if let Some((name, path, file)) = ui::device_choice(ui, &mut s.link) {
                let file = (!file.is_empty()).then(|| std::path::PathBuf::from(file));
                s.connect_device(&name, &path, file.as_deref());
            }
            return;
        };
        let how = if b.lockstep {
            "lockstep"
        } else {
            "free running"
        };
        ui.label(format!("board: {} ({how})", b.port));
        let mut say = ui::board_state(ui, b);
        let device = b.device.is_some();
        let hint = if device {
            "the handle held at the device's rest pose (its image's)"
        } else {
            "the device stands where the world's cursor starts"
        };
        if ui.button("calibrate").on_hover_text(hint).clicked() {
            if device {
                s.calibrate_device();
            } else {
                match s.at_rest_pm() {
                    Ok(position_pm) => say = Some(Message::Calibrate { position_pm }),
                    Err(e) => s.message = Some(e.to_string()),
                }
            }
        }
        if let Some(m) = say {
            s.tell_board(m);
        }
        if ui.button("disconnect").clicked() {
            s.disconnect();
        }
    });
    if let Some(m) = &s.message {
        ui.colored_label(Color32::RED, m.clone());
    }
}

/// One projection onto `axes` (the first drawn right, the second up).
fn projection<const N: usize>(
    ui: &mut Ui,
    s: &mut WorldState<N>,
    axes: [usize; 2],
    title: &str,
    width: f32,
) {
    ui.vertical(|ui| {
        ui.label(title);
        let (resp, painter) = ui.allocate_painter(Vec2::new(width, width * 0.75), Sense::drag());
        let r = resp.rect;
        painter.rect_filled(r, 2.0, Color32::from_gray(24));
        let [(ax0, ax1), (ay0, ay1)] = axes.map(|a| s.span_m[a]);
        let to_px = |x: f64, y: f64| {
            Pos2::new(
                r.left() + ((x - ax0) / (ax1 - ax0)) as f32 * r.width(),
                r.bottom() - ((y - ay0) / (ay1 - ay0)) as f32 * r.height(),
            )
        };
        let held = s.held();
        for (i, b) in s.blocks().iter().enumerate() {
            let lo = axes.map(|a| b.min[a].nm() as f64 * 1e-9);
            let hi = [0, 1].map(|k| lo[k] + b.size_nm[axes[k]] as f64 * 1e-9);
            let rect = Rect::from_two_pos(to_px(lo[0], lo[1]), to_px(hi[0], hi[1]));
            let fill = if Some(i) == held {
                Color32::from_rgb(240, 160, 40)
            } else {
                Color32::from_rgb(70, 110, 170)
            };
            painter.rect_filled(rect, 0.0, fill);
            painter.rect_stroke(
                rect,
                0.0,
                Stroke::new(1.0, Color32::from_gray(200)),
                egui::StrokeKind::Inside,
            );
        }
        // A linkage's arm, its links in grey and its joints as dots, clipped
        // to the view (its base may lie outside the workspace drawn).
        if let Some(arm) = s.arm() {
            let clipped = painter.with_clip_rect(r);
            for line in arm {
                let pts: Vec<Pos2> = line.iter().map(|p| to_px(p[axes[0]], p[axes[1]])).collect();
                clipped.add(egui::Shape::line(
                    pts.clone(),
                    Stroke::new(3.0, Color32::from_gray(170)),
                ));
                for p in pts {
                    clipped.circle_filled(p, 3.0, Color32::from_gray(220));
                }
            }
        }
        let c = s.cursor_m();
        painter.circle_filled(
            to_px(c[axes[0]], c[axes[1]]),
            4.0,
            Color32::from_rgb(230, 60, 60),
        );
        if resp.dragged() {
            let d = resp.drag_delta();
            let mut m = [0.0; 3];
            m[axes[0]] = d.x as f64 / r.width() as f64 * (ax1 - ax0);
            m[axes[1]] = -d.y as f64 / r.height() as f64 * (ay1 - ay0);
            s.drag(m);
        }
    });
}

/// Each axis's actuator force over the last seconds.
fn forces<const N: usize>(ui: &mut Ui, s: &WorldState<N>) {
    const COLORS: [Color32; 3] = [
        Color32::from_rgb(230, 90, 90),
        Color32::from_rgb(90, 200, 110),
        Color32::from_rgb(100, 150, 240),
    ];
    Plot::new("world-forces")
        .height(ui.available_height().max(80.0))
        .legend(Legend::default())
        .allow_drag(false)
        .allow_zoom(false)
        .allow_scroll(false)
        .show(ui, |p| {
            for (i, (ring, name)) in s
                .forces
                .iter()
                .zip(["f_x (N)", "f_y (N)", "f_z (N)"])
                .enumerate()
            {
                let pts: Vec<[f64; 2]> = ring.iter().map(|&(t, f)| [t, f]).collect();
                p.line(Line::new(name, PlotPoints::from(pts)).color(COLORS[i]));
            }
            if s.board.is_some() {
                for (i, (ring, name)) in s
                    .board_forces
                    .iter()
                    .zip(["board f_x (N)", "board f_y (N)", "board f_z (N)"])
                    .enumerate()
                {
                    let pts: Vec<[f64; 2]> = ring.iter().map(|&(t, f)| [t, f]).collect();
                    p.line(
                        Line::new(name, PlotPoints::from(pts))
                            .color(COLORS[i])
                            .style(egui_plot::LineStyle::dashed_loose()),
                    );
                }
            }
        });
}
