//! The chain on the linkages at a pose: each linkage board image
//! (processor in the loop, in-process) plays one experiment per Cartesian
//! axis from its calibration pose, hands off, on the device file's
//! nonlinear arm (gravity, which the board holds up, its encoders'
//! quantum); the fit gives the mass and damping the hand feels there,
//! `M_x` and `D_x`. The design the images run (every hand that grasps
//! with at least 2 N s/m, no stiffer than the paper's `Z_max`) on the
//! identified pose is the true pose's, and the design for the set that
//! spans the fit's uncertainty holds for the true pose: `verify` finds
//! nothing there.
//!
//! The joints' Coulomb friction is off there: with it on, the push these
//! experiments give sticks the joints, and the fit refuses the records
//! rather than read the friction as damping a design would credit. Then
//! sines at three levels give the joints' losses from the energy they
//! dissipate (`pose::losses`) and `M_x` from their fundamentals, and the
//! chain closes with the friction on.

#[path = "../../tests/support/cli.rs"]
mod support;

use host_sim::engine::scene::IdentifySpec;
use host_sim::link::LinkFaults;
use host_sim::pil::linkage::{self, LinkageImage, Plan, Sines};
use nalgebra::DMatrix;
use twoport_design::linkage::{
    bounded_workspace_design, verify_linkage, HandAssumption, PoseDynamics,
};
use twoport_design::network::HumanBound;
use twoport_design::Lag;
use twoport_identify::log::Log;
use twoport_identify::pose::fit::{fit, POSE_DOUBT};
use twoport_identify::pose::PoseMeasured;

/// The experiment every axis plays: 1 to 450 Hz every 1 Hz for thirty 1 s
/// periods, peaking at 0.5 N, held by 100 N/m and 1 N s/m (inside the
/// images' region). A larger push moves the handle centimetres at the
/// hold's resonance, where `M_x` is no longer the pose's.
fn spec(axis: u8) -> IdentifySpec {
    IdentifySpec {
        axis,
        start_s: 0.3,
        period_s: 1.0,
        band_hz: [1.0, 450.0],
        peak_n: 0.5,
        periods: 30,
        hold_k_npm: 100.0,
        hold_b_nspm: 1.0,
    }
}

/// Every axis's record of experiment `s`, the joints' friction acting or
/// not.
fn record(device: LinkageImage, s: IdentifySpec, friction: bool) -> Vec<Log> {
    let experiment = s.experiment(1e-3).unwrap();
    let plan = Plan::Identify {
        experiment,
        start_ticks: 300,
        friction,
    };
    // The boot tick, the 0.3 s before, and the periods: the board disarms
    // once they are played, and the arm falls.
    let played = (experiment.periods * experiment.period_ticks) as usize;
    let ticks = 1 + 300 + played as u64;
    let r = linkage::run_local(device, ticks, LinkFaults::default(), plan).unwrap();
    let logs = r.experiment_axes().unwrap().unwrap();
    assert!(logs.iter().all(|l| l.force_n.len() == played));
    logs
}

/// The stiffest coupling at `b_c = 0` proven over `poses` for every
/// hand that grasps with at least `grasp` (N s/m) under the paper's bound.
fn design(device: LinkageImage, poses: &[PoseDynamics], grasp: f64) -> f64 {
    let file = device.file().unwrap();
    bounded_workspace_design(&file, poses, 0.0, grasp, HumanBound::PAPER)
        .unwrap()
        .k_c_npm
}

/// The eigenvalues of a symmetric matrix, least first.
fn eigen(m: &DMatrix<f64>) -> Vec<f64> {
    let mut e: Vec<f64> = m.clone().symmetric_eigenvalues().iter().copied().collect();
    e.sort_by(f64::total_cmp);
    e
}

