//! What the designer answers: each report serialises to the JSON the
//! command line prints with `--json` and displays as its text.

use crate::limit_cycle::LimitCycle;
use serde::ser::{SerializeMap, Serializer};
use serde::Serialize;
use std::fmt;

mod check;
mod region;
mod teleop;
mod verify;

pub use check::CheckReport;
pub use region::{RegionBound, RegionReport};
pub use teleop::{TeleopCheckReport, TeleopVerifyReport};
pub use verify::VerifyReport;

/// Which display a report is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum DisplayKind {
    /// Measure motion, command force.
    Impedance,
    /// Measure force, command motion.
    Admittance,
}

impl DisplayKind {
    fn title(self) -> &'static str {
        match self {
            DisplayKind::Impedance => "Impedance",
            DisplayKind::Admittance => "Admittance",
        }
    }

    fn name(self) -> &'static str {
        match self {
            DisplayKind::Impedance => "impedance",
            DisplayKind::Admittance => "admittance",
        }
    }
}

/// What every report says of the device it is for.
#[derive(Clone, Debug, PartialEq)]
pub struct Context {
    /// The display.
    pub display: DisplayKind,
    /// The device's name (its model's, or its poses').
    pub device: String,
    /// The sample period (s).
    pub period_s: f64,
    /// Whether the proofs assume the human bound `Z_max = 300 + 1000/s`.
    pub human_model: bool,
    /// The latency from sampling to the force (s) every proof allows: the
    /// least of the poses'.
    pub latency_s: f64,
}

impl Context {
    fn human_text(&self) -> &'static str {
        if self.human_model {
            "human bound Z_max = 300 + 1000/s"
        } else {
            "no human bound (any passive human)"
        }
    }

    fn entries<M: SerializeMap>(&self, m: &mut M) -> Result<(), M::Error> {
        m.serialize_entry("display", &self.display)?;
        m.serialize_entry("period_s", &self.period_s)?;
        m.serialize_entry("human_model", &self.human_model)?;
        m.serialize_entry("latency_s", &self.latency_s)
    }
}

impl fmt::Display for Context {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} display, {} at T = {} ms, {}",
            self.display.title(),
            self.device,
            self.period_s * 1e3,
            self.human_text()
        )?;
        if self.latency_s > 0.0 {
            write!(f, ", latency {:.4} ms", self.latency_s * 1e3)?;
        }
        Ok(())
    }
}

/// What a design limits: the impedance display's coupling stiffness (more
/// is bolder) or the admittance display's coupling mass (less is).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Limit {
    /// `k_c` (N/m).
    Stiffness,
    /// `m_c` (kg).
    Mass,
}

impl Limit {
    /// `x` as published, with its unit: a stiffness rounded down (N/m), a
    /// mass up to the gram (kg), never past its proof.
    pub fn text(self, x: f64) -> String {
        match self {
            Limit::Stiffness => format!("{:.0} N/m", x.floor()),
            Limit::Mass => format!("{:.3} kg", (x * 1e3).ceil() / 1e3),
        }
    }

    /// The gain `margin` (a fraction) inside the boundary `x`.
    pub fn inside(self, x: f64, margin: f64) -> f64 {
        match self {
            Limit::Stiffness => x * (1.0 - margin),
            Limit::Mass => x / (1.0 - margin),
        }
    }

    /// The JSON key of the limit.
    fn key(self) -> &'static str {
        match self {
            Limit::Stiffness => "k_c_npm",
            Limit::Mass => "m_c_kg",
        }
    }

    fn what(self) -> &'static str {
        match self {
            Limit::Stiffness => "stiffness",
            Limit::Mass => "mass",
        }
    }

    fn unit(self) -> &'static str {
        match self {
            Limit::Stiffness => "N/m",
            Limit::Mass => "kg",
        }
    }

    /// By how much the paper's limit `paper` claims more than the proven
    /// `sound` one (a fraction; 0 where it claims no more).
    fn claims_more(self, sound: f64, paper: f64) -> f64 {
        match self {
            Limit::Stiffness => (paper - sound) / paper,
            Limit::Mass => (sound - paper) / paper,
        }
    }
}

/// Which bound set a design: the sampled-data one alone, or both alike.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum BindingBound {
    /// The sound bound binds: the paper's approximation claims more.
    #[serde(rename = "sampled-data")]
    SampledData,
    /// The paper's approximation gives the same limit.
    #[serde(rename = "both")]
    Both,
}

/// The admittance display's position regulator.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Regulator {
    /// `k_p` (N/m).
    pub kp: f64,
    /// `b_p` (N s/m).
    pub bp: f64,
    /// The regulated device's worst pole radius over the poses.
    pub pole_radius: f64,
}

