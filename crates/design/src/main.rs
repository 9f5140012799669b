//! `twoport`: design and check virtual couplings for a haptic device.

use clap::{Args, Parser, Subcommand, ValueEnum};
use serde_json::{json, Value};
use std::cell::RefCell;
use std::f64::consts::PI;
use std::path::PathBuf;
use std::process::ExitCode;
use std::rc::Rc;
use twoport_control::ZTransfer;
use twoport_design::design::{self, Analysis, GridSpec};
use twoport_design::twoport::HumanBound;
use twoport_design::{figures, plot, Device, DeviceModel, Plant};

const DEFAULT_MODEL: &str = twoport_design::model::EXCALIBUR_PATH;

/// Design haptic interfaces that are stable by construction: two-port
/// analysis, Llewellyn's absolute-stability criteria and virtual-coupling
/// synthesis after Adams & Hannaford (2002).
#[derive(Parser)]
#[command(name = "twoport", version, propagate_version = true)]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(Args, Clone)]
struct Common {
    /// Device model file (TOML). The default is the paper's Excalibur.
    /// Give it more than once for a device with several poses: a design
    /// is then proven for all of them.
    #[arg(long, default_value = DEFAULT_MODEL, action = clap::ArgAction::Append)]
    model: Vec<PathBuf>,
    /// Device file (TOML): a device of several axes, each with its own
    /// model (or poses). The command runs on every axis, and its JSON is
    /// one object with an entry per axis. In place of --model.
    #[arg(long, conflicts_with = "model")]
    device: Option<PathBuf>,
    /// The axis of a device file this run is for (set by `each_axis`).
    #[arg(skip)]
    axis: Option<AxisRun>,
    /// Sample period (s); the model's by default.
    #[arg(long, allow_negative_numbers = true)]
    period: Option<f64>,
    /// Leave out the human bound Z_max = 300 + 1000/s (any passive human).
    #[arg(long)]
    no_human: bool,
    /// Print one JSON object on stdout.
    #[arg(long)]
    json: bool,
}

#[derive(Subcommand)]
enum Cmd {
    /// Synthesise a virtual coupling.
    #[command(subcommand)]
    Design(Display<DesignImpedance, DesignAdmittance>),
    /// Check a coupling for absolute stability (Llewellyn).
    #[command(subcommand)]
    Check(Display<ImpedanceGains, AdmittanceGains>),
    /// Impedance range (Z_min, Z_max) over frequency, 0.1 Hz to Nyquist.
    #[command(subcommand)]
    Zrange(Display<ZrangeImpedance, ZrangeAdmittance>),
    /// Draw one of the paper's figures from this designer's results.
    Plot(PlotArgs),
    /// The proven region a board ships with: the limit for each damping.
    #[command(subcommand)]
    Region(Display<RegionImpedance, RegionAdmittance>),
    /// Search for a passive hand and VE that make the exact sampled loop
    /// unstable at these gains (independent of the two-port proof).
    #[command(subcommand)]
    Verify(Display<ImpedanceGains, AdmittanceGains>),
}

#[derive(Args, Clone)]
struct RegionGrid {
    /// Smallest coupling damping (N s/m).
    #[arg(long, default_value_t = 10.0)]
    b_from: f64,
    /// Largest coupling damping (N s/m).
    #[arg(long, default_value_t = 1000.0)]
    b_to: f64,
    /// Grid points (log-spaced).
    #[arg(long, default_value_t = 32)]
    points: usize,
    /// Print Rust source for a board image (twoport-board's `Region`)
    /// instead of a table.
    #[arg(long, conflicts_with = "json")]
    rust: bool,
}

#[derive(Args, Clone)]
struct RegionImpedance {
    #[command(flatten)]
    grid: RegionGrid,
    #[command(flatten)]
    common: Common,
}

#[derive(Args, Clone)]
struct RegionAdmittance {
    /// Regulator stiffness k_p (N/m) the region is proven for.
    #[arg(long, allow_negative_numbers = true)]
    kp: f64,
    /// Regulator damping b_p (N s/m).
    #[arg(long, allow_negative_numbers = true)]
    bp: f64,
    #[command(flatten)]
    grid: RegionGrid,
    #[command(flatten)]
    common: Common,
}

#[derive(Subcommand, Clone)]
enum Display<I: Args, A: Args> {
    /// Impedance display: measure motion, command force.
    Impedance(I),
    /// Admittance display: measure force, command motion.
    Admittance(A),
}

#[derive(Args, Clone)]
struct DesignImpedance {
    /// Coupling damping b_cI (N s/m); without it, the best (k, b) pair.
    #[arg(long, allow_negative_numbers = true)]
    b: Option<f64>,
    /// The recommended gain's margin below the boundary, as a fraction of
    /// the boundary's gain (a stiffness that much lower, a mass that much
    /// higher), from 0 to 0.9.
    #[arg(long, default_value_t = 0.1, allow_negative_numbers = true)]
    margin: f64,
    #[command(flatten)]
    common: Common,
}

#[derive(Args, Clone)]
struct DesignAdmittance {
    /// Regulator stiffness k_p (N/m); with --bp. Default: the impedance design (eq 30).
    #[arg(long, requires = "bp", allow_negative_numbers = true)]
    kp: Option<f64>,
    /// Regulator damping b_p (N s/m); with --kp.
    #[arg(long, requires = "kp", allow_negative_numbers = true)]
    bp: Option<f64>,
    /// Coupling damping b_cA (N s/m); without it, the best (m, b) pair.
    #[arg(long, allow_negative_numbers = true)]
    b: Option<f64>,
    /// The recommended gain's margin below the boundary, as a fraction of
    /// the boundary's gain (a stiffness that much lower, a mass that much
    /// higher), from 0 to 0.9.
    #[arg(long, default_value_t = 0.1, allow_negative_numbers = true)]
    margin: f64,
    #[command(flatten)]
    common: Common,
}

