//! The command line's arguments and the checks on them.

use clap::{Args, Subcommand, ValueEnum};
use std::path::PathBuf;

mod teleop;

pub(crate) use teleop::{Teleop, TeleopArgs, TeleopLaw};

pub(crate) const DEFAULT_MODEL: &str = twoport_design::model::EXCALIBUR_PATH;

#[derive(Args, Clone)]
pub(crate) struct Common {
    /// Device model file (TOML). The default is the paper's Excalibur.
    /// Give it more than once for a device with several poses: a design
    /// is then proven for all of them.
    #[arg(long, default_value = DEFAULT_MODEL, action = clap::ArgAction::Append)]
    pub(crate) model: Vec<PathBuf>,
    /// Device file (TOML): a device of several axes, each with its own
    /// model (or poses). The command runs on every axis, and its JSON is
    /// one object with an entry per axis. In place of --model.
    #[arg(long, conflicts_with = "model")]
    pub(crate) device: Option<PathBuf>,
    /// Sample period (s); the model's by default.
    #[arg(long, allow_negative_numbers = true)]
    pub(crate) period: Option<f64>,
    /// Latency from sampling the sensors to the force's change, in place of
    /// the model's `latency_s`: seconds (`50e-6`) or a fraction of the
    /// period (`0.25T`). The proof holds the force that much later.
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) latency: Option<Latency>,
    /// Leave out the human bound Z_max = 300 + 1000/s (any passive human).
    #[arg(long)]
    pub(crate) no_human: bool,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub(crate) json: bool,
}

/// A latency as the command line gives it: seconds, or periods.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Latency {
    /// Seconds.
    Seconds(f64),
    /// A number of sample periods.
    Periods(f64),
}

impl Latency {
    /// The latency (s) at sample period `period_s`.
    pub(crate) fn seconds(self, period_s: f64) -> f64 {
        match self {
            Latency::Seconds(s) => s,
            Latency::Periods(p) => p * period_s,
        }
    }
}

impl std::str::FromStr for Latency {
    type Err = String;
    fn from_str(text: &str) -> Result<Self, String> {
        let t = text.trim();
        let (number, periods) = match t.strip_suffix('T') {
            Some(n) => (n, true),
            None => (t, false),
        };
        let v: f64 = number.trim().parse().map_err(|_| {
            format!("{text:?}: a latency is seconds (50e-6) or a fraction of the period (0.25T)")
        })?;
        if !(v.is_finite() && v >= 0.0) {
            return Err(format!("{text:?}: a latency must be finite and >= 0"));
        }
        Ok(if periods {
            Latency::Periods(v)
        } else {
            Latency::Seconds(v)
        })
    }
}

#[derive(Args, Clone)]
pub(crate) struct RegionGrid {
    /// Smallest coupling damping (N s/m).
    #[arg(long, default_value_t = 10.0)]
    pub(crate) b_from: f64,
    /// Largest coupling damping (N s/m).
    #[arg(long, default_value_t = 1000.0)]
    pub(crate) b_to: f64,
    /// Grid points (log-spaced).
    #[arg(long, default_value_t = 32)]
    pub(crate) points: usize,
    /// Print Rust source for a board image (twoport-board's `Region`)
    /// instead of a table.
    #[arg(long, conflicts_with = "json")]
    pub(crate) rust: bool,
}

#[derive(Args, Clone)]
pub(crate) struct RegionImpedance {
    #[command(flatten)]
    pub(crate) grid: RegionGrid,
    #[command(flatten)]
    pub(crate) common: Common,
}

#[derive(Args, Clone)]
pub(crate) struct RegionAdmittance {
    /// Regulator stiffness k_p (N/m) the region is proven for.
    #[arg(long, allow_negative_numbers = true)]
    pub(crate) kp: f64,
    /// Regulator damping b_p (N s/m).
    #[arg(long, allow_negative_numbers = true)]
    pub(crate) bp: f64,
    #[command(flatten)]
    pub(crate) grid: RegionGrid,
    #[command(flatten)]
    pub(crate) common: Common,
}

