//! The figures of a fit: the measured responses beside the fitted
//! model's, with the measurement's deviation, and the coherence. The
//! command line draws them to PNG or SVG, the scope in its window: one
//! set of curves for both.

use crate::fit::{self, Fit, Measured};
use crate::frf::Frf;
use num_complex::Complex64;
use twoport_design::plot::{self, Curve, Figure, LegendAt, RGBColor};

/// Each figure of `fit` on `data`, with its file stem: `encoder`,
/// `load_cell` (where there is one) and `coherence`; `None` where the
/// fitted model has no finite response.
pub fn figures(data: &Measured, f: &Fit) -> Option<Vec<(&'static str, Figure)>> {
    let model = fit::sampled_response(&f.model, &data.position.freq_hz)?;
    let curve = |label: &str,
                 color: RGBColor,
                 width: u32,
                 dashed: bool,
                 frf: &Frf,
                 value: &dyn Fn(usize) -> f64| Curve {
        label: label.into(),
        width,
        dashed,
        color,
        points: frf
            .freq_hz
            .iter()
            .enumerate()
            .map(|(i, hz)| (*hz, value(i)))
            .collect(),
    };
    let x = &data.position;
    // The measured response, the fit's, and the measurement's deviation.
    let fitted = |frf: &Frf, pick: fn(&(Complex64, Complex64)) -> Complex64| {
        vec![
            curve("measured", plot::BLUE, 2, false, frf, &|i| {
                frf.response[i].norm()
            }),
            curve("fit", plot::INK, 2, true, frf, &|i| pick(&model[i]).norm()),
            curve("measured, 1 sigma", plot::RED, 1, false, frf, &|i| {
                frf.variance[i].sqrt()
            }),
        ]
    };
    let figure = |title: &str, y_label: &str, curves| Figure {
        x_label: "frequency (Hz)".into(),
        legend: LegendAt::LowerRight,
        title: title.into(),
        y_label: y_label.into(),
        curves,
    };
    // Each sensor's response, and its coherence on one figure. On a log
    // axis as what the coherence leaves, 1 - γ²: the noise's share of one
    // period's response, from 1e-6 to one half at a glance.
    let sensors = [
        Some((
            "encoder",
            "Actuator force to encoder: measured and fitted",
            "|X/F| (m/N)",
            x,
            plot::BLUE,
            (|m| m.0) as fn(&(Complex64, Complex64)) -> Complex64,
        )),
        data.load_cell.as_ref().map(|lc| {
            (
                "load_cell",
                "Actuator force to load cell: measured and fitted",
                "|F_lc/F| (N/N)",
                lc,
                plot::RED,
                (|m| m.1) as fn(&(Complex64, Complex64)) -> Complex64,
            )
        }),
    ];
    let (mut out, mut coherence) = (Vec::new(), Vec::new());
    for (stem, title, y_label, frf, color, pick) in sensors.into_iter().flatten() {
        out.push((stem, figure(title, y_label, fitted(frf, pick))));
        let c = frf.coherence();
        let label = stem.replace('_', " ");
        coherence.push(curve(&label, color, 2, false, frf, &|i| 1.0 - c[i]));
    }
    out.push((
        "coherence",
        figure(
            "What the excitation does not explain: 1 - coherence",
            "1 - coherence (noise share)",
            coherence,
        ),
    ));
    Some(out)
}