#[derive(Args, Clone)]
struct ImpedanceGains {
    /// Coupling stiffness k_cI (N/m).
    #[arg(long, allow_negative_numbers = true)]
    k: f64,
    /// Coupling damping b_cI (N s/m).
    #[arg(long, allow_negative_numbers = true)]
    b: f64,
    #[command(flatten)]
    common: Common,
}

#[derive(Args, Clone)]
struct AdmittanceGains {
    /// Regulator stiffness k_p (N/m).
    #[arg(long, allow_negative_numbers = true)]
    kp: f64,
    /// Regulator damping b_p (N s/m).
    #[arg(long, allow_negative_numbers = true)]
    bp: f64,
    /// Coupling mass m_cA (kg).
    #[arg(long, allow_negative_numbers = true)]
    m: f64,
    /// Coupling damping b_cA (N s/m).
    #[arg(long, allow_negative_numbers = true)]
    b: f64,
    #[command(flatten)]
    common: Common,
}

#[derive(Args, Clone)]
struct ZrangeImpedance {
    #[command(flatten)]
    gains: ImpedanceGains,
    /// Number of log-spaced frequencies.
    #[arg(long, default_value_t = 200)]
    points: usize,
}

#[derive(Args, Clone)]
struct ZrangeAdmittance {
    #[command(flatten)]
    gains: AdmittanceGains,
    /// Number of log-spaced frequencies.
    #[arg(long, default_value_t = 200)]
    points: usize,
}

#[derive(Clone, Copy, ValueEnum)]
enum Fig {
    /// Impedance-display design bound and coupling.
    Fig8,
    /// Admittance-display design bound and coupling.
    Fig9,
    /// Impedance range of both displays.
    Fig10,
}

#[derive(Args, Clone)]
struct PlotArgs {
    /// Which figure.
    figure: Fig,
    /// Output file, .png or .svg.
    #[arg(long)]
    out: PathBuf,
    /// Impedance-coupling damping to design at (N s/m).
    #[arg(long, default_value_t = 90.0)]
    b_impedance: f64,
    /// Admittance-coupling damping to design at (N s/m).
    #[arg(long, default_value_t = 500.0)]
    b_admittance: f64,
    #[command(flatten)]
    common: Common,
}

/// One axis of a device file, as one run of a command sees it.
#[derive(Clone, Debug)]
struct AxisRun {
    name: String,
    /// The axis's models (its poses), read once with the device file.
    models: Vec<(PathBuf, DeviceModel)>,
    /// Where a JSON run puts its object, for the device's one object.
    out: Rc<RefCell<Vec<Value>>>,
}

/// What a command's arguments share.
trait HasCommon {
    fn common(&mut self) -> &mut Common;
    /// Whether the command prints Rust source (a module per axis then,
    /// with no text heading).
    fn rust(&self) -> bool {
        false
    }
}

macro_rules! has_common {
    ($($t:ty),*) => {$(
        impl HasCommon for $t {
            fn common(&mut self) -> &mut Common {
                &mut self.common
            }
        }
    )*};
}
has_common!(
    PlotArgs,
    DesignImpedance,
    DesignAdmittance,
    ImpedanceGains,
    AdmittanceGains
);

impl HasCommon for RegionImpedance {
    fn common(&mut self) -> &mut Common {
        &mut self.common
    }
    fn rust(&self) -> bool {
        self.grid.rust
    }
}

impl HasCommon for RegionAdmittance {
    fn common(&mut self) -> &mut Common {
        &mut self.common
    }
    fn rust(&self) -> bool {
        self.grid.rust
    }
}

impl HasCommon for ZrangeImpedance {
    fn common(&mut self) -> &mut Common {
        self.gains.common()
    }
}

impl HasCommon for ZrangeAdmittance {
    fn common(&mut self) -> &mut Common {
        self.gains.common()
    }
}

impl<I: Args + HasCommon, A: Args + HasCommon> HasCommon for Display<I, A> {
    fn common(&mut self) -> &mut Common {
        match self {
            Display::Impedance(i) => i.common(),
            Display::Admittance(a) => a.common(),
        }
    }
    fn rust(&self) -> bool {
        match self {
            Display::Impedance(i) => i.rust(),
            Display::Admittance(a) => a.rust(),
        }
    }
}

/// `run` on `args`, or, given a device file, on each of its axes in turn:
/// the text under a heading per axis, the JSON as one object.
fn each_axis<A: HasCommon + Clone>(
    args: &A,
    run: fn(&A) -> Result<(), String>,
) -> Result<(), String> {
    let mut a = args.clone();
    let Some(path) = a.common().device.clone() else {
        return run(args);
    };
    let device = Device::load(&path).map_err(|e| e.to_string())?;
    let out = Rc::new(RefCell::new(Vec::new()));
    let json = a.common().json;
    for axis in &device.axes {
        let c = a.common();
        c.axis = Some(AxisRun {
            name: axis.name.clone(),
            models: axis
                .model_paths
                .iter()
                .cloned()
                .zip(axis.models.iter().cloned())
                .collect(),
            out: out.clone(),
        });
        if !json && !args.rust() {
            println!("axis {}:", axis.name);
        }
        run(&a).map_err(|e| format!("{}, axis {}: {e}", path.display(), axis.name))?;
    }
    if json {
        println!("{}", json!({"device": device.name, "axes": out.take()}));
    }
    Ok(())
}