/// The Jacobian where the handle is, from the device's kinematics near
/// its calibration pose.
fn along(device: LinkageImage) -> impl Fn(&[f64]) -> Option<DMatrix<f64>> + Sync {
    let file = device.file().unwrap();
    let rest = truth(device).q_rad;
    move |x| twoport_design::linkage::inverse(&file.geometry, x, &rest).map(|(_, j)| j)
}

/// The device's true pose at its calibration pose.
fn truth(device: LinkageImage) -> PoseDynamics {
    let rest: Vec<f64> = device
        .spec()
        .rest_rad
        .iter()
        .map(|q| f64::from(*q))
        .collect();
    device.file().unwrap().pose(&rest).unwrap()
}

/// The designs at the images' least grasp on the true pose, the
/// identified one and the set, and `verify`'s spectral radius on the
/// true pose at the set's.
struct Closed {
    k_true: f64,
    k_fit: f64,
    k_robust: f64,
    radius: f64,
}

/// The chain closed at a pose: `ident`'s principal masses within 2% of
/// the truth's (the heaviest within `heavy_tol`), its design within 3% of
/// the truth's, the design over `set` no stiffer than the truth's, and
/// `verify` on the true pose silent there.
fn closes(
    device: LinkageImage,
    ident: &PoseDynamics,
    set: &[PoseDynamics],
    heavy_tol: f64,
) -> Closed {
    let truth = truth(device);
    let (want, got) = (eigen(&truth.mass_kg), eigen(&ident.mass_kg));
    for (i, (w, g)) in want.iter().zip(&got).enumerate() {
        let tol = if i == 2 { heavy_tol } else { 0.02 };
        assert!(
            (g / w - 1.0).abs() < tol,
            "{device:?}: {got:?} against {want:?}"
        );
    }
    let grasp = f64::from(twoport_board::linkage::GRASP_NSPM);
    let k_true = design(device, std::slice::from_ref(&truth), grasp);
    let k_fit = design(device, std::slice::from_ref(ident), grasp);
    assert!(
        (k_fit / k_true - 1.0).abs() < 0.03,
        "{device:?}: {k_fit} against {k_true}"
    );
    let k_robust = design(device, set, grasp);
    assert!(
        k_robust <= k_true,
        "{device:?}: {k_robust} against {k_true}"
    );
    let hands = HandAssumption {
        min_grasp_nspm: grasp,
        human: Some(HumanBound::PAPER),
    };
    let period = device.file().unwrap().period_s;
    let v = verify_linkage(&[&truth], &hands, (k_robust, 0.0), (period, Lag::NONE)).unwrap();
    assert!(!v.unstable, "{device:?}: {v}");
    Closed {
        k_true,
        k_fit,
        k_robust,
        radius: v.spectral_radius,
    }
}

/// Per device, the chain closes ([`closes`]; the PHANToM's heaviest
/// direction, along its reach, within 20%) on the fit and over its set
/// (`POSE_DOUBT`: three standard deviations, no damping credited).
#[test]
#[cfg_attr(debug_assertions, ignore = "release only (CI runs it)")]
fn the_linkages_close_at_their_calibration_pose() {
    for (device, heavy_tol) in [(LinkageImage::SerialArm, 0.2), (LinkageImage::Delta, 0.02)] {
        let logs: Vec<Vec<Log>> = (0..3).map(|a| record(device, spec(a), false)).collect();
        // (Two periods skipped while the hold's mode settles.)
        let data = PoseMeasured::from_logs(&logs, 2).unwrap();
        let f = fit(&data).unwrap();
        let truth = truth(device);
        let ident = truth.with_body(&f.mass_kg, &f.damping_nspm);
        let set: Vec<PoseDynamics> = f
            .span(POSE_DOUBT)
            .iter()
            .map(|(m, d)| truth.with_body(m, d))
            .collect();
        let c = closes(device, &ident, &set, heavy_tol);
        let least = |p: &PoseDynamics| eigen(&p.damping_nspm)[0];
        eprintln!(
            "{device:?}: masses {:?} kg (true {:?}); least damping {:.4} ± {:.4} N s/m \
             (true {:.4}); misfit {:.2}; k at a 2 N s/m grasp: true {:.0}, fit {:.0}, \
             robust {:.0}, verify on the truth: radius {}; hands off: true {:.1}, fit {:.1}",
            eigen(&f.mass_kg),
            eigen(&truth.mass_kg),
            least(&ident),
            f.least_damping_sd(),
            least(&truth),
            f.misfit,
            c.k_true,
            c.k_fit,
            c.k_robust,
            c.radius,
            design(device, std::slice::from_ref(&truth), 0.0),
            design(device, std::slice::from_ref(&ident), 0.0),
        );
    }
}