/// A synthesised coupling: the boundary, the recommended gain inside it,
/// where it binds, and what the paper's approximation would have claimed.
#[derive(Clone, Debug, PartialEq)]
pub struct Design {
    /// The device and display.
    pub context: Context,
    /// What the design limits.
    pub limit: Limit,
    /// The boundary `(limit, b_c)`, where one is proven.
    pub coupling: Option<(f64, f64)>,
    /// The paper's approximation's boundary (aliasing neglected).
    pub paper: Option<(f64, f64)>,
    /// Whether the damping was asked for (else the best pair).
    pub fixed_damping: bool,
    /// The recommended gain's margin inside the boundary (a fraction).
    pub margin: f64,
    /// Where the design binds.
    pub binds_at: Option<Binds>,
    /// Which bound binds.
    pub binding: BindingBound,
    /// By how much the paper's approximation claims more (a fraction).
    pub aliasing_effect: f64,
    /// Why there is no design, where there is none.
    pub message: Option<String>,
    /// The admittance display's regulator.
    pub regulator: Option<Regulator>,
    /// What the encoder's quantum and the friction allow at the
    /// recommended gains, where the model gives them.
    pub limit_cycle: Option<LimitCycle>,
    /// Where a lightly damped mode holds the boundary below anything
    /// useful, the boundary, refused (N/m).
    pub limited_to: Option<f64>,
}

/// The least coupling stiffness worth proving (N/m): softer, a spring is
/// hard to tell from free motion through a handle (a 1 cm push meets
/// 1 N). A design held below it by a lightly damped mode is refused.
pub const USEFUL_STIFFNESS_NPM: f64 = 100.0;

/// Where a design binds.
#[derive(Clone, Debug, PartialEq)]
pub struct Binds {
    /// The frequency (Hz).
    pub frequency_hz: f64,
    /// The pose, with several.
    pub pose: Option<String>,
    /// A lightly damped mode of the device there, if it binds at one: what
    /// limits the design.
    pub limited_by: Option<LightMode>,
}

/// A lightly damped mode of the device (free, held still, or held by the
/// stiffest grasp), folded into the base band, that a design binds at.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct LightMode {
    /// Where it sits in the base band (Hz).
    pub frequency_hz: f64,
    /// Its damping ratio (its decay rate over its frequency).
    pub damping_ratio: f64,
}

impl Design {
    pub(super) fn new(
        context: Context,
        limit: Limit,
        [coupling, paper]: [Option<(f64, f64)>; 2],
        fixed_damping: bool,
        margin: f64,
        binds_at: Option<Binds>,
        message: Option<String>,
    ) -> Self {
        let (binding, aliasing_effect) = match (coupling, paper) {
            (Some((s, _)), Some((p, _))) => {
                let by = limit.claims_more(s, p);
                if by > 1e-5 {
                    (BindingBound::SampledData, by)
                } else {
                    (BindingBound::Both, by.max(0.0))
                }
            }
            (None, Some(_)) => (BindingBound::SampledData, 1.0),
            _ => (BindingBound::Both, 0.0),
        };
        Design {
            context,
            limit,
            coupling,
            paper,
            fixed_damping,
            margin,
            binds_at,
            binding,
            aliasing_effect,
            message,
            regulator: None,
            limit_cycle: None,
            limited_to: None,
        }
    }

    /// A stiffness limit held below [`USEFUL_STIFFNESS_NPM`] by a lightly
    /// damped mode is refused: no gains can help, and a number would read
    /// as a design. The limit stays in [`Design::limited_to`].
    pub(super) fn refuse_if_useless(&mut self) {
        let (Some((k, b)), Some(mode)) = (self.coupling, self.limited_by().copied()) else {
            return;
        };
        if self.limit != Limit::Stiffness || k >= USEFUL_STIFFNESS_NPM {
            return;
        }
        self.limited_to = Some(k);
        self.coupling = None;
        self.message = Some(format!(
            "nothing useful is proven: a mode at {:.2} Hz with damping ratio {:.1e} holds every coupling at b_c = {b:.1} N s/m below {} N/m, under the {USEFUL_STIFFNESS_NPM} N/m a hand can tell from free motion; damping that mode, or sensing where it moves, raises the limit",
            mode.frequency_hz,
            mode.damping_ratio,
            Limit::Stiffness.text(k).trim_end_matches(" N/m"),
        ));
    }

    /// The lightly damped mode the design binds at, if it binds at one.
    pub fn limited_by(&self) -> Option<&LightMode> {
        self.binds_at.as_ref().and_then(|b| b.limited_by.as_ref())
    }

    /// The recommended gain: `margin` inside the boundary.
    pub fn recommended(&self) -> Option<f64> {
        self.coupling
            .map(|(x, _)| self.limit.inside(x, self.margin))
    }
}