/// One pose of the device: its model, the plant at the period, and the
/// design grid.
struct Pose {
    model: DeviceModel,
    plant: Plant,
    analysis: Analysis,
}

/// The poses a command works on.
struct Session {
    poses: Vec<Pose>,
    human: Option<HumanBound>,
    json: bool,
    axis: Option<AxisRun>,
}

impl Session {
    fn open(c: &Common) -> Result<Self, String> {
        let models = match &c.axis {
            Some(a) => a.models.clone(),
            None => {
                let mut models = Vec::with_capacity(c.model.len());
                for path in &c.model {
                    let m = DeviceModel::load_or_excalibur(path).map_err(|e| e.to_string())?;
                    models.push((path.clone(), m));
                }
                models
            }
        };
        let period = match c.period {
            Some(p) => p,
            None => {
                let (p0, m0) = &models[0];
                for (p, m) in &models[1..] {
                    if m.period_s != m0.period_s {
                        return Err(format!(
                            "{} has period_s = {} but {} has {}: poses share one board, give --period",
                            p.display(),
                            m.period_s,
                            p0.display(),
                            m0.period_s
                        ));
                    }
                }
                m0.period_s
            }
        };
        if !(period.is_finite() && period > 0.0) {
            return Err(format!(
                "--period {period}: must be a positive number of seconds"
            ));
        }
        let mut poses = Vec::with_capacity(models.len());
        for (path, model) in models {
            let plant =
                Plant::new(&model, period).map_err(|e| format!("{}: {e}", path.display()))?;
            let analysis = Analysis::new(&plant, GridSpec::DEFAULT);
            poses.push(Pose {
                model,
                plant,
                analysis,
            });
        }
        Ok(Session {
            poses,
            human: (!c.no_human).then_some(HumanBound::PAPER),
            json: c.json,
            axis: c.axis.clone(),
        })
    }

    /// The one pose of a command that takes one.
    fn single(&self, command: &str) -> Result<&Pose, String> {
        match self.poses.as_slice() {
            [p] => Ok(p),
            _ => Err(format!("{command} takes one --model")),
        }
    }

    fn period(&self) -> f64 {
        self.poses[0].plant.period_s()
    }

    /// The device's name: its model's, or its poses'.
    fn name(&self) -> String {
        match self.poses.as_slice() {
            [p] => p.model.name.clone(),
            ps => format!(
                "{} poses ({})",
                ps.len(),
                ps.iter()
                    .map(|p| p.model.name.as_str())
                    .collect::<Vec<_>>()
                    .join("; ")
            ),
        }
    }

    /// An admittance display needs a force sensor in every pose.
    fn force_sensor(&self) -> Result<(), String> {
        match self.poses.iter().find(|p| !p.model.force_sensor) {
            Some(p) => Err(no_force_sensor(&p.model)),
            None => Ok(()),
        }
    }

    fn impedance_bounds(&self, paper: bool) -> Vec<Vec<f64>> {
        self.poses
            .iter()
            .map(|p| {
                if paper {
                    p.analysis.paper_impedance_bound(self.human)
                } else {
                    p.analysis.impedance_bound(self.human)
                }
            })
            .collect()
    }

    fn admittance_bounds(&self, kp: &ZTransfer, paper: bool) -> Vec<Vec<f64>> {
        self.poses
            .iter()
            .map(|p| {
                if paper {
                    p.analysis.paper_admittance_bound(kp, self.human)
                } else {
                    p.analysis.admittance_bound(kp, self.human)
                }
            })
            .collect()
    }

    /// Each pose's analysis beside its bound.
    fn with<'a>(&'a self, bounds: &'a [Vec<f64>]) -> Vec<(&'a Analysis, &'a [f64])> {
        self.poses
            .iter()
            .zip(bounds)
            .map(|(p, b)| (&p.analysis, b.as_slice()))
            .collect()
    }

    /// The regulated device's worst pole radius over the poses.
    fn regulated_pole_radius(&self, kp: &ZTransfer) -> f64 {
        self.poses
            .iter()
            .map(|p| p.plant.regulated_pole_radius(kp))
            .fold(0.0, f64::max)
    }

    /// The check over every pose: stable where every pose is, with the
    /// least margin and the pose that has it (the paper's figures likewise).
    fn worst_check(
        &self,
        check: impl Fn(&Pose) -> Option<design::Check>,
    ) -> Option<(design::Check, &str)> {
        let mut all = Vec::with_capacity(self.poses.len());
        for p in &self.poses {
            all.push((check(p)?, p.model.name.as_str()));
        }
        let least = |key: fn(&design::Check) -> f64| {
            all.iter()
                .copied()
                .min_by(|a, b| key(&a.0).total_cmp(&key(&b.0)))
        };
        let (mut c, name) = least(|c| c.min_margin)?;
        let (paper, _) = least(|c| c.paper.min_margin)?;
        c.absolutely_stable = all.iter().all(|x| x.0.absolutely_stable);
        c.regulator_pole_radius = all
            .iter()
            .map(|x| x.0.regulator_pole_radius)
            .fold(0.0, f64::max);
        c.paper = paper.paper;
        c.paper.absolutely_stable = all.iter().all(|x| x.0.paper.absolutely_stable);
        Some((c, name))
    }

    fn human_text(&self) -> &'static str {
        if self.human.is_some() {
            "human bound Z_max = 300 + 1000/s"
        } else {
            "no human bound (any passive human)"
        }
    }

    fn header(&self, display: &str) {
        println!(
            "{display} display, {} at T = {} ms, {}",
            self.name(),
            self.period() * 1e3,
            self.human_text()
        );
    }

    fn emit(&self, mut v: Value, text: impl FnOnce()) {
        match (&self.axis, self.json) {
            (Some(a), true) => {
                v["axis"] = json!(a.name);
                a.out.borrow_mut().push(v);
            }
            (None, true) => println!("{v}"),
            (_, false) => text(),
        }
    }
}