/// With the PHANToM's joint friction acting (0.01 N m each, about 0.16 N
/// along its reach at this pose, a third of the push), the joints stick:
/// no linear body fits the records to their noise, and the fit says so
/// instead of handing a design the friction as damping (fitted anyway,
/// its least damping is hundreds of times the joints').
#[test]
#[cfg_attr(debug_assertions, ignore = "release only (CI runs it)")]
fn a_pose_whose_joints_stick_is_refused() {
    let logs: Vec<Vec<Log>> = (0..3)
        .map(|a| record(LinkageImage::SerialArm, spec(a), true))
        .collect();
    let data = PoseMeasured::from_logs(&logs, 2).unwrap();
    match fit(&data) {
        Err(twoport_identify::IdentifyError::NotLinear { misfit, most }) => {
            assert!(misfit > most);
            eprintln!("PHANToM with friction: refused, misfit {misfit:.1}");
        }
        other => panic!("{other:?}"),
    }
}

/// With the joints' friction acting or not: the 10 Hz sine on every axis
/// at three levels (the PHANToM's top one about its motors' continuous
/// force at the handle), the joints' losses from the energy each
/// dissipates, `M_x` from the top level's fundamentals. Per device the
/// chain closes ([`closes`]; the PHANToM's heaviest direction, along its
/// reach, which changes over the centimetre the handle swings, within
/// 10%) on the fit and over the set: each level's mass, the damping three
/// standard deviations down.
#[test]
#[cfg_attr(debug_assertions, ignore = "release only (CI runs it)")]
fn the_linkages_close_with_their_joints_friction() {
    use twoport_identify::pose::{fit::mass, losses};
    const SKIP: usize = 8;
    for (device, levels, heavy_tol) in [
        (LinkageImage::SerialArm, [0.5, 1.0, 1.5], 0.1),
        (LinkageImage::Delta, [1.0, 2.0, 4.0], 0.02),
    ] {
        let file = device.file().unwrap();
        let truth = truth(device);
        for friction in [true, false] {
            let runs = Sines {
                hz: 10.0,
                periods: 24,
                levels_n: levels.to_vec(),
                hold: (100.0, 1.0),
                friction,
            }
            .play(device)
            .unwrap();
            let masses: Vec<_> = runs
                .iter()
                .map(|r| mass(&PoseMeasured::from_logs(r, SKIP).unwrap()).unwrap())
                .collect();
            let l = losses::fit(&runs.concat(), &along(device), SKIP).unwrap();
            let m = masses.last().unwrap();
            let d = l.damping_nspm(&truth.jacobian, 0.0).unwrap();
            let least = l.damping_nspm(&truth.jacobian, 3.0).unwrap();
            let set: Vec<PoseDynamics> =
                masses.iter().map(|m| truth.with_body(m, &least)).collect();
            let c = closes(device, &truth.with_body(m, &d), &set, heavy_tol);
            eprintln!(
                "{device:?}, friction {friction}: masses {:?} kg (true {:?}); joints' damping \
                 {:?} ± {:?} N m s/rad (true {:?}), friction {:?} ± {:?} N m (true {:?}), misfit \
                 {:.4}, unresolved {}; D_x {:?} N s/m (true {:?}); k at a 2 N s/m grasp: true \
                 {:.0}, fit {:.0}, robust {:.0}, verify on the truth: radius {}",
                eigen(m),
                eigen(&truth.mass_kg),
                l.damping_nmsprad,
                &l.sd[..3],
                file.joints.damping_nmsprad,
                l.friction_nm,
                &l.sd[3..],
                if friction {
                    file.joints.friction_nm.clone()
                } else {
                    vec![0.0; 3]
                },
                l.misfit,
                l.unresolved,
                eigen(&d),
                eigen(&truth.damping_nspm),
                c.k_true,
                c.k_fit,
                c.k_robust,
                c.radius,
            );
        }
    }
}