#[derive(Subcommand, Clone)]
pub(crate) enum Display<I: Args, A: Args> {
    /// Impedance display: measure motion, command force.
    Impedance(I),
    /// Admittance display: measure force, command motion.
    Admittance(A),
}

/// `design`'s margin for the recommended gain.
#[derive(Args, Clone)]
pub(crate) struct Margin {
    /// The recommended gain's margin below the boundary, as a fraction of
    /// the boundary's gain (a stiffness that much lower, a mass that much
    /// higher), from 0 to 0.9.
    #[arg(long, default_value_t = 0.1, allow_negative_numbers = true)]
    margin: f64,
}

impl Margin {
    /// The fraction, checked before any analysis.
    pub(crate) fn fraction(&self) -> Result<f64, String> {
        let v = self.margin;
        (0.0..=0.9)
            .contains(&v)
            .then_some(v)
            .ok_or_else(|| format!("--margin {v}: must be a fraction from 0 to 0.9"))
    }
}

#[derive(Args, Clone)]
pub(crate) struct DesignImpedance {
    /// Coupling damping b_cI (N s/m); without it, the best (k, b) pair.
    #[arg(long, allow_negative_numbers = true)]
    pub(crate) b: Option<f64>,
    /// A linkage device (--device): prove for every hand that grasps with
    /// at least this damping in every direction (N s/m; a dead-man switch
    /// keeps force off without a grasp), instead of every passive hand.
    #[arg(long, allow_negative_numbers = true)]
    pub(crate) min_grasp: Option<f64>,
    #[command(flatten)]
    pub(crate) margin: Margin,
    #[command(flatten)]
    pub(crate) common: Common,
}

#[derive(Args, Clone)]
pub(crate) struct DesignAdmittance {
    /// Regulator stiffness k_p (N/m); with --bp. Default: the impedance design (eq 30).
    #[arg(long, requires = "bp", allow_negative_numbers = true)]
    pub(crate) kp: Option<f64>,
    /// Regulator damping b_p (N s/m); with --kp.
    #[arg(long, requires = "kp", allow_negative_numbers = true)]
    pub(crate) bp: Option<f64>,
    /// Coupling damping b_cA (N s/m); without it, the best (m, b) pair.
    #[arg(long, allow_negative_numbers = true)]
    pub(crate) b: Option<f64>,
    #[command(flatten)]
    pub(crate) margin: Margin,
    #[command(flatten)]
    pub(crate) common: Common,
}

#[derive(Args, Clone)]
pub(crate) struct ImpedanceGains {
    /// Coupling stiffness k_cI (N/m).
    #[arg(long, allow_negative_numbers = true)]
    pub(crate) k: f64,
    /// Coupling damping b_cI (N s/m).
    #[arg(long, allow_negative_numbers = true)]
    pub(crate) b: f64,
    /// A linkage device (--device, `verify` only): every hand grasps with
    /// at least this damping in every direction (N s/m).
    #[arg(long, allow_negative_numbers = true)]
    pub(crate) min_grasp: Option<f64>,
    #[command(flatten)]
    pub(crate) common: Common,
}

#[derive(Args, Clone)]
pub(crate) struct AdmittanceGains {
    /// Regulator stiffness k_p (N/m).
    #[arg(long, allow_negative_numbers = true)]
    pub(crate) kp: f64,
    /// Regulator damping b_p (N s/m).
    #[arg(long, allow_negative_numbers = true)]
    pub(crate) bp: f64,
    /// Coupling mass m_cA (kg).
    #[arg(long, allow_negative_numbers = true)]
    pub(crate) m: f64,
    /// Coupling damping b_cA (N s/m).
    #[arg(long, allow_negative_numbers = true)]
    pub(crate) b: f64,
    #[command(flatten)]
    pub(crate) common: Common,
}

