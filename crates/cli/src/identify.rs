//! `twoport identify`: experiment records, one an axis, to each axis's
//! model file, the set of models that spans what its fit does not know,
//! and the figures of the fit; and two device files over the axes: the
//! fits (`device.toml`) and the sets, each model of an axis's set a pose
//! (`set.toml`).

use crate::args::{IdentifyArgs, PlotFormat};
use serde::Serialize;
use std::fmt;
use std::path::{Path, PathBuf};
use twoport_design::plot;
use twoport_identify::fit::{self, chain::ModelBase, uncertainty, Fit, Form, Measured};
use twoport_identify::log::{Excitation, Log};

pub(crate) fn identify(a: &IdentifyArgs) -> Result<IdentifyReport, String> {
    let positive = |name: &str, v: f64| {
        (v.is_finite() && v > 0.0)
            .then_some(v)
            .ok_or_else(|| format!("--{name} {v}: must be a finite number > 0"))
    };
    let amp = Amplifier {
        peak: positive("peak-force", a.peak_force)?,
        continuous: positive("continuous-force", a.continuous_force)?,
        pole: a
            .load_cell_pole
            .map(|p| positive("load-cell-pole", p))
            .transpose()?,
        excitation: a
            .excitation
            .as_deref()
            .map(|w| Excitation::parse(w).map_err(|e| format!("--excitation \"{w}\": {e}")))
            .transpose()?,
    };
    if !(a.sigmas.is_finite() && a.sigmas >= 0.0) {
        return Err(format!(
            "--sigmas {}: must be a finite number >= 0",
            a.sigmas
        ));
    }
    if !(0.0..1.0).contains(&a.damping_doubt) {
        return Err(format!(
            "--damping-doubt {}: must be a fraction from 0 to below 1",
            a.damping_doubt
        ));
    }
    // Each record is one axis, named by its file's stem.
    let mut names: Vec<String> = Vec::new();
    for r in &a.records {
        let name = r
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .filter(|s| !s.is_empty())
            .ok_or_else(|| format!("{}: a record needs a file name", r.display()))?;
        if names.contains(&name) {
            return Err(format!(
                "{}: two records name the axis {name:?}; each record's file name names its axis",
                r.display()
            ));
        }
        names.push(name);
    }
    let loaded = loaded_records(a, &names)?;
    let device = a
        .name
        .clone()
        .unwrap_or_else(|| format!("identified from {}", names.join(", ")));
    let axes = a
        .records
        .iter()
        .zip(&names)
        .map(|(r, name)| {
            let with = loaded
                .iter()
                .find(|l| &l.0 == name)
                .map(|l| (l.1.as_path(), l.2));
            axis(a, &amp, r, with, name, &device)
        })
        .collect::<Result<Vec<_>, _>>()?;

    let file = |what: &str, models: &dyn Fn(&Axis) -> Vec<String>| {
        let mut t = format!("# {what}\nname = {device:?}\n");
        for x in &axes {
            let list: Vec<String> = models(x).iter().map(|m| format!("  {m:?},")).collect();
            t += &format!(
                "\n[[axis]]\nname = {:?}\nmodels = [\n{}\n]\n",
                x.report.axis,
                list.join("\n")
            );
        }
        t
    };
    let device_path = write_file(
        a.out.join("device.toml"),
        file(
            "The fitted model of each axis, as `twoport identify` found it.",
            &|x| vec![format!("{}/model.toml", x.report.axis)],
        ),
    )?;
    let set_path = write_file(
        a.out.join("set.toml"),
        file(
            "Each axis's set of models, spanning what its fit does not know:\n# a design for this device file is proven for every one of them.",
            &|x| x.members.clone(),
        ),
    )?;
    // The files written read back as the device they describe.
    for p in [&device_path, &set_path] {
        twoport_design::Device::load(p).map_err(|e| e.to_string())?;
    }
    Ok(IdentifyReport {
        device: device_path,
        set: set_path,
        sigmas: a.sigmas,
        damping_doubt: a.damping_doubt,
        axes: axes.into_iter().map(|x| x.report).collect(),
    })
}

/// What `identify` wrote, and each axis's fit.
#[derive(Serialize)]
pub(crate) struct IdentifyReport {
    /// The device file of every axis's fit.
    device: PathBuf,
    /// The device file of every axis's set.
    set: PathBuf,
    /// How far the set reaches along each direction (standard deviations).
    sigmas: f64,
    /// The fraction by which the set's damping is lowered.
    damping_doubt: f64,
    axes: Vec<AxisReport>,
}

