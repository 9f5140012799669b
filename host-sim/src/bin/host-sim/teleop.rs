//! `host-sim teleop`: one teleoperation scene, both devices judged, with
//! its CSV or plot on request.

use crate::run::{csv_file, finish_csv, print_verdict, SceneArgs};
use clap::Args;
use host_sim::engine::teleop::{TeleopReport, TeleopSample, TeleopScene, Teleoperation};
use host_sim::Error;
use std::io::Write;
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
    let mut csv = csv_file(a.csv.as_deref(), COLUMNS)?;
    let mut kept: Vec<TeleopSample> = Vec::new();
    let mut csv_err = None;
    let report = run.run(|s| {
        if let Some(w) = csv.as_mut() {
            let (m, l) = (&s.master, &s.slave);
            let row = format!(
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
            );
            if let Err(e) = writeln!(w, "{row}") {
                csv_err.get_or_insert(e);
            }
        }
        if a.png.is_some() {
            kept.push(*s);
        }
    });
    finish_csv(csv, csv_err)?;
    if let Some(p) = &a.png {
        host_sim::study::plot::teleop_png(&kept, &name, p)?;
    }
    if a.scene.json {
        say!(
            "{}",
            serde_json::to_string(&report).map_err(|e| e.to_string())?
        );
    } else {
        print_report(&report);
    }
    Ok(())
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
