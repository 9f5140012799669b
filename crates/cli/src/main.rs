//! `twoport`: design and check virtual couplings for a haptic device.

/// `print!` for a report a reader may stop reading (`| head`): a closed
/// pipe ends the program quietly, as it does any Unix filter, where
/// `print!` would panic.
macro_rules! say {
    ($($t:tt)*) => {
        crate::say(format_args!($($t)*))
    };
}

/// Text on standard output; see [`say!`].
fn say(args: std::fmt::Arguments) {
    use std::io::Write;
    if let Err(e) = std::io::stdout().lock().write_fmt(args) {
        if e.kind() == std::io::ErrorKind::BrokenPipe {
            std::process::exit(0);
        }
        eprintln!("twoport: standard output: {e}");
        std::process::exit(2);
    }
}

mod args;
mod check;
mod host;
mod identify;
mod identify_pose;
mod plots;
mod rates;
mod region;
mod run;
mod spec;
mod synthesis;
mod teleop;
mod verify;

use crate::args::*;
use crate::run::{each_axis, one_axis, print, show};
use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// Design haptic interfaces that are stable by construction: two-port
/// analysis, Llewellyn's absolute-stability criteria and virtual-coupling
/// synthesis after Adams & Hannaford (2002).
#[derive(Parser)]
#[command(name = "twoport", version, propagate_version = true)]
pub(crate) struct Cli {
    #[command(subcommand)]
    pub(crate) cmd: Cmd,
}

#[derive(Subcommand)]
pub(crate) enum Cmd {
    /// Synthesise a virtual coupling.
    #[command(subcommand)]
    Design(Display<DesignImpedance, DesignAdmittance>),
    /// Check a coupling for absolute stability (Llewellyn).
    #[command(subcommand)]
    Check(Display<ImpedanceGains, AdmittanceGains>),
    /// Impedance range (Z_min, Z_max) over frequency, 0.1 Hz to Nyquist.
    #[command(subcommand)]
    Zrange(Display<ZrangeImpedance, ZrangeAdmittance>),
    /// Draw one of the paper's figures from this designer's results.
    Plot(PlotArgs),
    /// The proven region a board ships with: the limit for each damping.
    #[command(subcommand)]
    Region(Display<RegionImpedance, RegionAdmittance>),
    /// Search for a passive hand and VE that make the exact sampled loop
    /// unstable at these gains (independent of the two-port proof).
    #[command(subcommand)]
    Verify(Display<ImpedanceGains, AdmittanceGains>),
    /// Identify a device from a bench experiment's record: a model file,
    /// a set of models that spans what the fit does not know, and the
    /// figures of the fit.
    Identify(IdentifyArgs),
    /// Identify a linkage at a pose from sines played at several levels:
    /// its mass and damping matrices, its joints' damping and friction,
    /// and the coupling proven on them.
    IdentifyPose(IdentifyPoseArgs),
    /// What the servo rate buys: each device's proven coupling at each
    /// servo rate, as a table and a figure.
    Rates(RatesArgs),
    /// Prove an impedance coupling against a body the host simulates and
    /// moves with the handle, at its VE rate and the link's delay (or find
    /// the stiffest such coupling).
    HostVe(HostVeArgs),
    /// The devices whose servo loop runs on the PC, which `spec` knows.
    Devices(JsonArg),
    /// A device's coupling proven over its workspace at its loop's rate
    /// and latency, beside the stiffness CHAI3D sets for it by hand.
    Spec(SpecArgs),
    /// Two devices through one teleoperator law: a master under the
    /// operator's hand, a slave on the environment, a channel between.
    #[command(subcommand)]
    Teleop(Teleop),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let linkage = |c: &Common| {
        c.device
            .as_deref()
            .is_some_and(twoport_design::linkage::LinkageFile::is_linkage)
    };
    let r = match &cli.cmd {
        Cmd::Design(Display::Impedance(a)) if linkage(&a.common) => {
            show(a.common.json, synthesis::design_linkage(a))
        }
        Cmd::Design(Display::Impedance(a)) => each_axis(a, synthesis::design_impedance),
        Cmd::Design(Display::Admittance(a)) => each_axis(a, synthesis::design_admittance),
        Cmd::Check(d) => each_axis(d, check::check),
        Cmd::Zrange(d) => one_axis(d, plots::zrange),
        Cmd::Plot(p) if matches!(p.figure, Fig::Workspace) => {
            show(p.common.json, plots::plot_workspace(p))
        }
        Cmd::Plot(p) => one_axis(p, plots::plot_fig),
        Cmd::Region(d) => each_axis(d, region::region),
        Cmd::Verify(Display::Impedance(a)) if linkage(&a.common) => {
            show(a.common.json, verify::verify_linkage(a))
        }
        Cmd::Verify(d) => each_axis(d, verify::verify),
        Cmd::Identify(a) => identify::identify(a).and_then(|r| print(a.json, &r)),
        Cmd::IdentifyPose(a) => identify_pose::identify_pose(a).and_then(|r| print(a.json, &r)),
        Cmd::Rates(a) => rates::rates(a).and_then(|r| print(a.json, &r)),
        Cmd::HostVe(a) => one_axis(a, host::host_ve),
        Cmd::Devices(a) => print(a.json, &spec::devices()),
        Cmd::Spec(a) => spec::spec(&a.device, a.min_grasp).and_then(|r| print(a.json, &r)),
        Cmd::Teleop(Teleop::Verify(a)) => show(a.json, teleop::verify(a)),
        Cmd::Teleop(Teleop::Check(a)) => show(a.json, teleop::check(a)),
        Cmd::Teleop(Teleop::Design(a)) => show(a.json, teleop::design(a)),
    };
    match r {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("twoport: {e}");
            ExitCode::from(2)
        }
    }
}