/// `host-sim pil --linkage delta --sines 1,2,4 --log DIR` writes each
/// level's records where `twoport identify-pose` reads them, and they fit
/// to the delta's joints' friction within 2%; a missing folder or a level
/// that is no force is refused.
#[test]
#[cfg_attr(debug_assertions, ignore = "release only (CI runs it)")]
fn host_sim_writes_the_sines_identify_pose_reads() {
    use twoport_identify::pose::{losses, record_file};
    let tool = support::Tool {
        bin: env!("CARGO_BIN_EXE_host-sim"),
        root: concat!(env!("CARGO_MANIFEST_DIR"), "/.."),
    };
    let dir = support::scratch("sines");
    let d = dir.to_str().unwrap();
    let v = tool.json(&[
        "pil",
        "--linkage",
        "delta",
        "--sines",
        "1,2,4",
        "--log",
        d,
        "--json",
    ]);
    let folders = v["folders"].as_array().unwrap();
    assert_eq!(folders.len(), 3, "{v}");
    let mut records = Vec::new();
    for f in folders {
        let f = std::path::Path::new(f.as_str().unwrap());
        for pushed in 0..3 {
            let axes: Vec<Log> = (0..3)
                .map(|axis| {
                    let path = f.join(record_file(pushed, axis).unwrap());
                    let text = std::fs::read_to_string(&path).unwrap();
                    Log::from_csv(&text, &path.display().to_string()).unwrap()
                })
                .collect();
            records.push(axes);
        }
    }
    let l = losses::fit(&records, &along(LinkageImage::Delta), 8).unwrap();
    let c = LinkageImage::Delta.file().unwrap().joints.friction_nm;
    for (got, want) in l.friction_nm.iter().zip(&c) {
        assert!((got / want - 1.0).abs() < 0.02, "{l:?}");
    }
    for (args, want) in [
        (&["--sines", "1,2"][..], "--log"),
        (&["--sines", "1,-2", "--log", d][..], "--sines -2"),
        (
            &["--sines", "1,2", "--log", d, "--port", "/dev/null"][..],
            "in-process",
        ),
    ] {
        let mut all = vec!["pil", "--linkage", "delta"];
        all.extend(args);
        let e = tool.failure(&all);
        assert!(e.contains(want), "{args:?}: {e}");
    }
    let e = tool.failure(&["pil", "--sines", "1,2", "--log", d]);
    assert!(e.contains("--linkage"), "{e}");
    std::fs::remove_dir_all(dir).unwrap();
}

