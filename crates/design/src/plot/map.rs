//! A map: values at scattered points of a plane, coloured on a log scale
//! (the certified stiffness over a linkage's workspace).

use super::register_font;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// Values at points of a plane.
pub struct Map {
    /// Title.
    pub title: String,
    /// The axes' labels, with units.
    pub x_label: String,
    /// The vertical axis's label.
    pub y_label: String,
    /// What the colour shows, with its unit.
    pub value_label: String,
    /// `(x, y, value)`; values must be > 0 (log colour scale).
    pub points: Vec<(f64, f64, f64)>,
    /// A point to mark (where a proof binds).
    pub mark: Option<(f64, f64)>,
}

/// Draw `map` to `out`; the extension (.png or .svg) picks the format.
pub fn render_map(map: &Map, out: &Path) -> Result<(), crate::Error> {
    register_font();
    let ext = out
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let size = (900, 760);
    match ext.as_deref() {
        Some("png") => draw(map, BitMapBackend::new(out, size).into_drawing_area()),
        Some("svg") => draw(map, SVGBackend::new(out, size).into_drawing_area()),
        _ => Err(format!(
            "{}: the output must end in .png or .svg",
            out.display()
        )),
    }
    .map_err(crate::Error::Plot)
}

fn draw<DB: DrawingBackend>(map: &Map, root: DrawingArea<DB, Shift>) -> Result<(), String> {
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    let pts: Vec<_> = map
        .points
        .iter()
        .copied()
        .filter(|(x, y, v)| x.is_finite() && y.is_finite() && v.is_finite() && *v > 0.0)
        .collect();
    if pts.is_empty() {
        return Err("nothing to plot: no point has a value > 0".into());
    }
    let range = |f: fn(&(f64, f64, f64)) -> f64| {
        let lo = pts.iter().map(f).fold(f64::INFINITY, f64::min);
        let hi = pts.iter().map(f).fold(f64::NEG_INFINITY, f64::max);
        // A flat range gets some width, so that one point still draws.
        let pad = ((hi - lo) * 0.05).max(hi.abs().max(1e-9) * 0.05);
        (lo - pad, hi + pad)
    };
    let (x0, x1) = range(|p| p.0);
    let (y0, y1) = range(|p| p.1);
    let v0 = pts.iter().map(|p| p.2).fold(f64::INFINITY, f64::min);
    let v1 = pts.iter().map(|p| p.2).fold(0.0, f64::max);
    let span = (v1 / v0).ln().max(1e-12);
    let colour = |v: f64| viridis((v / v0).ln() / span);
    root.fill(&WHITE).map_err(e)?;
    let (plot, bar) = root.split_horizontally(780);
    let mut chart = ChartBuilder::on(&plot)
        .caption(&map.title, ("sans-serif", 17))
        .margin(12)
        .x_label_area_size(48)
        .y_label_area_size(70)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(e)?;
    chart
        .configure_mesh()
        .x_desc(&map.x_label)
        .y_desc(&map.y_label)
        .label_style(("sans-serif", 15))
        .axis_desc_style(("sans-serif", 17))
        .draw()
        .map_err(e)?;
    // The weakest points last, on top: a map is read for where it is weak.
    let mut sorted = pts.clone();
    sorted.sort_by(|a, b| b.2.total_cmp(&a.2));
    chart
        .draw_series(
            sorted
                .iter()
                .map(|&(x, y, v)| Circle::new((x, y), 5, colour(v).filled())),
        )
        .map_err(e)?;
    if let Some((x, y)) = map.mark {
        chart
            .draw_series([Cross::new((x, y), 9, RED.stroke_width(3))])
            .map_err(e)?
            .label("binds")
            .legend(|(x, y)| Cross::new((x, y), 6, RED.stroke_width(2)));
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .label_font(("sans-serif", 15))
            .draw()
            .map_err(e)?;
    }
    // The colour bar, log-spaced, with its ends labelled.
    let steps = 64;
    let top = 60;
    let height = 600;
    for i in 0..steps {
        let v = v0 * (span * (steps - 1 - i) as f64 / (steps - 1) as f64).exp();
        let y = top + height * i / steps;
        bar.draw(&Rectangle::new(
            [(20, y), (50, y + height / steps + 1)],
            colour(v).filled(),
        ))
        .map_err(e)?;
    }
    let text = |s: String, y: i32| Text::new(s, (8, y), ("sans-serif", 14));
    bar.draw(&text(format!("{v1:.3e}"), top - 22)).map_err(e)?;
    bar.draw(&text(format!("{v0:.3e}"), top + height + 8))
        .map_err(e)?;
    bar.draw(&text(map.value_label.clone(), top + height + 30))
        .map_err(e)?;
    Ok(())
}

/// Viridis at `t` in [0, 1] (dark blue to yellow), interpolated between
/// five of its colours: perceptually even, and readable in grey.
fn viridis(t: f64) -> RGBColor {
    const STOPS: [(f64, f64, f64); 5] = [
        (68.0, 1.0, 84.0),
        (59.0, 82.0, 139.0),
        (33.0, 145.0, 140.0),
        (94.0, 201.0, 98.0),
        (253.0, 231.0, 37.0),
    ];
    let x = t.clamp(0.0, 1.0) * (STOPS.len() - 1) as f64;
    let i = (x.floor() as usize).min(STOPS.len() - 2);
    let f = x - i as f64;
    let (a, b) = (STOPS[i], STOPS[i + 1]);
    let mix = |p: f64, q: f64| (p + (q - p) * f).round() as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}
