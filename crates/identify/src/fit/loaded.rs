//! A bare record's fit refitted with a loaded record beside it: the
//! handle's side, which only a mass on the handle shows.

use super::chain::Chain;
use super::modal::Modal;
use super::{finish, Fit, Form, Loaded, Measured};
use nalgebra::DVector;
use num_complex::Complex64;
use std::f64::consts::TAU;

/// A bare record's fit `bare` refitted to both records, bare and loaded:
/// from its parameters, and in the modal form with a
/// [bypass](Modal::bypass_npm) beside the load cell, which only the loaded
/// record shows. The bypass starts from a few strengths, the handle's
/// mass from the bare fit's and from what the load cell weighed (the fit
/// is not convex in them), and the least misfit is kept.
pub(super) fn refit_loaded(bare: &Fit, data: &Measured, loaded: &Loaded) -> Option<Fit> {
    let base = &bare.base;
    let encoder_only;
    let data = if bare.model.force_sensor {
        data
    } else {
        encoder_only = Measured {
            load_cell: None,
            loaded: Some(Box::new(Loaded {
                added_kg: loaded.added_kg,
                data: Measured {
                    load_cell: None,
                    ..loaded.data.clone()
                },
            })),
            ..data.clone()
        };
        &encoder_only
    };
    let m = match &bare.form {
        Form::Chain(c) => {
            let (masses, sign) = (c.masses_kg.len(), c.load_cell_sign);
            let at = c.ground.map(|g| g.at);
            return finish(
                data,
                base,
                bare.params.clone(),
                |p| Chain::from_log(masses, at, p, sign).model(base),
                |p| Form::Chain(Chain::from_log(masses, at, p, sign)),
            );
        }
        Form::Modal(m) => m,
    };
    let sign = m.load_cell_sign;
    let from = |p: &DVector<f64>| Modal::from_params(p, sign, base.period_s, true);
    // The lowest mode the bare fit found, or the top of the band.
    let w = m
        .modes
        .iter()
        .map(|m| m.mode.omega_n)
        .fold(TAU * data.position.freq_hz.last().copied()?, f64::min);
    // The load cell weighs the handle: at the lowest harmonics it reads
    // `m_h` per unit of acceleration bare and `m_h + m` loaded, so the
    // ratio of the two readings per motion gives `m_h` (the bypass hardly
    // stretches there). The bare fit's is a start too.
    let weighed = weighed_handle(data, loaded).filter(|h| (0.2..5.0).contains(&(h / m.handle_kg)));
    // Every parameter from several starts: the misfit is not convex in
    // the handle's mass and the bypass, and the modes move with them.
    [Some(m.handle_kg), weighed]
        .into_iter()
        .flatten()
        .flat_map(|h| [1e-3, 1e-2, 1e-1, 1.0].map(|share| (h, share * h * w * w)))
        .filter_map(|(handle_kg, kb)| {
            let start = Modal {
                handle_kg,
                bypass_npm: Some(kb),
                ..m.clone()
            };
            finish(
                data,
                base,
                start.to_params(),
                |p| from(p).model(base),
                |p| Form::Modal(from(p)),
            )
        })
        .min_by(|a, b| a.chi2.total_cmp(&b.chi2))
}

/// The handle's mass past the load cell (kg) from the lowest harmonics of
/// a bare and a loaded record: the load cell's reading per encoder motion
/// is `m_h ω²` bare and `(m_h + m) ω²` loaded.
fn weighed_handle(bare: &Measured, loaded: &Loaded) -> Option<f64> {
    let per_motion = |d: &Measured| -> Option<Vec<Complex64>> {
        let lc = d.load_cell.as_ref()?;
        Some(
            lc.response
                .iter()
                .zip(&d.position.response)
                .take(5)
                .map(|(f, x)| f / x)
                .collect(),
        )
    };
    let (b, l) = (per_motion(bare)?, per_motion(&loaded.data)?);
    let ratio = b.iter().zip(&l).map(|(b, l)| (l / b).re).sum::<f64>() / b.len() as f64;
    let m = loaded.added_kg / (ratio - 1.0);
    (m.is_finite() && m > 0.0).then_some(m)
}
