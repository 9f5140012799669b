//! `host-sim`: the scope (no subcommand), headless scene runs, sweeps to a
//! stability boundary, the paper's Table I, and processor-in-the-loop.

/// A [`host_sim::Error::Sim`] with a `format!` message.
macro_rules! err {
    ($($t:tt)*) => {
        host_sim::Error::Sim(format!($($t)*))
    };
}

/// `println!` for a report a reader may stop reading (`| head`): a closed
/// pipe ends the program quietly, as it does any Unix filter, where
/// `println!` would panic.
macro_rules! say {
    () => {
        crate::say(format_args!(""))
    };
    ($($t:tt)*) => {
        crate::say(format_args!($($t)*))
    };
}

/// One line on standard output; see [`say!`].
fn say(args: std::fmt::Arguments) {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    if let Err(e) = out.write_fmt(args).and_then(|()| out.write_all(b"\n")) {
        if e.kind() == std::io::ErrorKind::BrokenPipe {
            std::process::exit(0);
        }
        eprintln!("host-sim: standard output: {e}");
        std::process::exit(2);
    }
}

mod pil;
mod run;
mod scope;
mod study;
mod teleop;

use clap::{Parser, Subcommand};
use host_sim::Error;
use pil::{pil, PilArgs};
use run::{run, RunArgs};
use scope::{scope, ScopeArgs};
use std::process::ExitCode;
use study::{
    accuracy, latency_fit, passivity, sweep, table1, AccuracyArgs, LatencyFitArgs, PassivityArgs,
    SweepArgs, Table1Args,
};
use teleop::{teleop, TeleopArgs};

/// Simulate a haptic device around the board's own control code.
#[derive(Parser)]
#[command(name = "host-sim", version, args_conflicts_with_subcommands = true)]
struct Cli {
    #[command(subcommand)]
    cmd: Option<Cmd>,
    #[command(flatten)]
    scope: ScopeArgs,
}

#[derive(Subcommand)]
enum Cmd {
    /// The scope window (the same as no subcommand).
    Scope(ScopeArgs),
    /// Run one scene and judge its stability.
    Run(RunArgs),
    /// Find the marginal value of one parameter by bisection.
    Sweep(SweepArgs),
    /// Run the paper's Table I matrix and sweep its boundaries.
    Table1(Table1Args),
    /// Find the latency inside the tick at which a scene's swept boundary
    /// meets a measured one.
    LatencyFit(LatencyFitArgs),
    /// Measure what accuracy costs: every integrator x sub-step count.
    Accuracy(AccuracyArgs),
    /// The passivity layer's scenes: off, on, and at passive settings.
    Passivity(PassivityArgs),
    /// Two devices through one teleoperator: a master under the operator,
    /// a slave on the environment, the channel between them.
    Teleop(TeleopArgs),
    /// Processor-in-the-loop: this plant against a board over a serial port
    /// (the firmware in QEMU, or a real board), compared with the same
    /// board loop run in-process.
    Pil(PilArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let r = match &cli.cmd {
        None => scope(&cli.scope),
        Some(Cmd::Scope(a)) => scope(a),
        Some(c) => subcommand(c),
    };
    match r {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("host-sim: {e}");
            ExitCode::from(2)
        }
    }
}

fn subcommand(c: &Cmd) -> Result<(), Error> {
    match c {
        Cmd::Scope(a) => scope(a),
        Cmd::Run(a) => run(a),
        Cmd::Sweep(a) => sweep(a),
        Cmd::Passivity(a) => passivity(a),
        Cmd::Table1(a) => table1(a),
        Cmd::LatencyFit(a) => latency_fit(a),
        Cmd::Accuracy(a) => accuracy(a),
        Cmd::Teleop(a) => teleop(a),
        Cmd::Pil(a) => pil(a),
    }
}