#[derive(Args, Clone)]
pub(crate) struct ZrangeImpedance {
    #[command(flatten)]
    pub(crate) gains: ImpedanceGains,
    /// Number of log-spaced frequencies.
    #[arg(long, default_value_t = 200)]
    pub(crate) points: usize,
}

#[derive(Args, Clone)]
pub(crate) struct ZrangeAdmittance {
    #[command(flatten)]
    pub(crate) gains: AdmittanceGains,
    /// Number of log-spaced frequencies.
    #[arg(long, default_value_t = 200)]
    pub(crate) points: usize,
}

#[derive(Clone, Copy, ValueEnum)]
pub(crate) enum Fig {
    /// Impedance-display design bound and coupling.
    Fig8,
    /// Admittance-display design bound and coupling.
    Fig9,
    /// Impedance range of both displays.
    Fig10,
    /// A linkage's proven stiffness over its workspace (--device LINKAGE).
    Workspace,
}

#[derive(Args, Clone)]
pub(crate) struct PlotArgs {
    /// Which figure.
    pub(crate) figure: Fig,
    /// Output file, .png or .svg.
    #[arg(long)]
    pub(crate) out: PathBuf,
    /// Impedance-coupling damping to design at (N s/m).
    #[arg(long, default_value_t = 90.0)]
    pub(crate) b_impedance: f64,
    /// Admittance-coupling damping to design at (N s/m).
    #[arg(long, default_value_t = 500.0)]
    pub(crate) b_admittance: f64,
    /// `workspace`: prove for every grasp of at least this damping (N
    /// s/m) instead of every passive hand.
    #[arg(long, allow_negative_numbers = true)]
    pub(crate) min_grasp: Option<f64>,
    #[command(flatten)]
    pub(crate) common: Common,
}

/// What a command's arguments share.
pub(crate) trait HasCommon {
    fn common(&self) -> &Common;
    /// Whether the command prints Rust source (a module per axis then,
    /// with no text heading).
    fn rust(&self) -> bool {
        false
    }
}

macro_rules! has_common {
    ($($t:ty),*) => {$(
        impl HasCommon for $t {
            fn common(&self) -> &Common {
                &self.common
            }
        }
    )*};
}

has_common!(
    PlotArgs,
    DesignImpedance,
    DesignAdmittance,
    ImpedanceGains,
    AdmittanceGains,
    HostVeArgs
);

impl HasCommon for RegionImpedance {
    fn common(&self) -> &Common {
        &self.common
    }
    fn rust(&self) -> bool {
        self.grid.rust
    }
}

impl HasCommon for RegionAdmittance {
    fn common(&self) -> &Common {
        &self.common
    }
    fn rust(&self) -> bool {
        self.grid.rust
    }
}

impl HasCommon for ZrangeImpedance {
    fn common(&self) -> &Common {
        self.gains.common()
    }
}

impl HasCommon for ZrangeAdmittance {
    fn common(&self) -> &Common {
        self.gains.common()
    }
}