impl fmt::Display for IdentifyReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for x in &self.axes {
            writeln!(f, "axis {}:\n{x}", x.axis)?;
        }
        write!(
            f,
            "wrote {} (each axis's fit) and {} (each axis's set: +-{} sigma, damping lowered by {}%)\n\
             prove a coupling for all of them: twoport design impedance --device {}",
            self.device.display(),
            self.set.display(),
            self.sigmas,
            100.0 * self.damping_doubt,
            self.set.display()
        )
    }
}

/// Write `text` to `path`, an error naming the file.
fn write_file(path: PathBuf, text: String) -> Result<PathBuf, String> {
    std::fs::write(&path, text).map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(path)
}

/// What no experiment measures, the same for every axis.
struct Amplifier {
    peak: f64,
    continuous: f64,
    pole: Option<f64>,
    /// What the records played, where `--excitation` says it.
    excitation: Option<Excitation>,
}

/// One axis identified: its report, and its set's files (relative to the
/// output folder).
struct Axis {
    report: AxisReport,
    members: Vec<String>,
}

/// `--loaded AXIS=PATH` read as (axis, record, added mass), each axis one
/// of the records' and named once; `--added-mass` given exactly when they
/// are.
fn loaded_records(
    a: &IdentifyArgs,
    names: &[String],
) -> Result<Vec<(String, PathBuf, f64)>, String> {
    let mass = match (a.added_mass, a.loaded.is_empty()) {
        (None, true) => return Ok(Vec::new()),
        (Some(m), true) => {
            return Err(format!(
                "--added-mass {m}: it is the mass on the handle in the --loaded records; give them"
            ))
        }
        (None, false) => {
            return Err(
                "--loaded: give the mass clamped on the handle with --added-mass (kg)".into(),
            )
        }
        (Some(m), false) if !(m.is_finite() && m > 0.0) => {
            return Err(format!("--added-mass {m}: must be a finite number > 0"))
        }
        (Some(m), false) => m,
    };
    let mut out: Vec<(String, PathBuf, f64)> = Vec::new();
    for l in &a.loaded {
        let (axis, path) = l
            .split_once('=')
            .filter(|(x, p)| !x.is_empty() && !p.is_empty())
            .ok_or_else(|| format!("--loaded {l}: give it as AXIS=PATH (x=x-loaded.csv)"))?;
        if !names.iter().any(|n| n == axis) {
            return Err(format!(
                "--loaded {l}: no record names the axis {axis:?} (the records name {})",
                names.join(", ")
            ));
        }
        if out.iter().any(|o| o.0 == axis) {
            return Err(format!(
                "--loaded {l}: the axis {axis:?} has a loaded record already"
            ));
        }
        out.push((axis.to_string(), PathBuf::from(path), mass));
    }
    Ok(out)
}

/// A record read and checked against the amplifier's peak.
fn read_record(record: &Path, amp: &Amplifier) -> Result<(Log, String), String> {
    let text = std::fs::read_to_string(record).map_err(|e| format!("{}: {e}", record.display()))?;
    let source = record.display().to_string();
    let mut log = Log::from_csv(&text, &source).map_err(|e| e.to_string())?;
    match (log.excitation, amp.excitation) {
        (Some(own), Some(given)) if own != given => {
            return Err(format!(
                "{source}: the record says it played \"{}\", --excitation \"{}\"; give one",
                own.words(),
                given.words()
            ))
        }
        (None, Some(given)) => log.excitation = Some(given),
        _ => {}
    }
    let most = log.force_n.iter().fold(0.0_f64, |m, f| m.max(f.abs()));
    if most > amp.peak {
        return Err(format!(
            "{source}: the force reaches {most:.4} N, past --peak-force {} N; give the amplifier's peak",
            amp.peak
        ));
    }
    Ok((log, source))
}

