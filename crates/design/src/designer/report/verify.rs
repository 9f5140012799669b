//! `verify`'s report: the counterexample search's verdict on the worst
//! pose.

use super::Context;
use serde::ser::{SerializeMap, Serializer};
use serde::Serialize;
use std::fmt;

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
        let v = serde_json::to_value(&self.verdict).map_err(serde::ser::Error::custom)?;
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
        super::worst_termination(f, &v.termination)?;
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
