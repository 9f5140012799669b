//! `host-sim teleop`: one teleoperation scene, both devices judged, with
//! its CSV or plot on request.

use crate::run::{print_verdict, say_report, Recorder, SceneArgs};
use clap::Args;
use host_sim::engine::teleop::{TeleopReport, TeleopScene, Teleoperation};
use host_sim::Error;
use std::path::PathBuf;

#[derive(Args)]
pub(crate) struct TeleopArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// Write every tick of both devices to this CSV file.
    #[arg(long)]
    csv: Option<PathBuf>,
    /// Draw both devices' run to this PNG file.
    #[arg(long)]
    png: Option<PathBuf>,
}

impl TeleopArgs {
    /// A plain run of `scene`: its report, nothing written.
    pub(crate) fn of(scene: PathBuf) -> Self {
        TeleopArgs {
            scene: SceneArgs {
                scene,
                sets: Vec::new(),
                json: false,
            },
            csv: None,
            png: None,
        }
    }
}

const COLUMNS: &str = "t_s,master_position_m,slave_position_m,master_velocity_mps,\
slave_velocity_mps,operator_force_n,environment_force_n,master_actuator_force_n,\
slave_actuator_force_n,master_guard_nspm,slave_guard_nspm";

pub(crate) fn teleop(a: &TeleopArgs) -> Result<(), Error> {
    let scene = TeleopScene::load(&a.scene.scene, &a.scene.sets)?;
    let name = scene.name.clone();
    let mut run = Teleoperation::new(scene)?;
    let mut rec = Recorder::new(a.csv.as_deref(), COLUMNS, a.png.is_some())?;
    let report = run.run(|s| {
        rec.record(s, || {
            let (m, l) = (&s.master, &s.slave);
            format!(
                "{},{},{},{},{},{},{},{},{},{},{}",
                m.t_s,
                m.handle_m[0],
                l.handle_m[0],
                m.handle_mps[0],
                l.handle_mps[0],
                m.human_n[0],
                l.human_n[0],
                m.actuator_n[0],
                l.actuator_n[0],
                s.guard_nspm[0],
                s.guard_nspm[1]
            )
        })
    });
    let kept = rec.finish()?;
    if let Some(p) = &a.png {
        host_sim::study::plot::teleop_png(&kept, &name, p)?;
    }
    say_report(&report, a.scene.json, print_report)
}

fn print_report(r: &TeleopReport) {
    print_verdict(&r.scene, &r.reason);
    say!(
        "  tracking: RMS {:.3} mm over the run, at most {:.3} mm in the last second",
        r.tracking_rms_m * 1e3,
        r.late_error_m * 1e3
    );
    for (name, side, energy) in [
        ("master", &r.master, "operator's energy in"),
        ("slave", &r.slave, "environment's energy in"),
    ] {
        say!(
            "  {name}: peak force {:.2} N, {energy} {:.4} J",
            side.peak_force_n,
            side.energy_in_j
        );
    }
    say!(
        "  {:.1} s simulated in {:.3} s ({:.0}x real time)",
        r.master.sim_seconds,
        r.master.wall_seconds,
        r.master.realtime_factor
    );
}