/// Identify the axis `name` from `record` (and `loaded`, the same
/// experiment with a mass in kg on the handle), writing its model, its set
/// and its figures under the output folder's `name/`.
fn axis(
    a: &IdentifyArgs,
    amp: &Amplifier,
    record: &Path,
    loaded: Option<(&Path, f64)>,
    name: &str,
    device: &str,
) -> Result<Axis, String> {
    let (log, source) = read_record(record, amp)?;
    let pole = match (&log.load_cell_n, amp.pole) {
        (Some(_), None) => {
            return Err(format!(
                "{source}: the record has a load cell (load_cell_n); give its filter pole with --load-cell-pole (rad/s)"
            ))
        }
        (None, Some(_)) if a.records.len() == 1 => {
            return Err(format!(
                "--load-cell-pole: {source} has no load_cell_n column"
            ))
        }
        (lc, p) => p.filter(|_| lc.is_some()),
    };
    let mut data = Measured::from_log(&log, a.skip).map_err(|e| format!("{source}: {e}"))?;
    data.band_reaches(log.period_s)
        .map_err(|e| format!("{source}: {e}"))?;
    let mut sources = source.clone();
    if let Some((path, kg)) = loaded {
        let (l, src) = read_record(path, amp)?;
        if l.period_s != log.period_s {
            return Err(format!(
                "{src}: sampled every {} s, the bare record {source} every {} s: play the same experiment",
                l.period_s, log.period_s
            ));
        }
        let ld = Measured::from_log(&l, a.skip).map_err(|e| format!("{src}: {e}"))?;
        data = data
            .with_loaded(kg, ld)
            .map_err(|e| format!("{src}: {e}"))?;
        sources = format!("{source} and {src} ({kg} kg on the handle)");
    }
    let source = sources;
    let base = ModelBase {
        name: format!("{device}, axis {name}"),
        period_s: log.period_s,
        peak_force_n: amp.peak,
        continuous_force_n: amp.continuous,
        load_cell_pole_rad_s: pole,
    };
    let (fits, best) = fit::fit_orders(&data, &base);
    let chosen = fit::chosen(&fits, best).map_err(|e| format!("{source}: {e}"))?;
    let doubt = uncertainty::Doubt {
        sigmas: a.sigmas,
        damping: a.damping_doubt,
    };
    let set = uncertainty::span(chosen, doubt)
        .ok_or_else(|| format!("{source}: the fit's covariance is not finite"))?;

    let dir = a.out.join(name);
    std::fs::create_dir_all(dir.join("set")).map_err(|e| format!("{}: {e}", dir.display()))?;
    let header = provenance(&source, chosen);
    let model_path = write_file(dir.join("model.toml"), chosen.model.to_toml(&header))?;
    let mut members = Vec::new();
    for (i, m) in set.iter().enumerate() {
        let what = match m.direction {
            None => "the fit".to_string(),
            Some(d) => format!("direction {d}, {:+} sigma (step {:.2e})", m.sigmas, m.step),
        };
        let note = format!(
            "{header}\nMember {i} of the set: {what}; damping lowered by {}%.",
            100.0 * doubt.damping
        );
        let file = format!("{i:02}.toml");
        let mut model = m.model.clone();
        model.name = format!("{} [set {i:02}]", base.name);
        write_file(dir.join("set").join(&file), model.to_toml(&note))?;
        members.push(format!("{name}/set/{file}"));
    }
    let figures = match a.plot {
        Some(format) => draw(&dir, format, &data, chosen)?,
        None => Vec::new(),
    };
    let report = AxisReport::new(
        name, source, &log, &data, &fits, best, &set, model_path, figures,
    );
    Ok(Axis { report, members })
}

/// The longest run of harmonics in a row whose coherence is below a half,
/// from its first to its last (Hz); `None` for a run of fewer than three.
fn weak_band(freq_hz: &[f64], coherence: &[f64]) -> Option<[f64; 2]> {
    let mut best: Option<(usize, usize)> = None;
    let mut start = None;
    for (i, c) in coherence.iter().chain([&1.0]).enumerate() {
        match (*c < 0.5, start) {
            (true, None) => start = Some(i),
            (false, Some(s)) => {
                if best.is_none_or(|(a, b)| i - s > b - a) {
                    best = Some((s, i));
                }
                start = None;
            }
            _ => {}
        }
    }
    best.filter(|(a, b)| b - a >= 3)
        .map(|(a, b)| [freq_hz[a], freq_hz[b - 1]])
}

/// The header of every model file written: where it came from.
fn provenance(source: &str, f: &Fit) -> String {
    let form = match &f.form {
        Form::Chain(c) if c.ground.is_some() => "a chain of masses held to the frame by a spring",
        Form::Chain(_) => "a chain of masses",
        Form::Modal(m) if m.bypass_npm.is_some() => {
            "modes, the handle on its load cell and a bypass spring"
        }
        Form::Modal(_) => "modes, the handle on its load cell",
    };
    format!(
        "Identified by `twoport identify` from {source}:\n{} modes, {form}; chi2/nu {:.3}.",
        f.form.modes(),
        f.reduced_chi2()
    )
}

