//! The paper's figures: design bounds (Figs 8, 9) and impedance ranges
//! (Fig 10), log-log against frequency, as PNG or SVG.

use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

mod map;

pub use map::{render_map, Map};
pub use plotters::style::RGBColor;

/// The figures' palette: bounds and references.
pub const GREY: RGBColor = RGBColor(110, 110, 110);
/// Measured or designed.
pub const BLUE: RGBColor = RGBColor(31, 90, 180);
/// The other side of a pair.
pub const RED: RGBColor = RGBColor(190, 40, 40);
/// A fit or a model.
pub const INK: RGBColor = RGBColor(20, 20, 20);

/// One curve: a label, a style, and (frequency Hz, value) points. Points
/// with a value <= 0 are left out (log axis), breaking the line there, as
/// the paper's Fig. 8 does where the bound turns negative.
pub struct Curve {
    /// Legend text.
    pub label: String,
    /// Line width (px) and whether dashed.
    pub width: u32,
    /// Dashed line.
    pub dashed: bool,
    /// Colour.
    pub color: RGBColor,
    /// (Hz, value) points.
    pub points: Vec<(f64, f64)>,
}

/// A corner of the plot, for the legend.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LegendAt {
    /// Lower right.
    LowerRight,
    /// Upper left.
    UpperLeft,
}

/// A log-log figure.
pub struct Figure {
    /// Title.
    pub title: String,
    /// X axis label with unit (the curves' first coordinate).
    pub x_label: String,
    /// Y axis label with unit.
    pub y_label: String,
    /// Where the legend goes: the corner the curves leave empty.
    pub legend: LegendAt,
    /// The curves.
    pub curves: Vec<Curve>,
}

fn register_font() {
    // Fonts are embedded so that plotting needs no system fonts; a second
    // registration of the same name is harmless.
    let _ =
        plotters::style::register_font("sans-serif", FontStyle::Normal, dejavu::sans::regular());
}

/// Draw `fig` to `out`; the extension (.png or .svg) picks the format.
pub fn render(fig: &Figure, out: &Path) -> Result<(), crate::Error> {
    render_to(fig, out).map_err(crate::Error::Plot)
}

fn render_to(fig: &Figure, out: &Path) -> Result<(), String> {
    register_font();
    let ext = out
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let size = (1000, 640);
    match ext.as_deref() {
        Some("png") => draw(fig, BitMapBackend::new(out, size).into_drawing_area()),
        Some("svg") => draw(fig, SVGBackend::new(out, size).into_drawing_area()),
        _ => Err(format!(
            "{}: the output must end in .png or .svg",
            out.display()
        )),
    }
}

/// A frequency tick: 0.1, 1, 10, 100 rather than 0.100, 100.000.
fn tick(v: f64) -> String {
    if v >= 1.0 {
        format!("{v:.0}")
    } else {
        let s = format!("{v:.3}");
        s.trim_end_matches('0').to_string()
    }
}

fn segments(points: &[(f64, f64)]) -> Vec<Vec<(f64, f64)>> {
    let mut out = vec![Vec::new()];
    for &(x, y) in points {
        if y > 0.0 && y.is_finite() {
            out.last_mut().expect("non-empty").push((x, y));
        } else if !out.last().expect("non-empty").is_empty() {
            out.push(Vec::new());
        }
    }
    out.retain(|s| !s.is_empty());
    out
}

fn draw<DB: DrawingBackend>(fig: &Figure, root: DrawingArea<DB, Shift>) -> Result<(), String> {
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    root.fill(&WHITE).map_err(e)?;
    let all: Vec<(f64, f64)> = fig
        .curves
        .iter()
        .flat_map(|c| c.points.iter().copied())
        .filter(|(x, y)| *x > 0.0 && *y > 0.0 && y.is_finite())
        .collect();
    if all.is_empty() {
        return Err("nothing to plot: every value is <= 0".into());
    }
    let fold = |f: fn(f64, f64) -> f64, init: f64, pick: fn(&(f64, f64)) -> f64| {
        all.iter().map(pick).fold(init, f)
    };
    let (x0, x1) = (
        fold(f64::min, f64::INFINITY, |p| p.0),
        fold(f64::max, 0.0, |p| p.0),
    );
    let (y0, y1) = (
        fold(f64::min, f64::INFINITY, |p| p.1),
        fold(f64::max, 0.0, |p| p.1),
    );
    let mut chart = ChartBuilder::on(&root)
        .caption(&fig.title, ("sans-serif", 22))
        .margin(12)
        .margin_right(40)
        .x_label_area_size(48)
        .y_label_area_size(80)
        .build_cartesian_2d((x0..x1).log_scale(), (y0 / 2.0..y1 * 2.0).log_scale())
        .map_err(e)?;
    chart
        .configure_mesh()
        .x_desc(fig.x_label.as_str())
        .y_desc(&fig.y_label)
        .label_style(("sans-serif", 15))
        .axis_desc_style(("sans-serif", 17))
        .x_label_formatter(&|v| tick(*v))
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .draw()
        .map_err(e)?;
    for c in &fig.curves {
        let style = ShapeStyle::from(&c.color).stroke_width(c.width);
        let mut first = true;
        for seg in segments(&c.points) {
            let anno = if c.dashed {
                chart.draw_series(DashedLineSeries::new(seg, 8, 6, style))
            } else {
                chart.draw_series(LineSeries::new(seg, style))
            }
            .map_err(e)?;
            if first {
                let (color, w, dashed) = (c.color, c.width, c.dashed);
                anno.label(c.label.clone()).legend(move |(x, y)| {
                    let st = ShapeStyle::from(&color).stroke_width(w);
                    let gap = if dashed { 6 } else { 0 };
                    EmptyElement::at((x, y))
                        + PathElement::new(vec![(0, 0), (9, 0)], st)
                        + PathElement::new(vec![(9 + gap, 0), (24, 0)], st)
                });
                first = false;
            }
        }
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 15))
        .position(match fig.legend {
            LegendAt::LowerRight => SeriesLabelPosition::LowerRight,
            LegendAt::UpperLeft => SeriesLabelPosition::UpperLeft,
        })
        .draw()
        .map_err(e)?;
    root.present().map_err(e)?;
    Ok(())
}
