//! `teleop verify`'s report: the counterexample search's verdict on a
//! teleoperator.

use crate::verify::TeleopVerdict;
use serde::Serialize;
use std::fmt;
use twoport_control::teleop::FourChannelGains;

/// The search's verdict on a four-channel teleoperator between two
/// devices: the law's gains and channel, and the worst operator and
/// environment found.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TeleopVerifyReport {
    /// The master's model name.
    pub master: String,
    /// The slave's model name.
    pub slave: String,
    /// The sample period both run at (s).
    pub period_s: f64,
    /// The channel's delay each way (ticks).
    pub delay_ticks: usize,
    /// The law's gains.
    pub gains: FourChannelGains,
    /// What the search found.
    #[serde(flatten)]
    pub verdict: TeleopVerdict,
}

impl fmt::Display for TeleopVerifyReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (g, v) = (&self.gains, &self.verdict);
        writeln!(
            f,
            "Teleoperator: {} (master) and {} (slave) at T = {} ms, {} ticks of delay each way",
            self.master,
            self.slave,
            self.period_s * 1e3,
            self.delay_ticks
        )?;
        writeln!(
            f,
            "  master: k_m {} N/m, b_m {} N s/m, own damping {} N s/m; slave: k_s {} N/m, b_s {} N s/m",
            g.k_m_npm, g.b_m_nspm, g.b_local_nspm, g.k_s_npm, g.b_s_nspm
        )?;
        writeln!(
            f,
            "  force channels: c2 {}, c3 {}, c5 {}, c6 {}",
            g.c2, g.c3, g.c5, g.c6
        )?;
        let verdict = if v.unstable {
            "UNSTABLE: a passive operator and environment break this teleoperator"
        } else {
            "no counterexample found"
        };
        writeln!(
            f,
            "  {verdict} ({} closed loops searched); worst spectral radius 1 {:+.3e} at {:.2} Hz",
            v.evaluations,
            v.spectral_radius - 1.0,
            v.frequency_hz
        )?;
        super::worst_termination(f, &v.termination)
    }
}