/// The PHANToM's shoulder and elbow come apart with a second frequency.
/// At 10 Hz every push turns them in nearly one proportion; at 4 Hz, the
/// hold's own resonance along the reach, in another. The 10 Hz sines
/// (0.5, 1 and 1.5 N) and 4 Hz ones (0.3, 0.6 and 0.9 N) together, the
/// joints' friction acting, give each joint's damping within 25% and its
/// standard deviation within a fifth of it (the 10 Hz sines alone leave
/// the shoulder's at 120%), and friction within 3%. A hands-off design
/// then rests on the fit: over the whole workspace, with each joint's
/// damping three deviations down, it is proven no stiffer than the
/// truth's certificate, and at the calibration pose the fit's is within
/// 20% of the truth's and `verify` finds nothing at the set's.
#[test]
#[cfg_attr(debug_assertions, ignore = "release only (CI runs it)")]
fn the_phantoms_joints_come_apart_at_two_frequencies() {
    use twoport_design::linkage::certified_design;
    use twoport_identify::pose::losses;
    const SKIP: usize = 8;
    let device = LinkageImage::SerialArm;
    let file = device.file().unwrap();
    let truth = truth(device);
    let records: Vec<Vec<Log>> = [(10.0, [0.5, 1.0, 1.5]), (4.0, [0.3, 0.6, 0.9])]
        .into_iter()
        .flat_map(|(hz, levels)| {
            Sines {
                hz,
                periods: 24,
                levels_n: levels.to_vec(),
                hold: (100.0, 1.0),
                friction: true,
            }
            .play(device)
            .unwrap()
            .concat()
        })
        .collect();
    let l = losses::fit(&records, &along(device), SKIP).unwrap();
    let want = &file.joints.damping_nmsprad;
    for (i, (b, w)) in l.damping_nmsprad.iter().zip(want).enumerate() {
        assert!((b / w - 1.0).abs() < 0.25, "joint {i}: {l:?}");
        assert!(l.sd[i] < 0.2 * w, "joint {i}: {l:?}");
    }
    for (c, w) in l.friction_nm.iter().zip(&file.joints.friction_nm) {
        assert!((c / w - 1.0).abs() < 0.03, "{l:?}");
    }
    // Hands off over the workspace, each joint's damping three deviations
    // down.
    let mut down = file.clone();
    down.joints.damping_nmsprad = l
        .damping_nmsprad
        .iter()
        .zip(&l.sd)
        .map(|(b, s)| (b - 3.0 * s).max(0.0))
        .collect();
    let hands_off = |f: &twoport_design::linkage::LinkageFile| {
        certified_design(f, 0.0, 0.0, Some(HumanBound::PAPER))
            .unwrap()
            .k_c_npm
    };
    let (k_file, k_down) = (hands_off(&file), hands_off(&down));
    assert!(
        k_down <= k_file && k_down > 0.3 * k_file,
        "{k_down} against {k_file}"
    );
    // At the calibration pose.
    let d = l.damping_nspm(&truth.jacobian, 0.0).unwrap();
    let d_set = l.damping_nspm(&truth.jacobian, 3.0).unwrap();
    let at = |d: &DMatrix<f64>| design(device, &[truth.with_body(&truth.mass_kg, d)], 0.0);
    let (k_true, k_fit, k_set) = (
        design(device, std::slice::from_ref(&truth), 0.0),
        at(&d),
        at(&d_set),
    );
    assert!(
        (k_fit / k_true - 1.0).abs() < 0.2,
        "{k_fit} against {k_true}"
    );
    assert!(k_set <= k_true, "{k_set} against {k_true}");
    let hands = HandAssumption {
        min_grasp_nspm: 0.0,
        human: Some(HumanBound::PAPER),
    };
    let v = verify_linkage(&[&truth], &hands, (k_set, 0.0), (file.period_s, Lag::NONE)).unwrap();
    assert!(!v.unstable, "{v}");
    eprintln!(
        "PHANToM at two frequencies: joints' damping {:?} ± {:?} N m s/rad (true {want:?}), \
         friction {:?} N m, misfit {:.4}; hands off over the workspace: file {k_file:.4}, three \
         deviations down {k_down:.4} N/m; at the pose: true {k_true:.3}, fit {k_fit:.3}, set \
         {k_set:.3} N/m, verify on the truth at the set's: radius {}",
        l.damping_nmsprad,
        &l.sd[..3],
        l.friction_nm,
        l.misfit,
        v.spectral_radius
    );
}
