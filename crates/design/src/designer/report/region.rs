//! `region`'s report: the proven limit at each damping, the table a
//! board ships with.

use super::Context;
use serde::ser::{SerializeMap, Serializer};
use serde::Serialize;
use std::fmt;

/// What a region bounds at each damping.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum RegionBound {
    /// The impedance display's greatest coupling stiffness (N/m).
    #[serde(rename = "k_max_npm")]
    MaxStiffness,
    /// The admittance display's least coupling mass (kg).
    #[serde(rename = "m_min_kg")]
    MinMass,
}

impl RegionBound {
    fn name(self) -> &'static str {
        match self {
            RegionBound::MaxStiffness => "k_max_npm",
            RegionBound::MinMass => "m_min_kg",
        }
    }
}

/// The proven region a board ships with: the limit at each damping.
#[derive(Clone, Debug, PartialEq)]
pub struct RegionReport {
    /// The device and display.
    pub context: Context,
    /// What the limit is.
    pub bound: RegionBound,
    /// `(b_c, limit)` rows, damping ascending.
    pub rows: Vec<(f64, f64)>,
    /// The admittance display's regulator `(k_p, b_p)`.
    pub regulator: Option<(f64, f64)>,
}

impl Serialize for RegionReport {
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
        m.serialize_entry("b_nspm", &column(0))?;
        m.serialize_entry(self.bound.name(), &column(1))?;
        m.serialize_entry("regulator", &self.regulator)?;
        m.end()
    }
}

impl fmt::Display for RegionReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:>14} {:>16}", "b (N s/m)", self.bound.name())?;
        for (b, l) in &self.rows {
            write!(f, "\n{b:>14.3} {l:>16.4}")?;
        }
        Ok(())
    }
}
