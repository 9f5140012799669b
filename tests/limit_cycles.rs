//! The quantisation's limit cycles that `design` reports, against the
//! simulator with the encoder's quantum and Coulomb friction on: where the
//! report says friction holds the device, it stays still; where it does
//! not, no cycle moves faster than the report's bound.

use host_sim::{Scene, Simulation};
use std::path::{Path, PathBuf};
use twoport_design::limit_cycle::{Friction, LimitCycle};
use twoport_design::{Designer, DeviceModel};

/// The simulated Coulomb friction's smoothing velocity (m/s).
const SMOOTH: f64 = 1e-5;

fn root() -> PathBuf {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/..")).to_path_buf()
}

/// The capstan handle on a rigid wall (the bilateral VE behind the
/// coupling `k`, `b = 0`) with the grasp `grasp`, an encoder quantum
/// `quantum_m`, friction
/// `coulomb_n` (smoothed over `smooth_mps`), and a 1 N bump at 0.2 s.
fn scene(k: f64, quantum_m: f64, coulomb_n: f64, smooth_mps: f64, grasp: &str) -> Scene {
    let model = root().join("models/capstan.toml");
    let text = format!(
        r#"
name = "capstan on a quantised wall"
duration_s = 6.0
display = "impedance"
[plant]
model = "{}"
[coupling]
k = {k}
b = 0.0
[ve]
kind = "bilateral"
[human]
grasp = "{grasp}"
[[human.script]]
kind = "force"
at_s = 0.2
force_n = 1.0
for_s = 0.05
[effects]
flexibility = true
encoder = {{ resolution_m = {quantum_m:e}, bits = 16 }}
coulomb = {{ force_n = {coulomb_n:e}, smoothing_mps = {smooth_mps:e} }}
"#,
        model.display()
    );
    Scene::parse(&text, "limit_cycles.rs", &[]).unwrap()
}

/// The handle's RMS velocity over the last 3 s (m/s).
fn late_rms_velocity(scene: &Scene) -> f64 {
    let mut sim = Simulation::new(scene.clone()).unwrap();
    let (mut sum, mut n) = (0.0, 0usize);
    for _ in 0..sim.total_ticks() {
        let s = sim.step();
        if s.t_s > 3.0 {
            sum += s.handle_mps[0].powi(2);
            n += 1;
        }
    }
    (sum / n as f64).sqrt()
}

fn report(k: f64, quantum_m: f64, coulomb_n: f64) -> LimitCycle {
    let model = DeviceModel::load(&root().join("models/capstan.toml")).unwrap();
    let f = Friction {
        encoder_quantum_m: quantum_m,
        coulomb_friction_n: coulomb_n,
        ..model
            .friction()
            .expect("the capstan model gives its encoder")
    };
    LimitCycle::new(&f, k, 0.0, model.period_s, true)
}

#[test]
fn the_designer_reports_the_models_encoder_and_friction() {
    let model = DeviceModel::load(&root().join("models/capstan.toml")).unwrap();
    let designer = Designer::new(vec![model], None, None).unwrap();
    let lc = designer
        .check_impedance(3_000.0, 0.0)
        .unwrap()
        .limit_cycle
        .expect("a limit-cycle report");
    assert_eq!(lc, report(3_000.0, 1e-5, 0.05));
    assert!(lc.proven && lc.held);
    let d = designer.design_impedance(Some(0.0), 0.1).unwrap();
    let at = d.limit_cycle.expect("a limit-cycle report at the design");
    assert_eq!(at.stiffness_npm, d.recommended().unwrap());
}

/// Rigid and inside Colgate's condition, hands off after a bump: without
/// friction the quantised wall rings on, but never faster than the bound;
/// where the report says friction holds, the handle comes to rest.
#[test]
fn friction_holds_where_the_report_says_and_cycles_stay_under_the_bound() {
    for (k, q) in [
        (3_000.0, 1e-5),
        (3_900.0, 1e-5),
        (3_000.0, 1e-4),
        (3_990.0, 1e-4),
    ] {
        let free = report(k, q, 0.0);
        let v = late_rms_velocity(&scene(k, q, 0.0, SMOOTH, "hands_off"));
        let bound = free.velocity_rms_bound_mps.unwrap();
        assert!(
            v > 1e-4 && v <= bound,
            "k {k}, Δ {q}: without friction a cycle of {v:e} m/s RMS, bound {bound:e}"
        );
        for share in [1.0, 1.5] {
            let fc = share * free.quantum_force_n;
            let lc = report(k, q, fc);
            assert!(lc.held && lc.proven);
            // (The simulated friction is smoothed over `SMOOTH`, below
            // which a held handle creeps rather than sticks.)
            let v = late_rms_velocity(&scene(k, q, fc, SMOOTH, "hands_off"));
            assert!(
                v < SMOOTH,
                "k {k}, Δ {q}, f_c {fc}: friction holds, yet {v:e} m/s RMS"
            );
        }
    }
}

/// The stiffest grasp presses the handle into the wall and keeps still:
/// its damping leaves no cycle at all, friction or none.
#[test]
fn a_held_handle_does_not_cycle() {
    for fc in [0.0, 0.05] {
        let v = late_rms_velocity(&scene(3_000.0, 1e-5, fc, SMOOTH, "maximum"));
        assert!(v < SMOOTH, "f_c {fc}: {v:e} m/s RMS");
    }
}