/// Check a `--margin` before any analysis.
fn margin(v: f64) -> Result<f64, String> {
    (0.0..=0.9)
        .contains(&v)
        .then_some(v)
        .ok_or_else(|| format!("--margin {v}: must be a fraction from 0 to 0.9"))
}

/// What a design limits: the impedance display's coupling stiffness (more
/// is bolder) or the admittance display's coupling mass (less is).
#[derive(Clone, Copy)]
enum Limit {
    Stiffness,
    Mass,
}

impl Limit {
    /// `x` as published, with its unit: a stiffness rounded down (N/m), a
    /// mass up to the gram (kg), never past its proof.
    fn text(self, x: f64) -> String {
        match self {
            Limit::Stiffness => format!("{:.0} N/m", x.floor()),
            Limit::Mass => format!("{:.3} kg", (x * 1e3).ceil() / 1e3),
        }
    }

    /// The gain `margin` (a fraction) inside the boundary `x`.
    fn inside(self, x: f64, margin: f64) -> f64 {
        match self {
            Limit::Stiffness => x * (1.0 - margin),
            Limit::Mass => x / (1.0 - margin),
        }
    }
}

/// The text lines of a design `r` (limit, damping): the boundary, at the
/// asked damping (`fixed_b`) or the best pair, and the recommended gain
/// `margin` inside it; `v`'s message where there is none.
fn print_design(limit: Limit, r: Option<(f64, f64)>, fixed_b: bool, margin: f64, v: &Value) {
    let (name, most, side) = match limit {
        Limit::Stiffness => ("k_c", "greatest", "below"),
        Limit::Mass => ("m_c", "least", "above"),
    };
    match r {
        Some((x, b)) if fixed_b => println!(
            "  {most} {name} at b_c = {b} N s/m: {} (the boundary)",
            limit.text(x)
        ),
        Some((x, b)) => println!(
            "  best coupling: {name} = {}, b_c = {b:.1} N s/m (the boundary)",
            limit.text(x)
        ),
        None => println!("  infeasible: {}", v["message"].as_str().unwrap_or("")),
    }
    if let Some((x, _)) = r {
        println!(
            "  recommended: {name} = {}, {:.0}% {side} the boundary",
            limit.text(limit.inside(x, margin)),
            100.0 * margin
        );
    }
}

/// Check gains for sign and finiteness before any analysis.
fn gain(name: &str, v: f64) -> Result<f64, String> {
    (v.is_finite() && v >= 0.0)
        .then_some(v)
        .ok_or_else(|| format!("--{name} {v}: must be a finite number >= 0"))
}

fn impedance_design_on(
    s: &Session,
    bounds: &[Vec<f64>],
    b: Option<f64>,
) -> Result<Option<(f64, f64)>, String> {
    let poses = s.with(bounds);
    Ok(match b {
        Some(b) => design::max_stiffness_poses(&poses, gain("b", b)?).map(|k| (k, b)),
        None => design::best_impedance_poses(&poses),
    })
}

/// The admittance design on `bounds` for a regulator whose regulated
/// device has pole radius `radius`: none where that is unstable.
fn admittance_design_on(
    s: &Session,
    bounds: &[Vec<f64>],
    radius: f64,
    b: Option<f64>,
) -> Result<Option<(f64, f64)>, String> {
    let poses = s.with(bounds);
    Ok(if radius >= 1.0 {
        None
    } else {
        match b {
            Some(b) => design::min_mass_poses(&poses, gain("b", b)?).map(|m| (m, b)),
            None => design::best_admittance_poses(&poses),
        }
    })
}

fn impedance_design(s: &Session, b: Option<f64>) -> Result<Option<(f64, f64)>, String> {
    impedance_design_on(s, &s.impedance_bounds(false), b)
}

/// Where a design binds: the pose (when there are several) and frequency.
fn binding_pose(v: &mut Value, s: &Session, c: Option<(design::Check, &str)>) {
    if let Some((c, name)) = c {
        v["binding_frequency_hz"] = json!(c.worst_frequency_hz);
        if s.poses.len() > 1 {
            v["binding_pose"] = json!(name);
        }
    }
}

fn binding_pose_text(v: &Value) -> Option<String> {
    let f = v["binding_frequency_hz"].as_f64()?;
    Some(match v["binding_pose"].as_str() {
        Some(p) => format!("  binds at {f:.2} Hz in pose {p}"),
        None => format!("  binds at {f:.2} Hz"),
    })
}

/// The sound design `r` and the paper's `paper` as `(limit, b_c)` into `v`
/// (`key` and `paper_key`, with `b_c`), and which of the two binds.
fn designs(
    v: &mut Value,
    key: &str,
    r: Option<(f64, f64)>,
    paper: Option<(f64, f64)>,
    more_is_bolder: bool,
) {
    if let Some((l, b)) = paper {
        v[format!("paper_{key}")] = json!(l);
        v["paper_b_c"] = json!(b);
    }
    if let Some((l, b)) = r {
        v[key] = json!(l);
        v["b_c"] = json!(b);
    }
    binding(v, r.map(|r| r.0), paper.map(|p| p.0), more_is_bolder);
}

