//! What the designer answers: each report serialises to the JSON the
//! command line prints with `--json` and displays as its text.

use crate::analysis::Check;
use crate::limit_cycle::LimitCycle;
use serde::ser::{SerializeMap, Serializer};
use serde::Serialize;
use std::fmt;
use twoport_control::Gains;

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
        m.serialize_entry("human_model", &self.human_model)
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
        )
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
            Limit::Stiffness => "k_c",
            Limit::Mass => "m_c",
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
pub enum Binding {
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
    pub binding: Binding,
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
                    (Binding::SampledData, by)
                } else {
                    (Binding::Both, by.max(0.0))
                }
            }
            (None, Some(_)) => (Binding::SampledData, 1.0),
            _ => (Binding::Both, 0.0),
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
            m.serialize_entry("kp", &r.kp)?;
            m.serialize_entry("bp", &r.bp)?;
            m.serialize_entry("regulator_pole_radius", &r.pole_radius)?;
        }
        if let Some((l, b)) = self.paper {
            m.serialize_entry(&format!("paper_{key}"), &l)?;
            m.serialize_entry("paper_b_c", &b)?;
        }
        if let Some((l, b)) = self.coupling {
            m.serialize_entry(key, &l)?;
            m.serialize_entry("b_c", &b)?;
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
            Some((p, _)) if self.binding == Binding::SampledData => write!(
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

/// Given gains, checked: proven or not, the least margin and where, the
/// paper's verdict beside it, and how far inside the boundary at their
/// damping.
#[derive(Clone, Debug, PartialEq)]
pub struct CheckReport {
    /// The device and display.
    pub context: Context,
    /// The gains checked.
    pub gains: Gains,
    /// The check over every pose (the worst).
    pub check: Check,
    /// The pose with the least margin, with several poses.
    pub worst_pose: Option<String>,
    /// The boundary's limit at the same damping, where one is proven.
    pub boundary: Option<f64>,
    /// How far inside the boundary (a fraction; negative past it).
    pub gain_margin: Option<f64>,
    /// What the encoder's quantum and the friction allow at these gains,
    /// where the model gives them.
    pub limit_cycle: Option<LimitCycle>,
    /// The coupling's own numbers: `(limit, b_c, regulator)`.
    coupling: (f64, f64, Option<(f64, f64)>),
}

impl CheckReport {
    pub(super) fn new(
        context: Context,
        gains: Gains,
        coupling: (f64, f64, Option<(f64, f64)>),
        check: &Check,
        worst_pose: Option<String>,
        boundary: Option<f64>,
    ) -> Self {
        let x = coupling.0;
        let gain_margin = boundary.map(|l| match context.display {
            // 1 - k/k_max below the boundary; 1 - m_min/m above it.
            DisplayKind::Impedance => 1.0 - x / l,
            DisplayKind::Admittance => 1.0 - l / x,
        });
        CheckReport {
            context,
            gains,
            check: *check,
            worst_pose,
            boundary,
            gain_margin,
            limit_cycle: None,
            coupling,
        }
    }

    /// The boundary at the checked damping as published (rounded to
    /// safety: a stiffness down, a mass up), where one is proven.
    pub fn boundary_text(&self) -> Option<String> {
        self.boundary.map(|l| self.limit().text(l))
    }

    fn limit(&self) -> Limit {
        match self.context.display {
            DisplayKind::Impedance => Limit::Stiffness,
            DisplayKind::Admittance => Limit::Mass,
        }
    }
}

impl Serialize for CheckReport {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let c = &self.check;
        let mut m = s.serialize_map(None)?;
        self.context.entries(&mut m)?;
        m.serialize_entry("absolutely_stable", &c.absolutely_stable)?;
        m.serialize_entry("min_margin", &c.min_margin)?;
        m.serialize_entry("worst_frequency_hz", &c.worst_frequency_hz)?;
        let binding = if c.sampled_binds() {
            Binding::SampledData
        } else {
            Binding::Both
        };
        m.serialize_entry("binding_bound", &binding)?;
        m.serialize_entry("paper_absolutely_stable", &c.paper.absolutely_stable)?;
        m.serialize_entry("paper_min_margin", &c.paper.min_margin)?;
        m.serialize_entry("paper_worst_frequency_hz", &c.paper.worst_frequency_hz)?;
        if let Some(p) = &self.worst_pose {
            m.serialize_entry("worst_pose", p)?;
        }
        if self.context.display == DisplayKind::Admittance {
            m.serialize_entry("regulator_pole_radius", &c.regulator_pole_radius)?;
        }
        m.serialize_entry(&format!("boundary_{}", self.limit().key()), &self.boundary)?;
        m.serialize_entry("gain_margin", &self.gain_margin)?;
        if let Some(l) = &self.limit_cycle {
            m.serialize_entry("limit_cycle", l)?;
        }
        m.end()
    }
}

impl fmt::Display for CheckReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "{}", self.context)?;
        let (x, b, regulator) = self.coupling;
        match regulator {
            None => writeln!(f, "  coupling k_c = {x} N/m, b_c = {b} N s/m")?,
            Some((kp, bp)) => {
                writeln!(
                    f,
                    "  regulator k_p = {kp} N/m, b_p = {bp} N s/m; coupling m_c = {x} kg, b_c = {b} N s/m"
                )?;
                writeln!(
                    f,
                    "  regulated device pole radius {:.4}",
                    self.check.regulator_pole_radius
                )?;
            }
        }
        let c = &self.check;
        let verdict = |ok| {
            if ok {
                "absolutely stable (proven)"
            } else {
                "NOT proven absolutely stable"
            }
        };
        writeln!(
            f,
            "  {}: least margin {:.4} at {:.2} Hz (sampled-data analysis)",
            verdict(c.absolutely_stable),
            c.min_margin,
            c.worst_frequency_hz
        )?;
        if c.sampled_binds() {
            writeln!(
                f,
                "  the paper's approximation (aliasing at the handle neglected) would say {}: margin {:.4} at {:.2} Hz",
                verdict(c.paper.absolutely_stable),
                c.paper.min_margin,
                c.paper.worst_frequency_hz
            )?;
        }
        match (
            self.gain_margin,
            self.boundary.map(|l| self.limit().text(l)),
        ) {
            (Some(g), Some(b)) if g >= 0.0 => write!(
                f,
                "  gain margin {:.2}%: the boundary at this damping is {b}",
                100.0 * g
            ),
            (Some(g), Some(b)) => write!(
                f,
                "  {:.2}% past the boundary at this damping, {b}",
                -100.0 * g
            ),
            _ => write!(f, "  nothing is proven at this damping"),
        }?;
        if let Some(l) = &self.limit_cycle {
            write!(f, "\n{l}")?;
        }
        Ok(())
    }
}

