//! A scene's identification experiment, run from the scope: the board's
//! own loop in-process against the scene's plant (as `host-sim pil` runs
//! it), its record fitted as `twoport identify` fits it, and the fit's
//! figures. State only; `ui.rs` draws it.

use crate::engine::scene::Scene;
use crate::link::{LinkFaults, LocalBoard};
use crate::pil;
use twoport_design::plot::Figure;
use twoport_identify::fit::{self, chain::ModelBase, Form, Measured};

/// What the experiment showed: a line on the fit, and its figures.
pub struct Identification {
    /// The order chosen, the resonances, the friction and the cogging.
    pub summary: String,
    /// The measured responses with the fit's, and the coherence, each
    /// with its name (`encoder`, `load_cell`, `coherence`).
    pub figures: Vec<(&'static str, Figure)>,
}

/// Periods skipped while the hold's own mode settles.
const SKIP: usize = 2;

/// Play `scene`'s experiment and fit its record, or say why not.
pub fn identify(scene: &Scene) -> Result<Identification, String> {
    if scene.identify.is_none() {
        return Err("this scene has no [identify] section".into());
    }
    let model = scene.device_model().map_err(|e| e.to_string())?;
    let ticks = (scene.duration_s / scene.period()).round() as u64;
    let board = LocalBoard::excalibur().map_err(|e| e.to_string())?;
    let run =
        pil::run(scene.clone(), ticks, board, LinkFaults::default()).map_err(|e| e.to_string())?;
    let log = run
        .experiment_log(model.force_sensor)
        .ok_or("the board played no experiment (did it arm?)")?
        .map_err(|e| e.to_string())?;
    let data = Measured::from_log(&log, SKIP).map_err(|e| e.to_string())?;
    data.band_reaches(log.period_s).map_err(|e| e.to_string())?;
    // What no experiment measures comes from the scene's own model: the
    // amplifier and the load cell's filter, as a lab knows its own.
    let base = ModelBase {
        name: format!("identified from {}", scene.name),
        period_s: log.period_s,
        peak_force_n: model.peak_force_n,
        continuous_force_n: model.continuous_force_n,
        load_cell_pole_rad_s: model.force_sensor.then_some(model.load_cell_pole_rad_s),
    };
    let (fits, best) = fit::fit_orders(&data, &base);
    let f = fit::chosen(&fits, best).map_err(|e| e.to_string())?;
    let figures = twoport_identify::figures::figures(&data, f)
        .ok_or("the fitted model has no finite response")?;
    let form = match f.form {
        Form::Chain(_) => "a chain of masses",
        Form::Modal(_) => "modes, the handle on its load cell",
    };
    let mut summary = format!(
        "{} modes ({form}), chi2/nu {:.2}",
        f.form.modes(),
        f.reduced_chi2()
    );
    let res: Vec<String> = f
        .resonances()
        .iter()
        .map(|(hz, _)| format!("{hz:.1}"))
        .collect();
    if !res.is_empty() {
        summary += &format!("; resonances {} Hz", res.join(", "));
    }
    if let Some(c) = f.model.coulomb_friction_n {
        summary += &format!("; friction {c:.3} N");
    }
    if let Some(c) = f.cogging {
        summary += &format!(
            "; cogging {:.3} N every {:.2} mm",
            c.amplitude_n,
            c.period_m * 1e3
        );
    }
    Ok(Identification { summary, figures })
}