/// Which bound set a design, and by how much the paper's approximation
/// (aliasing at the handle port neglected) would have claimed more. `sound`
/// and `paper` are the designed limits; `more_is_bolder` says whether a
/// larger limit claims more (a stiffness) or less (a mass).
fn binding(v: &mut Value, sound: Option<f64>, paper: Option<f64>, more_is_bolder: bool) {
    let (text, by) = match (sound, paper) {
        (Some(s), Some(p)) => {
            let by = if more_is_bolder {
                (p - s) / p
            } else {
                (s - p) / p
            };
            if by > 1e-5 {
                ("sampled-data", by)
            } else {
                ("both", by.max(0.0))
            }
        }
        (None, Some(_)) => ("sampled-data", 1.0),
        _ => ("both", 0.0),
    };
    v["binding_bound"] = json!(text);
    v["aliasing_effect"] = json!(by);
}

fn binding_text(v: &Value, what: &str, paper: &str, unit: &str) -> String {
    let by = 100.0 * v["aliasing_effect"].as_f64().unwrap_or(0.0);
    match v[paper].as_f64() {
        Some(p) if v["binding_bound"] == "sampled-data" => format!(
            "  the sampled-data analysis binds: the paper's approximation (aliasing at the handle neglected) gives {p:.4} {unit}; the proven {what} is {by:.1}% {}", if unit == "kg" { "higher" } else { "lower" }
        ),
        Some(_) => format!("  the paper's approximation gives the same {what} (aliasing moves it by {by:.4}%)"),
        None => "  the paper's approximation finds no design either".into(),
    }
}

fn design_impedance(a: &DesignImpedance) -> Result<(), String> {
    let margin = margin(a.margin)?;
    let s = Session::open(&a.common)?;
    let r = impedance_design(&s, a.b)?;
    let paper = impedance_design_on(&s, &s.impedance_bounds(true), a.b)?;
    let mut v = json!({"display": "impedance", "feasible": r.is_some(), "period_s": s.period(), "human_model": s.human.is_some()});
    designs(&mut v, "k_c", r, paper, true);
    match r {
        Some((k, b)) => {
            let c = s.worst_check(|p| design::check_impedance(&p.analysis, k, b, s.human));
            binding_pose(&mut v, &s, c);
            v["margin"] = json!(margin);
            v["recommended_k_c"] = json!(Limit::Stiffness.inside(k, margin));
        }
        None => {
            let what = ("stiffness", "m/(N s)", design::K_RANGE, "N/m");
            v["message"] = json!(infeasible(&s, &s.impedance_bounds(false), what, a.b));
        }
    }
    s.emit(v.clone(), || {
        s.header("Impedance");
        print_design(Limit::Stiffness, r, a.b.is_some(), margin, &v);
        if let Some(t) = binding_pose_text(&v) {
            println!("{t}");
        }
        println!("{}", binding_text(&v, "stiffness", "paper_k_c", "N/m"));
    });
    Ok(())
}

/// Why no coupling `what` (its bound's unit, its search range and unit)
/// meets `bounds`: the limit toward DC, or the range searched.
fn infeasible(
    s: &Session,
    bounds: &[Vec<f64>],
    (what, bound_unit, (lo, hi), unit): (&str, &str, (f64, f64), &str),
    b: Option<f64>,
) -> String {
    let at = b
        .map(|b| format!(" at b_c = {b} N s/m"))
        .unwrap_or_default();
    match s
        .with(bounds)
        .iter()
        .find_map(|(a, b)| design::low_frequency_obstacle(a, b))
    {
        Some(limit) => format!(
            "no finite coupling {what} is absolutely stable: toward DC the bound stays positive (its limit is {limit:.4e} {bound_unit}), while the coupling's real part goes to zero as the frequency does"
        ),
        None => format!("no coupling {what} from {lo} to {hi} {unit} meets the bound{at}"),
    }
}

/// Why an admittance display cannot be built for `model`.
fn no_force_sensor(model: &DeviceModel) -> String {
    format!(
        "{}: the model has no force sensor (no C_f), and an admittance display needs one to measure the hand's force; design an impedance display instead",
        model.name
    )
}

