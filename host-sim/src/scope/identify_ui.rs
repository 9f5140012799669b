//! The identification panel: a scene's experiment played and fitted
//! (`identify`), its line and its figures.

use crate::scope::app::ScopeState;
use crate::scope::log_plot::figure_plot;
use eframe::egui::{Color32, Ui};

/// A scene's identification experiment: play it, and the fit's figures.
pub fn identify_panel(ui: &mut Ui, s: &mut ScopeState) {
    if s.scene().identify.is_none() {
        return;
    }
    ui.heading("Identification");
    if ui.button("Play the experiment and fit").clicked() {
        s.identify();
    }
    match &s.identification {
        None => {
            ui.label("the board plays the scene's multisine in-process, then fits its record");
        }
        Some(Err(e)) => {
            ui.colored_label(Color32::from_rgb(190, 40, 40), e);
        }
        Some(Ok(id)) => {
            ui.label(&id.summary);
            for (name, fig) in &id.figures {
                figure_plot(ui, name, fig);
            }
        }
    }
    ui.separator();
}