/// One axis's fit: the record, the orders tried, the model chosen and
/// what was written.
#[derive(Serialize)]
struct AxisReport {
    axis: String,
    record: String,
    samples: usize,
    period_s: f64,
    /// The lowest and highest harmonic read.
    harmonics_hz: [Option<f64>; 2],
    periods_averaged: usize,
    /// The encoder's least coherence over the harmonics, and where.
    coherence_min: f64,
    coherence_min_hz: Option<f64>,
    /// Harmonics whose coherence is below a half: the noise, or the
    /// encoder's quantum, as large as the response there. Each counts by
    /// its variance, so they weigh little; they are not dropped.
    weak_harmonics: usize,
    /// The longest band of such harmonics in a row (Hz), if any: where the
    /// coherence collapses.
    weak_band_hz: Option<[f64; 2]>,
    orders: Vec<Order>,
    chosen: Chosen,
    coulomb_friction_n: Option<f64>,
    cogging_n: Option<f64>,
    cogging_period_m: Option<f64>,
    encoder_quantum_m: Option<f64>,
    /// The model file written.
    model: PathBuf,
    set_models: usize,
    set_directions: usize,
    figures: Vec<PathBuf>,
}

/// One order fitted.
#[derive(Serialize)]
struct Order {
    modes: usize,
    /// Fitted with the loaded record too.
    loaded: bool,
    chi2_per_dof: f64,
    bic: f64,
    chosen: bool,
}

/// The model chosen.
#[derive(Serialize)]
struct Chosen {
    /// "chain" or "modal".
    form: &'static str,
    modes: usize,
    /// Resonances below Nyquist and their damping ratios.
    resonances_hz: Vec<f64>,
    damping_ratios: Vec<f64>,
    chi2_per_dof: f64,
    /// What the handle weighs past the load cell (modal form).
    handle_kg: Option<f64>,
    /// The spring that holds the handle beside the load cell, if any.
    bypass_npm: Option<f64>,
    /// A chain's spring to the frame: the mass it holds (0 the
    /// actuator's), and its stiffness.
    ground_at: Option<usize>,
    ground_npm: Option<f64>,
}

impl AxisReport {
    #[allow(clippy::too_many_arguments)]
    fn new(
        axis: &str,
        record: String,
        log: &Log,
        data: &Measured,
        fits: &[Fit],
        best: Option<usize>,
        set: &[uncertainty::Member],
        model: PathBuf,
        figures: Vec<PathBuf>,
    ) -> Self {
        let f = &fits[best.unwrap_or(0)];
        let x = &data.position;
        let (worst_at, worst) = x
            .coherence()
            .iter()
            .enumerate()
            .fold((0, 1.0_f64), |b, (i, c)| if *c < b.1 { (i, *c) } else { b });
        let res = f.resonances();
        let handle = match &f.form {
            Form::Modal(m) => Some((m.handle_kg, m.bypass_npm)),
            Form::Chain(_) => None,
        };
        let ground = match &f.form {
            Form::Chain(c) => c.ground,
            Form::Modal(_) => None,
        };
        AxisReport {
            axis: axis.to_string(),
            record,
            samples: log.force_n.len(),
            period_s: log.period_s,
            harmonics_hz: [x.freq_hz.first().copied(), x.freq_hz.last().copied()],
            periods_averaged: x.periods,
            coherence_min: worst,
            coherence_min_hz: x.freq_hz.get(worst_at).copied(),
            weak_harmonics: x.coherence().iter().filter(|c| **c < 0.5).count(),
            weak_band_hz: weak_band(&x.freq_hz, &x.coherence()),
            orders: fits
                .iter()
                .enumerate()
                .map(|(i, g)| Order {
                    modes: g.form.modes(),
                    loaded: g.loaded,
                    chi2_per_dof: g.reduced_chi2(),
                    bic: g.bic,
                    chosen: Some(i) == best,
                })
                .collect(),
            chosen: Chosen {
                form: match f.form {
                    Form::Chain(_) => "chain",
                    Form::Modal(_) => "modal",
                },
                modes: f.form.modes(),
                resonances_hz: res.iter().map(|r| r.0).collect(),
                damping_ratios: res.iter().map(|r| r.1).collect(),
                chi2_per_dof: f.reduced_chi2(),
                handle_kg: handle.map(|h| h.0),
                bypass_npm: handle.and_then(|h| h.1),
                ground_at: ground.map(|g| g.at),
                ground_npm: ground.map(|g| g.npm),
            },
            coulomb_friction_n: f.model.coulomb_friction_n,
            cogging_n: f.cogging.map(|c| c.amplitude_n),
            cogging_period_m: f.cogging.map(|c| c.period_m),
            encoder_quantum_m: f.model.encoder_quantum_m,
            model,
            set_models: set.len(),
            set_directions: set
                .iter()
                .filter_map(|m| m.direction)
                .max()
                .map_or(0, |d| d + 1),
            figures,
        }
    }
}