/// What a region bounds at each damping.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum RegionBound {
    /// The impedance display's greatest coupling stiffness (N/m).
    #[serde(rename = "max_stiffness_npm")]
    MaxStiffness,
    /// The admittance display's least coupling mass (kg).
    #[serde(rename = "min_mass_kg")]
    MinMass,
}

impl RegionBound {
    fn name(self) -> &'static str {
        match self {
            RegionBound::MaxStiffness => "max_stiffness_npm",
            RegionBound::MinMass => "min_mass_kg",
        }
    }
}

/// The proven region a board ships with: the limit at each damping.
#[derive(Clone, Debug, PartialEq)]
pub struct Region {
    /// The device and display.
    pub context: Context,
    /// What the limit is.
    pub bound: RegionBound,
    /// `(b_c, limit)` rows, damping ascending.
    pub rows: Vec<(f64, f64)>,
    /// The admittance display's regulator `(k_p, b_p)`.
    pub regulator: Option<(f64, f64)>,
}

impl Serialize for Region {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut m = s.serialize_map(None)?;
        self.context.entries(&mut m)?;
        m.serialize_entry("bound", &self.bound)?;
        let column = |i: usize| -> Vec<f64> {
            self.rows
                .iter()
                .map(|r| if i == 0 { r.0 } else { r.1 })
                .collect()
        };
        m.serialize_entry("damping_nspm", &column(0))?;
        m.serialize_entry("limit", &column(1))?;
        m.serialize_entry("regulator", &self.regulator)?;
        m.end()
    }
}

impl fmt::Display for Region {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:>14} {:>16}", "b (N s/m)", self.bound.name())?;
        for (b, l) in &self.rows {
            write!(f, "\n{b:>14.3} {l:>16.4}")?;
        }
        Ok(())
    }
}

/// The counterexample search's verdict on the worst pose.
#[derive(Clone, Debug, PartialEq)]
pub struct VerifyReport {
    /// The device and display.
    pub context: Context,
    /// The worst pose's verdict, with the closed loops searched over all.
    pub verdict: crate::verify::Verdict,
    /// The worst pose, with several poses.
    pub worst_pose: Option<String>,
}

impl Serialize for VerifyReport {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let v = serde_json::to_value(self.verdict).map_err(serde::ser::Error::custom)?;
        let mut m = s.serialize_map(None)?;
        if let serde_json::Value::Object(fields) = v {
            for (k, v) in fields {
                m.serialize_entry(&k, &v)?;
            }
        }
        self.context.entries(&mut m)?;
        if let Some(p) = &self.worst_pose {
            m.serialize_entry("worst_pose", p)?;
        }
        m.end()
    }
}

impl fmt::Display for VerifyReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (c, v) = (&self.context, &self.verdict);
        writeln!(
            f,
            "{} display, {} at T = {} ms: {} closed loops searched",
            c.display.name(),
            c.device,
            c.period_s * 1e3,
            v.evaluations
        )?;
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
        writeln!(
            f,
            "  {verdict}; worst spectral radius 1 {:+.3e} at {:.2} Hz ({growth})",
            v.spectral_radius - 1.0,
            v.frequency_hz
        )?;
        write!(
            f,
            "  worst termination: {}",
            serde_json::to_string(&v.termination).unwrap_or_default()
        )?;
        if let Some(c) = &v.constructed {
            write!(
                f,
                "\n  constructed: a lossless hand and VE put a pole on the unit circle at {:.2} Hz (radius 1 {:+.1e}): {}",
                c.frequency_hz,
                c.spectral_radius - 1.0,
                serde_json::to_string(&c.termination).unwrap_or_default()
            )?;
        }
        Ok(())
    }
}