fn design_admittance(a: &DesignAdmittance) -> Result<(), String> {
    let margin = margin(a.margin)?;
    let s = Session::open(&a.common)?;
    s.force_sensor()?;
    let (kp, bp) = match (a.kp, a.bp) {
        (Some(kp), Some(bp)) => (gain("kp", kp)?, gain("bp", bp)?),
        _ => impedance_design(&s, None)?
            .ok_or("no impedance design exists to take K_p from (eq 30); give --kp and --bp")?,
    };
    let k = design::regulator_tf(kp, bp, s.period()).map_err(|e| e.to_string())?;
    let radius = s.regulated_pole_radius(&k);
    let r = admittance_design_on(&s, &s.admittance_bounds(&k, false), radius, a.b)?;
    let paper = admittance_design_on(&s, &s.admittance_bounds(&k, true), radius, a.b)?;
    let mut v = json!({"display": "admittance", "feasible": r.is_some(), "kp": kp, "bp": bp,
        "period_s": s.period(), "human_model": s.human.is_some(), "regulator_pole_radius": radius});
    designs(&mut v, "m_c", r, paper, false);
    match r {
        Some((m, b)) => {
            let c = s.worst_check(|p| {
                design::check_admittance(&p.plant, &p.analysis, (kp, bp), (m, b), s.human)
            });
            binding_pose(&mut v, &s, c);
            v["margin"] = json!(margin);
            v["recommended_m_c"] = json!(Limit::Mass.inside(m, margin));
        }
        None if radius >= 1.0 => {
            v["message"] = json!(format!(
                "the regulator k_p = {kp}, b_p = {bp} does not stabilise the device (pole radius {radius:.4})"
            ))
        }
        None => {
            let what = ("mass", "N s/m", design::M_RANGE, "kg");
            v["message"] = json!(infeasible(&s, &s.admittance_bounds(&k, false), what, a.b));
        }
    }
    s.emit(v.clone(), || {
        s.header("Admittance");
        println!(
            "  position regulator K_p = {kp:.0} + {bp:.1} (1 - 1/z)/T (pole radius {radius:.4})"
        );
        print_design(Limit::Mass, r, a.b.is_some(), margin, &v);
        if let Some(t) = binding_pose_text(&v) {
            println!("{t}");
        }
        println!("{}", binding_text(&v, "mass", "paper_m_c", "kg"));
    });
    Ok(())
}

fn check_json(c: &design::Check) -> Value {
    let p = &c.paper;
    let binding = if c.sampled_binds() {
        "sampled-data"
    } else {
        "both"
    };
    json!({"absolutely_stable": c.absolutely_stable, "min_margin": c.min_margin,
        "worst_frequency_hz": c.worst_frequency_hz, "binding_bound": binding,
        "paper_absolutely_stable": p.absolutely_stable, "paper_min_margin": p.min_margin,
        "paper_worst_frequency_hz": p.worst_frequency_hz})
}

fn print_check(c: &design::Check) {
    let verdict = |ok| {
        if ok {
            "absolutely stable (proven)"
        } else {
            "NOT proven absolutely stable"
        }
    };
    println!(
        "  {}: least margin {:.4} at {:.2} Hz (sampled-data analysis)",
        verdict(c.absolutely_stable),
        c.min_margin,
        c.worst_frequency_hz
    );
    let p = &c.paper;
    if c.sampled_binds() {
        println!(
            "  the paper's approximation (aliasing at the handle neglected) would say {}: margin {:.4} at {:.2} Hz",
            verdict(p.absolutely_stable),
            p.min_margin,
            p.worst_frequency_hz
        );
    }
}

/// The gain margin line of `check`: how far inside (or past) the boundary
/// `boundary` at the same damping the gains are.
fn print_gain_margin(margin: Option<f64>, boundary: Option<String>) {
    match (margin, boundary) {
        (Some(g), Some(b)) if g >= 0.0 => println!(
            "  gain margin {:.2}%: the boundary at this damping is {b}",
            100.0 * g
        ),
        (Some(g), Some(b)) => println!(
            "  {:.2}% past the boundary at this damping, {b}",
            -100.0 * g
        ),
        _ => println!("  nothing is proven at this damping"),
    }
}

fn check(d: &Display<ImpedanceGains, AdmittanceGains>) -> Result<(), String> {
    match d {
        Display::Impedance(g) => {
            let s = Session::open(&g.common)?;
            let (k, b) = (gain("k", g.k)?, gain("b", g.b)?);
            let (c, pose) = s
                .worst_check(|p| design::check_impedance(&p.analysis, k, b, s.human))
                .ok_or_else(|| {
                    format!("--k {k} --b {b}: not a valid coupling (k T + b must be > 0)")
                })?;
            let mut v = check_json(&c);
            v["display"] = json!("impedance");
            if s.poses.len() > 1 {
                v["worst_pose"] = json!(pose);
            }
            // How far below the boundary at this damping: 1 - k/k_max.
            let boundary = impedance_design(&s, Some(b))?.map(|(k, _)| k);
            let gain_margin = boundary.map(|kb| 1.0 - k / kb);
            v["boundary_k_c"] = json!(boundary);
            v["gain_margin"] = json!(gain_margin);
            s.emit(v, || {
                s.header("Impedance");
                println!("  coupling k_c = {k} N/m, b_c = {b} N s/m");
                print_check(&c);
                print_gain_margin(gain_margin, boundary.map(|k| Limit::Stiffness.text(k)));
            });
        }
        Display::Admittance(g) => {
            let s = Session::open(&g.common)?;
            s.force_sensor()?;
            let kp = (gain("kp", g.kp)?, gain("bp", g.bp)?);
            let mb = (g.m, gain("b", g.b)?);
            if !(g.m.is_finite() && g.m > 0.0) {
                return Err(format!("--m {}: must be a finite mass > 0 kg", g.m));
            }
            let (c, pose) = s
                .worst_check(|p| design::check_admittance(&p.plant, &p.analysis, kp, mb, s.human))
                .ok_or("--b must be > 0 for the admittance coupling")?;
            let mut v = check_json(&c);
            v["display"] = json!("admittance");
            if s.poses.len() > 1 {
                v["worst_pose"] = json!(pose);
            }
            v["regulator_pole_radius"] = json!(c.regulator_pole_radius);
            // How far above the boundary at this damping: 1 - m_min/m.
            let k = design::regulator_tf(kp.0, kp.1, s.period()).map_err(|e| e.to_string())?;
            let bounds = s.admittance_bounds(&k, false);
            let boundary = admittance_design_on(&s, &bounds, c.regulator_pole_radius, Some(mb.1))?
                .map(|(m, _)| m);
            let gain_margin = boundary.map(|m| 1.0 - m / mb.0);
            v["boundary_m_c"] = json!(boundary);
            v["gain_margin"] = json!(gain_margin);
            s.emit(v, || {
                s.header("Admittance");
                println!("  regulator k_p = {} N/m, b_p = {} N s/m; coupling m_c = {} kg, b_c = {} N s/m", kp.0, kp.1, mb.0, mb.1);
                println!("  regulated device pole radius {:.4}", c.regulator_pole_radius);
                print_check(&c);
                print_gain_margin(gain_margin, boundary.map(|m| Limit::Mass.text(m)));
            });
        }
    }
    Ok(())
}

