//! A PNG of a run: handle position over time, and the forces.

use crate::engine::teleop::TeleopSample;
use crate::Error;
use crate::Sample;
use plotters::prelude::*;
use std::path::Path;

/// One line of a panel: its legend, colour and value per sample.
type Series<'a, T> = (&'a str, RGBColor, &'a dyn Fn(&T) -> f64);

/// Draw the first axis of `samples` to `out` (PNG).
pub fn png<const N: usize>(samples: &[Sample<N>], title: &str, out: &Path) -> Result<(), Error> {
    panels_png(
        samples,
        &|s| s.t_s,
        title,
        out,
        &[
            (
                "position (m)",
                &[
                    ("handle", BLUE, &|s| s.handle_m[0]),
                    ("VE", RED, &|s| s.ve_m[0]),
                ],
            ),
            (
                "force (N)",
                &[
                    ("human", GREEN, &|s| s.human_n[0]),
                    ("actuator (delivered)", BLUE, &|s| s.actuator_n[0]),
                    ("VE", RED, &|s| s.ve_n[0]),
                ],
            ),
        ],
    )
}

/// A teleoperation run to `out` (PNG): both devices' positions, and the
/// operator's, the environment's and both actuators' forces.
pub fn teleop_png(samples: &[TeleopSample], title: &str, out: &Path) -> Result<(), Error> {
    panels_png(
        samples,
        &|s| s.master.t_s,
        title,
        out,
        &[
            (
                "position (m)",
                &[
                    ("master", BLUE, &|s| s.master.handle_m[0]),
                    ("slave", RED, &|s| s.slave.handle_m[0]),
                ],
            ),
            (
                "force (N)",
                &[
                    ("operator", GREEN, &|s| s.master.human_n[0]),
                    ("slave's hand (environment)", MAGENTA, &|s| {
                        s.slave.human_n[0]
                    }),
                    ("master actuator", BLUE, &|s| s.master.actuator_n[0]),
                    ("slave actuator", RED, &|s| s.slave.actuator_n[0]),
                ],
            ),
        ],
    )
}

/// `samples` against `time` (s) to `out` (PNG), one panel over another,
/// each its y label and its lines.
fn panels_png<T>(
    samples: &[T],
    time: &dyn Fn(&T) -> f64,
    title: &str,
    out: &Path,
    panels: &[(&str, &[Series<T>])],
) -> Result<(), Error> {
    let _ =
        plotters::style::register_font("sans-serif", FontStyle::Normal, dejavu::sans::regular());
    if samples.is_empty() {
        return Err("no samples to plot".into());
    }
    let root = BitMapBackend::new(out, (1100, 720)).into_drawing_area();
    let e = |e: DrawingAreaErrorKind<_>| Error::Output(format!("{}: {e}", out.display()));
    root.fill(&WHITE).map_err(e)?;
    let root = root.titled(title, ("sans-serif", 22)).map_err(e)?;
    let areas = root.split_evenly((panels.len(), 1));
    let t1 = samples.last().map_or(1.0, time);
    let range = |f: &dyn Fn(&T) -> f64| {
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
    for (area, (y_desc, series)) in areas.iter().zip(panels) {
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
            .y_desc(*y_desc)
            .label_style(("sans-serif", 14))
            .draw()
            .map_err(e)?;
        for (name, color, f) in series.iter() {
            let color = *color;
            chart
                .draw_series(LineSeries::new(
                    samples.iter().map(|s| (time(s), f(s))),
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
    }
    root.present().map_err(e)
}

/// The accuracy study as a PNG: error against cost, one line per method,
/// a panel per scene.
pub fn accuracy_png(cells: &[crate::study::accuracy::Cell], out: &Path) -> Result<(), Error> {
    let _ =
        plotters::style::register_font("sans-serif", FontStyle::Normal, dejavu::sans::regular());
    let root = BitMapBackend::new(out, (1200, 560)).into_drawing_area();
    let e = |e: DrawingAreaErrorKind<_>| Error::Output(format!("{}: {e}", out.display()));
    root.fill(&WHITE).map_err(e)?;
    let root = root
        .titled(
            "What accuracy costs: max handle error vs wall time, per integrator",
            ("sans-serif", 20),
        )
        .map_err(e)?;
    let mut scenes: Vec<&str> = cells.iter().map(|c| c.scene.as_str()).collect();
    scenes.dedup();
    let panels = root.split_evenly((1, scenes.len().max(1)));
    let colors = [
        RGBColor(31, 90, 180),
        RGBColor(190, 40, 40),
        RGBColor(20, 140, 60),
        RGBColor(150, 90, 20),
    ];
    for (panel, scene) in panels.iter().zip(&scenes) {
        let mine: Vec<_> = cells
            .iter()
            .filter(|c| c.scene == *scene && c.error.is_some_and(|x| x > 0.0))
            .collect();
        if mine.is_empty() {
            continue;
        }
        let (x0, x1) = mine.iter().fold((f64::INFINITY, 0.0f64), |(a, b), c| {
            (a.min(c.ns_per_sim_ms), b.max(c.ns_per_sim_ms))
        });
        let (y0, y1) = mine
            .iter()
            .filter_map(|c| c.error)
            .fold((f64::INFINITY, 0.0f64), |(a, b), v| (a.min(v), b.max(v)));
        let mut chart = ChartBuilder::on(panel)
            .caption(*scene, ("sans-serif", 14))
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(70)
            .build_cartesian_2d(
                (x0 / 1.5..x1 * 1.5).log_scale(),
                (y0 / 3.0..y1 * 3.0).log_scale(),
            )
            .map_err(e)?;
        chart
            .configure_mesh()
            .x_desc("ns per simulated ms")
            .y_desc("max error / peak")
            .x_label_formatter(&|v| format!("{v:.0e}"))
            .y_label_formatter(&|v| format!("{v:.0e}"))
            .label_style(("sans-serif", 12))
            .draw()
            .map_err(e)?;
        let mut methods: Vec<&str> = mine.iter().map(|c| c.method.as_str()).collect();
        methods.sort();
        methods.dedup();
        // One colour per method; the f32 controller solid, f64 thin.
        for (i, m) in methods.iter().enumerate() {
            for (controller, width) in [("f32", 2), ("f64", 1)] {
                let color = colors[i % colors.len()];
                let pts: Vec<(f64, f64)> = mine
                    .iter()
                    .filter(|c| c.method == *m && c.controller == controller)
                    .filter_map(|c| Some((c.ns_per_sim_ms, c.error?)))
                    .collect();
                if pts.is_empty() {
                    continue;
                }
                chart
                    .draw_series(LineSeries::new(pts.clone(), color.stroke_width(width)))
                    .map_err(e)?
                    .label(format!("{m} ({controller})"))
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(width))
                    });
                chart
                    .draw_series(pts.iter().map(|p| Circle::new(*p, 3, color.filled())))
                    .map_err(e)?;
            }
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 12))
            .draw()
            .map_err(e)?;
    }
    root.present().map_err(e)
}
