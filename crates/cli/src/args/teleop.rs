//! `teleop`'s arguments: two devices, a law and the channel.

use clap::{Args, Subcommand};
use std::path::PathBuf;

/// `teleop`'s commands.
#[derive(Subcommand, Clone)]
pub(crate) enum Teleop {
    /// Search for a passive operator and environment that make the exact
    /// sampled teleoperator unstable at these gains (master, slave, law
    /// and channel in one discrete loop).
    Verify(TeleopArgs),
    /// Prove the teleoperator absolutely stable for every passive operator
    /// and environment: the sampled loop's two-port, aliasing at both
    /// handles.
    Check(TeleopArgs),
    /// The largest gain the proof allows: position-position's --k,
    /// position-force's --k-f or the wave channel's --b, left out and
    /// found.
    Design(TeleopArgs),
}

/// Two devices and the law between them.
#[derive(Args, Clone)]
pub(crate) struct TeleopArgs {
    /// The master's model file (TOML): the device under the operator's
    /// hand.
    #[arg(long)]
    pub(crate) master: PathBuf,
    /// The slave's model file (TOML): the device on the environment. Both
    /// must sample at one period.
    #[arg(long)]
    pub(crate) slave: PathBuf,
    /// The channel's delay each way (ticks of the devices' period).
    #[arg(long, default_value_t = 0)]
    pub(crate) delay: usize,
    /// Hold the operator to the human bound Z_max = 300 + 1000/s (check
    /// and design; verify searches every passive operator).
    #[arg(long)]
    pub(crate) human_bound: bool,
    /// Draw what the operator feels through the law (check and design),
    /// through free space and against a rigid wall, against frequency
    /// (.png or .svg).
    #[arg(long)]
    pub(crate) plot: Option<PathBuf>,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub(crate) json: bool,
    #[command(subcommand)]
    pub(crate) law: TeleopLaw,
}

/// The teleoperator's law: one of Lawrence's four-channel laws.
#[derive(Subcommand, Clone)]
pub(crate) enum TeleopLaw {
    /// Each side held to the other's delayed motion by one spring and
    /// damper; no force sensed.
    PositionPosition {
        /// Stiffness (N/m); design finds it.
        #[arg(long, allow_negative_numbers = true)]
        k: Option<f32>,
        /// Damping (N s/m).
        #[arg(long, allow_negative_numbers = true)]
        b: f32,
    },
    /// Force reflection: the slave held to the master's delayed motion,
    /// the master pushed by the slave's sensed force.
    PositionForce {
        /// The slave's stiffness (N/m).
        #[arg(long, allow_negative_numbers = true)]
        k: f32,
        /// The slave's damping (N s/m).
        #[arg(long, allow_negative_numbers = true)]
        b: f32,
        /// The force fed back to the master per the slave's sensed force;
        /// design finds it.
        #[arg(long, allow_negative_numbers = true)]
        k_f: Option<f32>,
        /// The master's own damping (N s/m).
        #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
        b_m: f32,
    },
    /// The wave-variable channel (passive for any constant delay of at
    /// least one tick), each side's incoming wave low-passed at
    /// --filter-pole (0: none; a bare channel's line resonates with a
    /// stiff termination at Nyquist).
    Wave {
        /// The wave impedance (N s/m); design finds the largest proven.
        #[arg(long, allow_negative_numbers = true)]
        b: Option<f32>,
        /// The incoming-wave filter's pole, in [0, 1).
        #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
        filter_pole: f32,
    },
    /// Lawrence's four channels, each gain given by name (0 where left
    /// out): `k_m_npm`, `b_m_nspm` (the master's coupling to the slave's
    /// motion), `b_local_nspm` (the master's own damping), `k_s_npm`,
    /// `b_s_nspm` (the slave's coupling), `c2`, `c3`, `c5`, `c6` (the
    /// force channels), as a teleoperation scene's `[law.gains]` names them.
    FourChannel {
        /// A gain, e.g. `--gain k_m_npm=300` (repeatable).
        #[arg(
            long = "gain",
            value_name = "NAME=VALUE",
            allow_negative_numbers = true
        )]
        gains: Vec<String>,
    },
}
