//! A PNG of a run: handle position over time, and the forces.

use crate::Sample;
use plotters::prelude::*;
use std::path::Path;

/// Draw `samples` to `out` (PNG).
pub fn png(samples: &[Sample], title: &str, out: &Path) -> Result<(), String> {
    let _ =
        plotters::style::register_font("sans-serif", FontStyle::Normal, dejavu::sans::regular());
    if samples.is_empty() {
        return Err("no samples to plot".into());
    }
    let root = BitMapBackend::new(out, (1100, 720)).into_drawing_area();
    let e = |e: DrawingAreaErrorKind<_>| format!("{}: {e}", out.display());
    root.fill(&WHITE).map_err(e)?;
    let root = root.titled(title, ("sans-serif", 22)).map_err(e)?;
    let (top, bottom) = root.split_vertically(340);
    let t1 = samples.last().map_or(1.0, |s| s.t_s);
    let range = |f: &dyn Fn(&Sample) -> f64| {
        let (lo, hi) = samples
            .iter()
            .map(f)
            .filter(|v| v.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(v), b.max(v))
            });
        let pad = ((hi - lo) * 0.05).max(1e-9);
        (lo - pad)..(hi + pad)
    };
    type Series<'a> = (&'a str, RGBColor, &'a dyn Fn(&Sample) -> f64);
    let panel = |area: &DrawingArea<BitMapBackend, plotters::coord::Shift>,
                 y_desc: &str,
                 series: &[Series]|
     -> Result<(), String> {
        let lo = series
            .iter()
            .map(|s| range(s.2).start)
            .fold(f64::INFINITY, f64::min);
        let hi = series
            .iter()
            .map(|s| range(s.2).end)
            .fold(f64::NEG_INFINITY, f64::max);
        let mut chart = ChartBuilder::on(area)
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(80)
            .build_cartesian_2d(0.0..t1, lo..hi)
            .map_err(e)?;
        chart
            .configure_mesh()
            .x_desc("time (s)")
            .y_desc(y_desc)
            .label_style(("sans-serif", 14))
            .draw()
            .map_err(e)?;
        for (name, color, f) in series {
            let color = *color;
            chart
                .draw_series(LineSeries::new(
                    samples.iter().map(|s| (s.t_s, f(s))),
                    color.stroke_width(2),
                ))
                .map_err(e)?
                .label(*name)
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
                });
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 14))
            .draw()
            .map_err(e)?;
        Ok(())
    };
    panel(
        &top,
        "position (m)",
        &[("handle", BLUE, &|s| s.handle_m), ("VE", RED, &|s| s.ve_m)],
    )?;
    panel(
        &bottom,
        "force (N)",
        &[
            ("human", GREEN, &|s| s.human_n),
            ("actuator (delivered)", BLUE, &|s| s.actuator_n),
            ("VE", RED, &|s| s.ve_n),
        ],
    )?;
    root.present().map_err(e)
}