impl<I: Args + HasCommon, A: Args + HasCommon> HasCommon for Display<I, A> {
    fn common(&self) -> &Common {
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

/// Check gains for sign and finiteness before any analysis.
pub(crate) fn gain(name: &str, v: f64) -> Result<f64, String> {
    (v.is_finite() && v >= 0.0)
        .then_some(v)
        .ok_or_else(|| format!("--{name} {v}: must be a finite number >= 0"))
}

/// A figure's file format.
#[derive(Clone, Copy, ValueEnum)]
pub(crate) enum PlotFormat {
    Png,
    Svg,
}

#[derive(Args, Clone)]
pub(crate) struct IdentifyArgs {
    /// The experiments' records, one an axis, each named by its file's
    /// stem (x.csv is the axis x): CSV with columns t_s, force_n,
    /// position_m and optionally load_cell_n, after a `# twoport
    /// experiment:` line naming the excitation (what `host-sim pil --log`
    /// and a board's capture write).
    #[arg(required = true)]
    pub(crate) records: Vec<PathBuf>,
    /// Folder to write into: for each axis, AXIS/model.toml (its fit),
    /// AXIS/set/NN.toml (the set that spans its uncertainty) and its
    /// figures; device.toml (every axis's fit) and set.toml (every axis's
    /// set, each model a pose), for `design --device`.
    #[arg(long)]
    pub(crate) out: PathBuf,
    /// The amplifier's peak force (N): the model needs it, and no
    /// experiment measures it.
    #[arg(long, allow_negative_numbers = true)]
    pub(crate) peak_force: f64,
    /// The amplifier's continuous force (N).
    #[arg(long, allow_negative_numbers = true)]
    pub(crate) continuous_force: f64,
    /// The load cell's filter pole (rad/s); needed where a record has a
    /// load cell.
    #[arg(long, allow_negative_numbers = true)]
    pub(crate) load_cell_pole: Option<f64>,
    /// Whole periods (or a stepped sine's steps) skipped at the start,
    /// while the transient settles.
    #[arg(long, default_value_t = 2)]
    pub(crate) skip: usize,
    /// What the records played, for records without a `# twoport
    /// experiment:` line (made by another program), in its words: a
    /// periodic force, "period_ticks = 4096, first = 2, last = 1843" (the
    /// harmonics of that period it holds: a multisine, random phases, a
    /// chirp swept once a period); or a stepped sine, "stepped, step_ticks
    /// = 3000" (one frequency held for each 3000 samples).
    #[arg(long, value_name = "WORDS")]
    pub(crate) excitation: Option<String>,
    /// A second record of an axis's experiment, played with a known mass
    /// clamped on the handle (--added-mass), fitted with the bare record:
    /// it shows the handle's side of the device (what the handle weighs
    /// past the load cell, and any path that holds it beside the load
    /// cell), which an admittance display depends on and the bare
    /// experiment cannot see. Repeat for each axis that has one.
    #[arg(long, value_name = "AXIS=PATH")]
    pub(crate) loaded: Vec<String>,
    /// The mass clamped on the handle in the --loaded records (kg).
    #[arg(long, allow_negative_numbers = true)]
    pub(crate) added_mass: Option<f64>,
    /// The device's name; by default, from the records' file names.
    #[arg(long)]
    pub(crate) name: Option<String>,
    /// Standard deviations the set reaches either side of the fit along
    /// each principal direction of its covariance.
    #[arg(long, default_value_t = 3.0, allow_negative_numbers = true)]
    pub(crate) sigmas: f64,
    /// The fraction by which every model of the set has its damping
    /// lowered: what amplitude-dependent damping (friction before it
    /// slides) may have added during the experiment.
    #[arg(long, default_value_t = 0.05, allow_negative_numbers = true)]
    pub(crate) damping_doubt: f64,
    /// Draw the measured responses with the fit's, and their coherence,
    /// into the output folder in this format.
    #[arg(long, value_enum)]
    pub(crate) plot: Option<PlotFormat>,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub(crate) json: bool,
}

/// `rates`: the devices, the servo rates and the linkages' grasp.
#[derive(Args, Clone)]
pub(crate) struct RatesArgs {
    /// Device model files (one axis each); the shipped Excalibur, capstan
    /// and two-mass device by default.
    #[arg(long, num_args = 1.., default_values = [
        "models/excalibur.toml", "models/capstan.toml", "models/two_mass.toml",
    ])]
    pub(crate) model: Vec<PathBuf>,
    /// Linkage files, proven over their workspace at b = 0 for a grasp of
    /// at least --min-grasp; the shipped four by default.
    #[arg(long, num_args = 0.., default_values = [
        "models/linkages/phantom_premium_1_5.toml", "models/linkages/falcon_like.toml",
        "models/linkages/haply_2diy.toml", "models/linkages/hapkit.toml",
    ])]
    pub(crate) linkage: Vec<PathBuf>,
    /// Servo rates (Hz), comma-separated.
    #[arg(long, value_delimiter = ',', default_values_t = [1000.0, 2000.0, 4000.0, 10000.0], allow_negative_numbers = true)]
    rates: Vec<f64>,
    /// The linkages' least grasp damping (N s/m).
    #[arg(long, default_value_t = 2.0, allow_negative_numbers = true)]
    min_grasp: f64,
    /// With --host-body, each lumped device's row also gives the best
    /// coupling proven against that body.
    #[command(flatten)]
    pub(crate) host: HostOpts,
    /// The board's latency from sampling to the force (`2e-6`, s: a
    /// computation takes the same time at every rate, a larger share of a
    /// faster tick; or `0.1T`, the same share of each). Every device is
    /// proven with it.
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) latency: Option<Latency>,
    /// Draw the table as a log-log figure (.png or .svg).
    #[arg(long)]
    pub(crate) plot: Option<PathBuf>,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub(crate) json: bool,
}

