//! Figures on log-log axes in the scope: curves of (Hz, value) as lines
//! of decades, the spans a log axis cannot show named in the legend, and
//! a grid at every decade. The design panel and the identification panel
//! draw through it.

use eframe::egui::{Color32, RichText, Ui};
use egui_plot::{Legend, Line, Plot, PlotPoints};

/// A curve of the design figure as a log-log axis can show it: each run of
/// positive values as its own line of `[log10 f, log10 v]` points, a value
/// below `floor` (decades) drawn at the floor so that a dive leaves the
/// plot at its bottom edge, and the spans where the value is not positive
/// (there any coupling meets the bound), which a log axis cannot draw.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LogCurve {
    /// The runs of positive values, each a line of its own.
    pub runs: Vec<Vec<[f64; 2]>>,
    /// Each span of non-positive values: its first and last frequency (Hz).
    pub not_positive: Vec<(f64, f64)>,
}

impl LogCurve {
    /// `points` (frequency in Hz, value), in rising frequency.
    pub fn new(points: &[(f64, f64)], floor: f64) -> Self {
        let mut c = LogCurve::default();
        let mut run = Vec::new();
        let mut span: Option<(f64, f64)> = None;
        for &(f, v) in points.iter().filter(|(f, v)| *f > 0.0 && !v.is_nan()) {
            if v > 0.0 {
                if let Some(s) = span.take() {
                    c.not_positive.push(s);
                }
                run.push([f.log10(), v.log10().max(floor)]);
            } else {
                if !run.is_empty() {
                    c.runs.push(std::mem::take(&mut run));
                }
                span = Some(span.map_or((f, f), |(a, _)| (a, f)));
            }
        }
        c.runs.extend((!run.is_empty()).then_some(run));
        c.not_positive.extend(span);
        c
    }

    /// Every drawn point, run after run.
    pub fn points(&self) -> impl Iterator<Item = [f64; 2]> + '_ {
        self.runs.iter().flatten().copied()
    }

    /// The curve's legend name: `label`, and where it is not positive.
    pub fn legend(&self, label: &str) -> String {
        if self.not_positive.is_empty() {
            return label.to_string();
        }
        let spans: Vec<String> = self
            .not_positive
            .iter()
            .map(|(a, b)| format!("{}-{}", hz(*a), hz(*b)))
            .collect();
        // (On a second line: the panel is narrow.)
        format!("{label}\n≤ 0 (not drawn) at {} Hz", spans.join(", "))
    }
}

/// A frequency to three significant figures, without trailing zeros.
pub(crate) fn hz(f: f64) -> String {
    let digits = (2 - f.abs().log10().floor() as i32).max(0) as usize;
    let s = format!("{f:.digits$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// A curve of the design figure on log-log axes: `[log10 f, log10 v]`,
/// leaving out the points where the value is not positive (where the bound
/// turns negative any coupling meets it), as the paper's figures do.
pub fn log_log(points: &[(f64, f64)]) -> Vec<[f64; 2]> {
    LogCurve::new(points, f64::NEG_INFINITY).points().collect()
}

/// A grid line at every decade of an axis in decades (a linear spacer
/// would step by ten decades over a range of seven, and label none).
pub(crate) fn decades(input: egui_plot::GridInput) -> Vec<egui_plot::GridMark> {
    let (lo, hi) = input.bounds;
    let (lo, hi) = (lo.ceil() as i64, hi.floor() as i64);
    (lo..=hi.max(lo))
        .map(|d| egui_plot::GridMark {
            value: d as f64,
            step_size: 1.0,
        })
        .collect()
}

/// `10^x` for an axis in decades.
pub(crate) fn decade_label(x: f64) -> String {
    if (x - x.round()).abs() < 1e-6 {
        format!("1e{:.0}", x.round())
    } else {
        String::new()
    }
}

/// A figure's curves on log-log axes, framed on what they show.
pub(crate) fn figure_plot(ui: &mut Ui, id: &str, fig: &twoport_design::plot::Figure) {
    ui.label(RichText::new(&fig.title).small());
    Plot::new(id)
        .height(170.0)
        .legend(Legend::default().position(egui_plot::Corner::LeftBottom))
        .y_axis_min_width(40.0)
        .x_axis_label(fig.x_label.clone())
        .y_axis_label(fig.y_label.clone())
        .x_axis_formatter(|m, _| decade_label(m.value))
        .y_axis_formatter(|m, _| decade_label(m.value))
        .x_grid_spacer(decades)
        .y_grid_spacer(decades)
        .show(ui, |p| curves(p, id, fig, f64::NEG_INFINITY));
}

/// A figure's curves as log-log lines, each value clamped to `floor`
/// decades (and left out where not positive).
pub(crate) fn curves(
    p: &mut egui_plot::PlotUi,
    id: &str,
    fig: &twoport_design::plot::Figure,
    floor: f64,
) {
    for (i, c) in fig.curves.iter().enumerate() {
        let color = Color32::from_rgb(c.color.0, c.color.1, c.color.2);
        let curve = LogCurve::new(&c.points, floor);
        let name = curve.legend(&c.label);
        for (j, run) in curve.runs.into_iter().enumerate() {
            p.line(
                Line::new(name.clone(), PlotPoints::from(run))
                    .color(color)
                    .width(c.width as f32)
                    .id((id, i, j)),
            );
        }
    }
}
