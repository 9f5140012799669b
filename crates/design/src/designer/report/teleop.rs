//! `teleop`'s reports: the proof's and the counterexample search's
//! verdicts on a teleoperator.

use crate::analysis::{Felt, TeleopCheck};
use crate::verify::{TeleopLaw, TeleopVerdict};
use serde::Serialize;
use std::fmt;
use twoport_control::teleop::FourChannelGains;

/// The search's verdict on a teleoperator between two devices: the law
/// and its channel, and the worst operator and
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
    /// The law (JSON: `gains` or `wave`).
    #[serde(flatten)]
    pub law: TeleopLaw,
    /// What the search found.
    #[serde(flatten)]
    pub verdict: TeleopVerdict,
}

/// The proof's verdict on a four-channel teleoperator between two
/// devices: the law's gains and channel, and the proof's margin.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TeleopCheckReport {
    /// The master's model name.
    pub master: String,
    /// The slave's model name.
    pub slave: String,
    /// The sample period both run at (s).
    pub period_s: f64,
    /// The channel's delay each way (ticks).
    pub delay_ticks: usize,
    /// Whether the operator was held to the human bound (else any
    /// passive operator).
    pub human_bound: bool,
    /// The law (JSON: `gains` or `wave`).
    #[serde(flatten)]
    pub law: TeleopLaw,
    /// What the proof found.
    #[serde(flatten)]
    pub check: TeleopCheck,
    /// What the operator feels at the grid's lowest frequency, through
    /// free space and against a rigid wall (the teleoperator's Z-width,
    /// at the base band).
    pub felt: Option<Felt>,
}

/// The heading both reports share: the devices, the channel and the law.
fn heading(
    f: &mut fmt::Formatter<'_>,
    (master, slave): (&str, &str),
    period_s: f64,
    delay_ticks: usize,
    law: &TeleopLaw,
) -> fmt::Result {
    writeln!(
        f,
        "Teleoperator: {master} (master) and {slave} (slave) at T = {} ms, {delay_ticks} ticks of delay each way",
        period_s * 1e3,
    )?;
    match law {
        TeleopLaw::FourChannel(g) => four_channel(f, g),
        TeleopLaw::Wave(w) => writeln!(
            f,
            "  wave channel: impedance {} N s/m, incoming waves filtered at pole {}",
            w.b_nspm, w.filter_pole
        ),
    }
}

fn four_channel(f: &mut fmt::Formatter<'_>, g: &FourChannelGains) -> fmt::Result {
    writeln!(
        f,
        "  master: k_m {} N/m, b_m {} N s/m, own damping {} N s/m; slave: k_s {} N/m, b_s {} N s/m",
        g.k_m_npm, g.b_m_nspm, g.b_local_nspm, g.k_s_npm, g.b_s_nspm
    )?;
    writeln!(
        f,
        "  force channels: c2 {}, c3 {}, c5 {}, c6 {}",
        g.c2, g.c3, g.c5, g.c6
    )
}

impl fmt::Display for TeleopCheckReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let names = (self.master.as_str(), self.slave.as_str());
        heading(f, names, self.period_s, self.delay_ticks, &self.law)?;
        let c = &self.check;
        let who = if self.human_bound {
            "every operator within the human bound"
        } else {
            "every passive operator"
        };
        if c.proven {
            writeln!(
                f,
                "  PROVEN: absolutely stable for {who} and every passive environment"
            )?;
        } else {
            writeln!(f, "  NOT PROVEN for {who} and every passive environment")?;
        }
        writeln!(
            f,
            "  least slack {:.3e} at {:.2} Hz (positive: no termination closes a pole)",
            c.slack, c.frequency_hz
        )?;
        if !c.holds_toward_dc {
            writeln!(
                f,
                "  toward DC the slack falls below zero (a law reading a load cell: its aliased \
                 share is bounded too loosely there)"
            )?;
        }
        writeln!(
            f,
            "  both ends let go: spectral radius 1 {:+.3e}",
            c.let_go_radius - 1.0
        )?;
        if let Some(t) = &self.felt {
            writeln!(
                f,
                "  the operator feels: through free space {:.4} kg and {:.3} N s/m; against a rigid wall {:.1} N/m",
                t.free_mass_kg, t.free_damping_nspm, t.wall_stiffness_npm
            )?;
        }
        Ok(())
    }
}

impl fmt::Display for TeleopVerifyReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let v = &self.verdict;
        let names = (self.master.as_str(), self.slave.as_str());
        heading(f, names, self.period_s, self.delay_ticks, &self.law)?;
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