/// A body the host simulates and moves with the handle, and its link.
#[derive(Args, Clone)]
pub(crate) struct HostOpts {
    /// The host body's mass (kg) and damping (N s/m), e.g. `1,10`: a body
    /// the host steps at its VE rate from the force the board reports and
    /// sends back as a held surface.
    #[arg(long, value_delimiter = ',', allow_negative_numbers = true)]
    host_body: Option<Vec<f64>>,
    /// The host's VE rate (Hz): the servo rate must be a whole multiple.
    #[arg(long, default_value_t = 1000.0, allow_negative_numbers = true)]
    ve_rate: f64,
    /// From the tick whose force the host reads to the tick that takes its
    /// answer (s): the host's step and the link both ways. Rounded up to
    /// whole ticks.
    #[arg(long, default_value_t = 0.002, allow_negative_numbers = true)]
    host_delay: f64,
}

/// A host body and its link, checked.
#[derive(Clone, Copy, Debug)]
pub(crate) struct HostArgs {
    /// The body's mass (kg) and damping (N s/m).
    pub(crate) body: (f64, f64),
    /// The VE rate (Hz).
    pub(crate) ve_rate_hz: f64,
    /// The delay (s).
    pub(crate) delay_s: f64,
}

impl HostArgs {
    /// `(N, d)` at `servo_hz`: the VE period and the delay in ticks, or
    /// why the rate is not a whole multiple of the VE rate.
    pub(crate) fn ticks(&self, servo_hz: f64) -> Result<(u32, u32), String> {
        use twoport_design::{host_ve::HostLoop, Error};
        HostLoop::ticks_at(1.0 / servo_hz, self.ve_rate_hz, self.delay_s).map_err(|e| match e {
            Error::HostRate { .. } => format!(
                "--rates {servo_hz} Hz: not a whole multiple of --ve-rate {} Hz",
                self.ve_rate_hz
            ),
            Error::HostDelay(_) => {
                format!("--host-delay {}: must be a time > 0 s", self.delay_s)
            }
            other => format!(
                "--rates {servo_hz} Hz, --ve-rate {} Hz, --host-delay {}: {other}",
                self.ve_rate_hz, self.delay_s
            ),
        })
    }
}

impl HostOpts {
    /// The host body and link, checked, where `--host-body` is given.
    pub(crate) fn get(&self) -> Result<Option<HostArgs>, String> {
        let Some(b) = &self.host_body else {
            return Ok(None);
        };
        let &[m, d] = b.as_slice() else {
            return Err(format!(
                "--host-body {b:?}: give the mass (kg) and the damping (N s/m), e.g. 1,10"
            ));
        };
        if !(m.is_finite() && m > 0.0) {
            return Err(format!("--host-body {m},{d}: the mass must be > 0 kg"));
        }
        if !(d.is_finite() && d >= 0.0) {
            return Err(format!(
                "--host-body {m},{d}: the damping must be 0 N s/m or more"
            ));
        }
        if !(self.ve_rate.is_finite() && self.ve_rate > 0.0) {
            return Err(format!("--ve-rate {}: not a rate (Hz)", self.ve_rate));
        }
        if !(self.host_delay.is_finite() && self.host_delay > 0.0) {
            return Err(format!(
                "--host-delay {}: must be a time > 0 s",
                self.host_delay
            ));
        }
        Ok(Some(HostArgs {
            body: (m, d),
            ve_rate_hz: self.ve_rate,
            delay_s: self.host_delay,
        }))
    }
}