impl fmt::Display for AxisReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let [lo, hi] = self.harmonics_hz.map(|h| h.unwrap_or(0.0));
        writeln!(
            f,
            "  record {}: {} samples at {:.0} Hz, harmonics {lo:.3} to {hi:.3} Hz, {} periods (or blocks of a step) averaged",
            self.record,
            self.samples,
            1.0 / self.period_s,
            self.periods_averaged
        )?;
        writeln!(
            f,
            "  coherence (encoder): lowest {:.3} at {:.3} Hz",
            self.coherence_min,
            self.coherence_min_hz.unwrap_or(0.0)
        )?;
        if self.weak_harmonics > 0 {
            writeln!(
                f,
                "  {} harmonics have a coherence below 0.5 (the noise or the encoder's quantum as large as the response): each is weighed by its variance, so they count for little",
                self.weak_harmonics
            )?;
        }
        if let Some([lo, hi]) = self.weak_band_hz {
            writeln!(
                f,
                "  the coherence collapses from {lo:.3} to {hi:.3} Hz: a larger excitation there, or more periods, would show the device in that band"
            )?;
        }
        writeln!(f, "  orders fitted (modes: chi2/nu, BIC):")?;
        for g in &self.orders {
            let mark = if g.chosen { "  <- chosen" } else { "" };
            let both = if g.loaded {
                " (with the loaded record)"
            } else {
                ""
            };
            writeln!(
                f,
                "    {}{both}: {:.3}, {:.1}{mark}",
                g.modes, g.chi2_per_dof, g.bic
            )?;
        }
        let c = &self.chosen;
        writeln!(f, "  model ({}), resonances below Nyquist:", c.form)?;
        for (hz, zeta) in c.resonances_hz.iter().zip(&c.damping_ratios) {
            writeln!(f, "    {hz:9.3} Hz  damping ratio {zeta:.4}")?;
        }
        if let (Some(at), Some(k)) = (c.ground_at, c.ground_npm) {
            writeln!(
                f,
                "  held to the frame by {k:.1} N/m at mass {at} of the chain (0 the actuator's)"
            )?;
        }
        if let Some(kg) = c.handle_kg {
            write!(f, "  handle past the load cell {kg:.4} kg")?;
            match c.bypass_npm {
                Some(b) => writeln!(f, ", held beside it by {b:.1} N/m to the actuator")?,
                None => writeln!(f)?,
            }
        }
        if let Some(c) = self.coulomb_friction_n {
            writeln!(f, "  Coulomb friction {c:.4} N")?;
        }
        if let (Some(a), Some(p)) = (self.cogging_n, self.cogging_period_m) {
            writeln!(
                f,
                "  cogging {a:.4} N every {:.4} mm of the actuator's travel",
                p * 1e3
            )?;
        }
        if let Some(q) = self.encoder_quantum_m {
            writeln!(f, "  encoder quantum {:.4} um", q * 1e6)?;
        }
        writeln!(f, "  wrote {}", self.model.display())?;
        write!(
            f,
            "  its set: {} models, along {} principal directions",
            self.set_models, self.set_directions
        )?;
        for p in &self.figures {
            write!(f, "\n  wrote {}", p.display())?;
        }
        Ok(())
    }
}

/// The fit's figures (`twoport_identify::figures`), drawn into `out`.
fn draw(out: &Path, format: PlotFormat, data: &Measured, f: &Fit) -> Result<Vec<PathBuf>, String> {
    let ext = match format {
        PlotFormat::Png => "png",
        PlotFormat::Svg => "svg",
    };
    let figures = twoport_identify::figures::figures(data, f)
        .ok_or("the fitted model has no finite response")?;
    let mut written = Vec::new();
    for (name, fig) in figures {
        let path = out.join(format!("{name}.{ext}"));
        plot::render(&fig, &path).map_err(|e| e.to_string())?;
        written.push(path);
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::weak_band;

    /// The longest run of weak harmonics is named, first to last; short
    /// runs and a record with none are not.
    #[test]
    fn the_band_where_the_coherence_collapses_is_named() {
        let f: Vec<f64> = (1..=12).map(f64::from).collect();
        let c = [0.9, 0.4, 0.3, 0.9, 0.2, 0.1, 0.3, 0.4, 0.9, 0.1, 0.2, 0.3];
        assert_eq!(weak_band(&f, &c), Some([5.0, 8.0]));
        let mut tail = c;
        tail[8] = 0.1;
        assert_eq!(weak_band(&f, &tail), Some([5.0, 12.0]));
        assert_eq!(weak_band(&f, &[0.9; 12]), None);
        assert_eq!(weak_band(&f[..3], &[0.9, 0.1, 0.1]), None);
    }
}