fn zrange(d: &Display<ZrangeImpedance, ZrangeAdmittance>) -> Result<(), String> {
    let (common, points) = match d {
        Display::Impedance(z) => (&z.gains.common, z.points),
        Display::Admittance(z) => (&z.gains.common, z.points),
    };
    if points < 2 {
        return Err(format!("--points {points}: need at least 2"));
    }
    let s = Session::open(common)?;
    let pose = s.single("zrange")?;
    let nyq = pose.plant.nyquist();
    let lo = 2.0 * PI * 0.1;
    let omegas = design::log_grid(lo, nyq, points);
    let a = Analysis::on(&pose.plant, &omegas);
    let range = match d {
        Display::Impedance(z) => {
            let (k, b) = (gain("k", z.gains.k)?, gain("b", z.gains.b)?);
            design::impedance_range_impedance(&a, k, b)
        }
        Display::Admittance(z) => {
            let g = &z.gains;
            design::impedance_range_admittance(
                &a,
                (gain("kp", g.kp)?, gain("bp", g.bp)?),
                (g.m, gain("b", g.b)?),
            )
        }
    }
    .ok_or("the gains do not make a valid coupling")?;
    let freq: Vec<f64> = omegas.iter().map(|w| w / (2.0 * PI)).collect();
    let pair = |c: num_complex::Complex64| [c.re, c.im];
    let v = json!({
        "freq_hz": freq,
        "z_min": range.iter().map(|r| pair(r.0)).collect::<Vec<_>>(),
        "z_max": range.iter().map(|r| pair(r.1)).collect::<Vec<_>>(),
    });
    s.emit(v, || {
        println!(
            "{:>12} {:>14} {:>14}",
            "freq (Hz)", "|Z_min| N s/m", "|Z_max| N s/m"
        );
        for (f, r) in freq.iter().zip(&range) {
            println!("{f:>12.3} {:>14.4e} {:>14.4e}", r.0.norm(), r.1.norm());
        }
    });
    Ok(())
}

fn plot_fig(p: &PlotArgs) -> Result<(), String> {
    let s = Session::open(&p.common)?;
    let a = &s.single("plot")?.analysis;
    let t = s.period();
    let bi = a.impedance_bound(Some(HumanBound::PAPER));
    let (k, b) = design::max_stiffness(a, &bi, gain("b-impedance", p.b_impedance)?)
        .map(|k| (k, p.b_impedance))
        .ok_or("no impedance coupling meets the bound at --b-impedance")?;
    let kp = design::regulator_tf(k, b, t).map_err(|e| e.to_string())?;
    let ba = a.admittance_bound(&kp, Some(HumanBound::PAPER));
    let m = design::min_mass(a, &ba, gain("b-admittance", p.b_admittance)?)
        .ok_or("no admittance coupling meets the bound at --b-admittance")?;
    let fig = match p.figure {
        Fig::Fig8 => figures::fig8(a, k, b),
        Fig::Fig9 => figures::fig9(a, (k, b), (m, p.b_admittance)),
        Fig::Fig10 => figures::fig10(a, (k, b), (k, b), (m, p.b_admittance)),
    }?;
    plot::render(&fig, &p.out)?;
    s.emit(
        json!({"out": p.out, "k_c": k, "b_c": b, "m_c": m, "b_cA": p.b_admittance}),
        || {
            println!(
                "wrote {} (k_c = {k:.0} N/m, b_c = {b} N s/m, m_c = {m:.3} kg, b_cA = {} N s/m)",
                p.out.display(),
                p.b_admittance
            )
        },
    );
    Ok(())
}

