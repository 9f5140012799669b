//! The view of a teleoperation scene: the law and channel, run, pause and
//! start again, a push on the master's handle, and both devices on one
//! time axis: their positions, then their forces.

use crate::scope::rings::Ring;
use crate::scope::teleop::TeleopState;
use eframe::egui::{self, Color32, Ui};
use egui_plot::{Line, PlotPoints};
use twoport_design::verify::TeleopLaw;

const MASTER: Color32 = Color32::from_rgb(31, 119, 180);
const SLAVE: Color32 = Color32::from_rgb(214, 39, 40);
const HAND: Color32 = Color32::from_rgb(44, 160, 44);

/// The whole view.
pub fn teleop(ui: &mut Ui, s: &mut TeleopState) {
    ui.heading(s.scene().name.clone());
    ui.label(describe(s));
    controls(ui, s);
    let h = ((ui.available_height() - 16.0) / 2.0).max(80.0);
    let (t1, span) = (s.time_s(), 5.0);
    let t0 = (t1 - span).max(0.0);
    let [m, l] = &s.sides;
    plot(
        ui,
        "teleop-positions",
        h,
        (t0, t0 + span),
        &[
            ("master position (m)", MASTER, &m.position_m),
            ("slave position (m)", SLAVE, &l.position_m),
        ],
    );
    plot(
        ui,
        "teleop-forces",
        h,
        (t0, t0 + span),
        &[
            ("operator's force (N)", HAND, &m.hand_n),
            ("master actuator (N)", MASTER, &m.actuator_n),
            ("slave actuator (N)", SLAVE, &l.actuator_n),
        ],
    );
}

/// The law and the channel, in a line.
fn describe(s: &TeleopState) -> String {
    let sc = s.scene();
    let law = match sc.law {
        TeleopLaw::FourChannel(g) => format!(
            "four channels: k_m {} N/m, b_m {} N s/m, b_local {} N s/m, k_s {} N/m, b_s {} N s/m, c2 {}, c3 {}, c5 {}, c6 {}",
            g.k_m_npm, g.b_m_nspm, g.b_local_nspm, g.k_s_npm, g.b_s_nspm, g.c2, g.c3, g.c5, g.c6
        ),
        TeleopLaw::Wave(w) => format!(
            "wave variables: b {} N s/m, filter pole {}",
            w.b_nspm, w.filter_pole
        ),
    };
    let c = &sc.channel;
    format!(
        "{law}; channel {} ticks each way{}{}",
        c.delay_ticks,
        if c.jitter_ticks > 0 {
            format!(", jitter up to {} more", c.jitter_ticks)
        } else {
            String::new()
        },
        if c.guard.is_some() { ", guarded" } else { "" }
    )
}

fn controls(ui: &mut Ui, s: &mut TeleopState) {
    ui.horizontal(|ui| {
        let label = if s.running { "pause" } else { "run" };
        if ui.button(label).clicked() {
            s.running = !s.running;
        }
        if ui.button("start again").clicked() {
            if let Err(e) = s.reset() {
                s.stopped = Some(e.to_string());
            }
        }
        let mut push = s.push_n as f32;
        let slider = egui::Slider::new(&mut push, -5.0..=5.0).text("push on the master (N)");
        if ui.add(slider).changed() {
            s.set_push(f64::from(push));
        }
        ui.label(format!("t = {:.2} s", s.time_s()));
        if let Some(l) = s.last {
            ui.label(format!(
                "master {:.2} mm, slave {:.2} mm",
                l.master.handle_m[0] * 1e3,
                l.slave.handle_m[0] * 1e3
            ));
        }
        if let Some(why) = &s.stopped {
            ui.colored_label(Color32::RED, why.clone());
        }
    });
}

/// One plot of named rings over `[t0, t1)`.
fn plot(
    ui: &mut Ui,
    id: &str,
    height: f32,
    (t0, t1): (f64, f64),
    lines: &[(&str, Color32, &Ring)],
) {
    crate::scope::ui::time_plot(id, height, "teleop-time").show(ui, |p| {
        p.set_plot_bounds_x(t0..=t1);
        p.set_auto_bounds([false, true]);
        for (name, color, ring) in lines {
            let pts: Vec<[f64; 2]> = ring
                .iter()
                .filter(|(t, _)| *t >= t0)
                .map(|&(t, v)| [t, v])
                .collect();
            p.line(Line::new(*name, PlotPoints::from(pts)).color(*color));
        }
    });
}
