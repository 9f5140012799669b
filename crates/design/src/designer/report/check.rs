//! `check`'s report: given gains, proven or not, and how far inside the
//! boundary.

use super::{BindingBound, Context, DisplayKind, Limit};
use crate::analysis::Check;
use crate::limit_cycle::LimitCycle;
use serde::ser::{SerializeMap, Serializer};
use serde::Serialize;
use std::fmt;
use twoport_control::Gains;

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
    pub(in crate::designer) fn new(
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
            BindingBound::SampledData
        } else {
            BindingBound::Both
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