fn region(d: &Display<RegionImpedance, RegionAdmittance>) -> Result<(), String> {
    let (grid, common) = match d {
        Display::Impedance(r) => (&r.grid, &r.common),
        Display::Admittance(r) => (&r.grid, &r.common),
    };
    let (lo, hi) = (gain("b-from", grid.b_from)?, gain("b-to", grid.b_to)?);
    if !(lo > 0.0 && hi > lo && (2..=1000).contains(&grid.points)) {
        return Err("need 0 < --b-from < --b-to and 2..=1000 --points".into());
    }
    let s = Session::open(common)?;
    let (bound, rows, regulator) = match d {
        Display::Impedance(_) => {
            let b = s.impedance_bounds(false);
            (
                "max_stiffness_npm",
                design::region_impedance(&s.with(&b), (lo, hi), grid.points),
                None,
            )
        }
        Display::Admittance(r) => {
            s.force_sensor()?;
            let (kp, bp) = (gain("kp", r.kp)?, gain("bp", r.bp)?);
            let k = design::regulator_tf(kp, bp, s.period()).map_err(|e| e.to_string())?;
            let b = s.admittance_bounds(&k, false);
            (
                "min_mass_kg",
                design::region_admittance(&s.with(&b), (lo, hi), grid.points),
                Some((kp, bp)),
            )
        }
    };
    if grid.rust {
        let how = std::env::args().skip(1).collect::<Vec<_>>().join(" ");
        let source = design::region_rust_source(
            &rows,
            bound == "max_stiffness_npm",
            regulator,
            &format!("twoport {how}"),
        );
        match &s.axis {
            // A device file: one module per axis, for a board's regions.
            Some(a) => {
                let ident: String = a
                    .name
                    .chars()
                    .map(|c| {
                        if c.is_ascii_alphanumeric() {
                            c.to_ascii_lowercase()
                        } else {
                            '_'
                        }
                    })
                    .collect();
                println!(
                    "/// Axis {}'s proven region.\npub mod axis_{ident} {{\nuse super::*;",
                    a.name
                );
                print!("{source}");
                println!("}}");
            }
            None => print!("{source}"),
        }
        return Ok(());
    }
    let v = json!({"bound": bound, "damping_nspm": rows.iter().map(|r| r.0).collect::<Vec<_>>(),
        "limit": rows.iter().map(|r| r.1).collect::<Vec<_>>(), "regulator": regulator,
        "period_s": s.period(), "human_model": s.human.is_some()});
    s.emit(v, || {
        println!("{:>14} {:>16}", "b (N s/m)", bound);
        for (b, l) in &rows {
            println!("{b:>14.3} {l:>16.4}");
        }
    });
    Ok(())
}

fn verify(d: &Display<ImpedanceGains, AdmittanceGains>) -> Result<(), String> {
    use twoport_design::verify::{self, Gains};
    let (common, gains) = match d {
        Display::Impedance(g) => (
            &g.common,
            Gains::Impedance {
                k_npm: gain("k", g.k)?,
                b_nspm: gain("b", g.b)?,
            },
        ),
        Display::Admittance(g) => {
            if !(g.m.is_finite() && g.m > 0.0) {
                return Err(format!("--m {}: must be a finite mass > 0 kg", g.m));
            }
            (
                &g.common,
                Gains::Admittance {
                    kp_npm: gain("kp", g.kp)?,
                    bp_nspm: gain("bp", g.bp)?,
                    m_kg: g.m,
                    b_nspm: gain("b", g.b)?,
                },
            )
        }
    };
    let s = Session::open(common)?;
    if matches!(gains, Gains::Admittance { .. }) {
        s.force_sensor()?;
    }
    let (period, human) = (s.period(), s.human);
    let mut worst: Option<(verify::Verdict, &DeviceModel)> = None;
    let mut evaluations = 0;
    for p in &s.poses {
        let v = verify::verify(
            &p.model,
            period,
            &gains,
            human,
            p.model.delay_samples as usize,
        )
        .map_err(|e| format!("{}: {e}", p.model.name))?;
        evaluations += v.evaluations;
        if worst
            .as_ref()
            .is_none_or(|w| (v.unstable, v.spectral_radius) > (w.0.unstable, w.0.spectral_radius))
        {
            worst = Some((v, &p.model));
        }
    }
    let (mut v, model) = worst.ok_or("no pose to verify")?;
    v.evaluations = evaluations;
    let display = match d {
        Display::Impedance(_) => "impedance",
        Display::Admittance(_) => "admittance",
    };
    let mut out = serde_json::to_value(v).map_err(|e| e.to_string())?;
    out["display"] = json!(display);
    if s.poses.len() > 1 {
        out["worst_pose"] = json!(model.name);
    }
    out["human_model"] = json!(human.is_some());
    out["period_s"] = json!(period);
    if common.json {
        println!("{out}");
    } else {
        println!(
            "{display} display, {} at T = {} ms: {} closed loops searched",
            s.name(),
            period * 1e3,
            v.evaluations
        );
        let verdict = if v.unstable {
            "UNSTABLE: a passive termination breaks these gains"
        } else {
            "no counterexample found"
        };
        let growth = if v.growth_per_s > 0.0 {
            format!("grows by e every {:.3e} s", 1.0 / v.growth_per_s)
        } else {
            format!("decays by e every {:.3e} s", -1.0 / v.growth_per_s)
        };
        println!(
            "  {verdict}; worst spectral radius 1 {:+.3e} at {:.2} Hz ({growth})",
            v.spectral_radius - 1.0,
            v.frequency_hz
        );
        println!(
            "  worst termination: {}",
            serde_json::to_string(&v.termination).unwrap_or_default()
        );
    }
    Ok(())
}

/// `run` on `args`, refusing a device file: the command draws one axis.
fn one_axis<A: HasCommon + Clone>(
    args: &A,
    run: fn(&A) -> Result<(), String>,
) -> Result<(), String> {
    match args.clone().common().device.clone() {
        Some(p) => Err(format!(
            "--device {}: this command draws one axis; give that axis's --model",
            p.display()
        )),
        None => run(args),
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let r = match &cli.cmd {
        Cmd::Design(Display::Impedance(a)) => each_axis(a, design_impedance),
        Cmd::Design(Display::Admittance(a)) => each_axis(a, design_admittance),
        Cmd::Check(d) => each_axis(d, check),
        Cmd::Zrange(d) => one_axis(d, zrange),
        Cmd::Plot(p) => one_axis(p, plot_fig),
        Cmd::Region(d) => each_axis(d, region),
        Cmd::Verify(d) => each_axis(d, verify),
    };
    match r {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("twoport: {e}");
            ExitCode::from(2)
        }
    }
}