impl Serialize for Design {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut m = s.serialize_map(None)?;
        self.context.entries(&mut m)?;
        m.serialize_entry("feasible", &self.coupling.is_some())?;
        let key = self.limit.key();
        if let Some(r) = &self.regulator {
            m.serialize_entry("kp_npm", &r.kp)?;
            m.serialize_entry("bp_nspm", &r.bp)?;
            m.serialize_entry("regulator_pole_radius", &r.pole_radius)?;
        }
        if let Some((l, b)) = self.paper {
            m.serialize_entry(&format!("paper_{key}"), &l)?;
            m.serialize_entry("paper_b_c_nspm", &b)?;
        }
        if let Some((l, b)) = self.coupling {
            m.serialize_entry(key, &l)?;
            m.serialize_entry("b_c_nspm", &b)?;
        }
        m.serialize_entry("binding_bound", &self.binding)?;
        m.serialize_entry("aliasing_effect", &self.aliasing_effect)?;
        if let Some(b) = &self.binds_at {
            m.serialize_entry("binding_frequency_hz", &b.frequency_hz)?;
            if let Some(p) = &b.pose {
                m.serialize_entry("binding_pose", p)?;
            }
        }
        if let Some(r) = self.recommended() {
            m.serialize_entry("margin", &self.margin)?;
            m.serialize_entry(&format!("recommended_{key}"), &r)?;
        }
        if let Some(msg) = &self.message {
            m.serialize_entry("message", msg)?;
        }
        if let Some(l) = self.limited_by() {
            m.serialize_entry("limited_by", l)?;
        }
        if let Some(l) = &self.limit_cycle {
            m.serialize_entry("limit_cycle", l)?;
        }
        if let Some(k) = self.limited_to {
            m.serialize_entry(&format!("limited_to_{key}"), &k)?;
        }
        m.end()
    }
}

impl fmt::Display for Design {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "{}", self.context)?;
        if let Some(r) = &self.regulator {
            writeln!(
                f,
                "  position regulator K_p = {:.0} + {:.1} (1 - 1/z)/T (pole radius {:.4})",
                r.kp, r.bp, r.pole_radius
            )?;
        }
        let limit = self.limit;
        let (name, most, side) = match limit {
            Limit::Stiffness => ("k_c", "greatest", "below"),
            Limit::Mass => ("m_c", "least", "above"),
        };
        match self.coupling {
            Some((x, b)) if self.fixed_damping => writeln!(
                f,
                "  {most} {name} at b_c = {b} N s/m: {} (the boundary)",
                limit.text(x)
            )?,
            Some((x, b)) => writeln!(
                f,
                "  best coupling: {name} = {}, b_c = {b:.1} N s/m (the boundary)",
                limit.text(x)
            )?,
            None => writeln!(f, "  infeasible: {}", self.message.as_deref().unwrap_or(""))?,
        }
        if let Some(r) = self.recommended() {
            writeln!(
                f,
                "  recommended: {name} = {}, {:.0}% {side} the boundary",
                limit.text(r),
                100.0 * self.margin
            )?;
        }
        match &self.binds_at {
            Some(Binds {
                frequency_hz: hz,
                pose: Some(p),
                ..
            }) => writeln!(f, "  binds at {hz:.2} Hz in pose {p}")?,
            Some(Binds {
                frequency_hz: hz, ..
            }) => writeln!(f, "  binds at {hz:.2} Hz")?,
            None => {}
        }
        if let Some(l) = self.limited_by().filter(|_| self.limited_to.is_none()) {
            writeln!(
                f,
                "  limited by a mode at {:.2} Hz with damping ratio {:.1e}: so lightly damped a mode bounds what can be proven; damping it, or sensing where it moves, raises the limit",
                l.frequency_hz, l.damping_ratio
            )?;
        }
        let by = 100.0 * self.aliasing_effect;
        let (what, unit) = (limit.what(), limit.unit());
        match self.paper {
            Some((p, _)) if self.binding == BindingBound::SampledData => write!(
                f,
                "  the sampled-data analysis binds: the paper's approximation (aliasing at the handle neglected) gives {p:.4} {unit}; the proven {what} is {by:.1}% {}",
                if limit == Limit::Mass { "higher" } else { "lower" }
            ),
            Some(_) => write!(
                f,
                "  the paper's approximation gives the same {what} (aliasing moves it by {by:.4}%)"
            ),
            None => write!(f, "  the paper's approximation finds no design either"),
        }?;
        if let Some(l) = &self.limit_cycle {
            write!(f, "\n{l}")?;
        }
        Ok(())
    }
}

/// A search's worst termination as the text reports print it: one line
/// of its JSON.
fn worst_termination(f: &mut fmt::Formatter<'_>, t: &impl Serialize) -> fmt::Result {
    let json = serde_json::to_string(t).unwrap_or_default();
    write!(f, "  worst termination: {json}")
}