/// `twoport host-ve`'s arguments.
#[derive(Args, Clone)]
pub(crate) struct HostVeArgs {
    /// Coupling stiffness k_cI (N/m); without it, the stiffest proven
    /// (at --b, or the best pair).
    #[arg(long, allow_negative_numbers = true)]
    pub(crate) k: Option<f64>,
    /// Coupling damping b_cI (N s/m); without it (and without --k), the
    /// best pair.
    #[arg(long, allow_negative_numbers = true)]
    pub(crate) b: Option<f64>,
    #[command(flatten)]
    pub(crate) host: HostOpts,
    /// Also search hands on the exact two-rate loop (independent of the
    /// proof).
    #[arg(long)]
    pub(crate) verify: bool,
    #[command(flatten)]
    pub(crate) common: Common,
}

impl RatesArgs {
    /// The rates, each finite and positive, or the one that is not.
    pub(crate) fn rates(&self) -> Result<Vec<f64>, String> {
        match self.rates.iter().find(|r| !(r.is_finite() && **r > 0.0)) {
            Some(r) => Err(format!("--rates: {r} Hz is not a rate")),
            None => Ok(self.rates.clone()),
        }
    }

    /// The grasp, finite and not negative.
    pub(crate) fn grasp(&self) -> Result<f64, String> {
        let g = self.min_grasp;
        (g.is_finite() && g >= 0.0)
            .then_some(g)
            .ok_or_else(|| format!("--min-grasp {g}: a damping (N s/m), 0 or more"))
    }
}

/// `identify-pose`: a linkage's sines at one pose to the mass, damping and
/// joint losses there, and the coupling proven on them.
#[derive(Args, Clone)]
pub(crate) struct IdentifyPoseArgs {
    /// The linkage file: its kinematics take the handle's motion to the
    /// joints, and its period and motors are the design's.
    #[arg(long)]
    pub(crate) linkage: PathBuf,
    /// The joint angles the experiments were played at (rad),
    /// comma-separated.
    #[arg(
        long,
        value_delimiter = ',',
        required = true,
        allow_negative_numbers = true
    )]
    pub(crate) pose_rad: Vec<f64>,
    /// A folder of one level's sines: one experiment per Cartesian axis,
    /// each with every axis's record, named PUSHED-AXIS.csv (x-x.csv,
    /// x-y.csv, ..., z-z.csv). Give two levels or more, lowest first: the
    /// levels tell the joints' damping from their friction.
    #[arg(long, required = true)]
    pub(crate) level: Vec<PathBuf>,
    /// Whole periods skipped at the start of each record: the hold's own
    /// mode must have died away.
    #[arg(long, default_value_t = 8)]
    pub(crate) skip: usize,
    /// The least damping (N s/m) every hand grasps with: the dead-man
    /// switch's promise, which the design credits.
    #[arg(long, default_value_t = 2.0, allow_negative_numbers = true)]
    pub(crate) min_grasp: f64,
    /// Standard deviations the set's damping is lowered by.
    #[arg(long, default_value_t = 3.0, allow_negative_numbers = true)]
    pub(crate) sigmas: f64,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub(crate) json: bool,
}

/// Only `--json`.
#[derive(Args)]
pub(crate) struct JsonArg {
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub(crate) json: bool,
}

/// `twoport spec`'s arguments.
#[derive(Args)]
pub(crate) struct SpecArgs {
    /// The device (`twoport devices` lists them).
    pub(crate) device: String,
    /// The least grasp damping the second proof assumes (N s/m): a
    /// dead-man switch keeps force off without it.
    #[arg(long, default_value_t = 2.0, allow_negative_numbers = true)]
    pub(crate) min_grasp: f64,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub(crate) json: bool,
}
