//! The chain closed in simulation: the board plays its experiment on a
//! device (processor in the loop, in-process) with a 1 um encoder,
//! Coulomb friction and cogging (and, on the Excalibur and the two-mass
//! device, a noisy load-cell ADC) that no fit is told of; its record goes
//! through CSV, the fit chooses the model, the design on that model is the true model's, and
//! the design proven for the set that spans the fit's uncertainty holds
//! for the true device: `verify` finds nothing there.

use host_sim::link::{LinkFaults, LocalBoard};
use host_sim::{pil, Scene};
use std::f64::consts::TAU;
use std::path::Path;
use twoport_control::{AdmittanceGains, Gains, ImpedanceGains};
use twoport_design::network::HumanBound;
use twoport_design::{Designer, DeviceModel, Plant};
use twoport_identify::fit::uncertainty::{span, Doubt};
use twoport_identify::fit::{self, chain::ModelBase, Fit, Measured};
use twoport_identify::log::Log;

fn impedance_k(models: Vec<DeviceModel>, b: f64) -> f64 {
    Designer::new(models, None, Some(HumanBound::PAPER))
        .unwrap()
        .design_impedance(Some(b), 0.0)
        .unwrap()
        .coupling
        .unwrap()
        .0
}

fn resonances_hz(m: &DeviceModel) -> Vec<f64> {
    Plant::new(m, m.period_s)
        .unwrap()
        .modes()
        .iter()
        .map(|m| m.omega_n / TAU)
        .filter(|f| *f < 500.0)
        .collect()
}

/// The admittance display: the regulator `(k_p, b_p)` and the coupling's
/// damping `b` (N/m, N s/m, N s/m).
#[derive(Clone, Copy)]
struct Admittance {
    regulator: (f64, f64),
    b: f64,
}

/// The admittance design's coupling mass (kg).
fn admittance_m(models: Vec<DeviceModel>, a: Admittance) -> f64 {
    Designer::new(models, None, Some(HumanBound::PAPER))
        .unwrap()
        .design_admittance(Some(a.regulator), Some(a.b), 0.0)
        .unwrap()
        .coupling
        .unwrap()
        .0
}

/// The scene's experiment, with `handle_kg` clamped on the handle (0 for
/// none), run on the Excalibur's board image against the scene's plant,
/// through its CSV record to what it measured.
fn measured(scene: &str, model: &str, truth: &DeviceModel, handle_kg: f64) -> Measured {
    // (Two periods skipped while the hold's mode settles.)
    Measured::from_log(&record(scene, model, truth, handle_kg), 2).unwrap()
}

/// [`measured`]'s CSV record, read back.
fn record(scene: &str, model: &str, truth: &DeviceModel, handle_kg: f64) -> Log {
    // (Paths in scenes are the repository root's; tests run in host-sim.)
    let sets = [
        format!("plant.model=\"../{model}\""),
        format!("plant.handle_mass_kg={handle_kg:?}"),
    ];
    let scene = Scene::load(Path::new(scene), &sets).unwrap();
    let ticks = (scene.duration_s / 1e-3).round() as u64;
    let r = pil::run(
        scene,
        ticks,
        LocalBoard::excalibur().unwrap(),
        LinkFaults::default(),
    )
    .unwrap();
    let csv = r
        .experiment_log(truth.force_sensor)
        .unwrap()
        .unwrap()
        .to_csv();
    let log = Log::from_csv(&csv, "record.csv").unwrap();
    // A 30 s experiment: thirty 1 s periods.
    assert_eq!(log.force_n.len(), 30_000);
    log
}

/// The Excalibur's record with its force's sign turned (the commonest
/// mistake with an amplifier) or its encoder's: named as a reversed sign
/// before any fit, so no model is made from it.
#[test]
#[cfg_attr(debug_assertions, ignore = "release only (CI runs it)")]
fn a_record_with_a_reversed_sign_is_named_not_fitted() {
    let truth = DeviceModel::load(Path::new("../models/excalibur.toml")).unwrap();
    let log = record(
        "../scenes/identify/excalibur.toml",
        "models/excalibur.toml",
        &truth,
        0.0,
    );
    let force = Log {
        force_n: log.force_n.iter().map(|f| -f).collect(),
        ..log.clone()
    };
    let encoder = Log {
        position_m: log.position_m.iter().map(|x| -x).collect(),
        ..log
    };
    for turned in [force, encoder] {
        let e = Measured::from_log(&turned, 2).unwrap_err();
        assert!(
            matches!(e, twoport_identify::IdentifyError::ReversedSign { .. }),
            "{e}"
        );
    }
}

/// The scene's experiment through to the chosen fit; with `loaded`, the
/// same experiment again with that mass (kg) on the handle, fitted with it.
fn identified(scene: &str, model: &str, truth: &DeviceModel, loaded: Option<f64>) -> Fit {
    let mut data = measured(scene, model, truth, 0.0);
    if let Some(kg) = loaded {
        data = data
            .with_loaded(kg, measured(scene, model, truth, kg))
            .unwrap();
    }
    let base = ModelBase {
        name: format!("identified {}", truth.name),
        period_s: 1e-3,
        peak_force_n: truth.peak_force_n,
        continuous_force_n: truth.continuous_force_n,
        load_cell_pole_rad_s: truth.force_sensor.then_some(truth.load_cell_pole_rad_s),
    };
    let (mut fits, best) = fit::fit_orders(&data, &base);
    fits.swap_remove(best.unwrap())
}

/// What each device must show: its modes in the band, its resonances
/// within 2%, the identified model's impedance design at `b` within 3% of
/// the true model's, the robust design no stiffer than the truth's and
/// `verify` silent on the true model there, and the friction and the
/// cogging (`cogging_n`, every 2 mm) found. With
/// an `admittance` display, its design too: within 3% of the truth's, the
/// robust one no lighter, and `verify` silent on the true model there.
/// `loaded` is the mass (kg) on the handle of a second, loaded record.
fn closes(
    model: &str,
    modes: usize,
    b: f64,
    friction: (f64, f64),
    cogging_n: Option<f64>,
    admittance: Option<Admittance>,
    loaded: Option<f64>,
) {
    let device = Path::new(model).file_stem().unwrap().to_str().unwrap();
    let truth = DeviceModel::load(Path::new(&format!("../{model}"))).unwrap();
    let scene = format!("../scenes/identify/{device}.toml");
    let f = identified(&scene, model, &truth, loaded);
    assert_eq!(f.loaded, loaded.is_some());
    assert_eq!(f.form.modes(), modes, "{:?}", f.form);
    let (want, got) = (resonances_hz(&truth), resonances_hz(&f.model));
    assert_eq!(want.len(), got.len(), "{got:?} against {want:?}");
    for (w, g) in want.iter().zip(&got) {
        assert!((g / w - 1.0).abs() < 0.02, "{got:?} against {want:?}");
    }
    let k_true = impedance_k(vec![truth.clone()], b);
    let k_fit = impedance_k(vec![f.model.clone()], b);
    assert!(
        (k_fit / k_true - 1.0).abs() < 0.03,
        "{k_fit} against {k_true}"
    );
    let set: Vec<DeviceModel> = span(&f, Doubt::default())
        .unwrap()
        .into_iter()
        .map(|m| m.model)
        .collect();
    let k_robust = impedance_k(set.clone(), b);
    assert!(k_robust <= k_true, "{k_robust} against {k_true}");
    let on_truth = |g: Gains| {
        Designer::new(vec![truth.clone()], None, Some(HumanBound::PAPER))
            .unwrap()
            .verify(&g)
            .unwrap()
            .verdict
    };
    let verdict = on_truth(Gains::Impedance(ImpedanceGains {
        k_npm: k_robust as f32,
        b_nspm: b as f32,
    }));
    assert!(!verdict.unstable, "{verdict:?}");
    if let Some(a) = admittance {
        let m_true = admittance_m(vec![truth.clone()], a);
        let m_fit = admittance_m(vec![f.model.clone()], a);
        assert!(
            (m_fit / m_true - 1.0).abs() < 0.03,
            "{m_fit} against {m_true}"
        );
        let m_robust = admittance_m(set, a);
        assert!(m_robust >= m_true, "{m_robust} against {m_true}");
        let v = on_truth(Gains::Admittance(AdmittanceGains::new(
            a.regulator.0 as f32,
            a.regulator.1 as f32,
            m_robust as f32,
            a.b as f32,
        )));
        assert!(!v.unstable, "{v:?}");
        eprintln!(
            "{scene}: m at {} N s/m: true {m_true:.4}, fit {m_fit:.4}, robust \
             {m_robust:.4}; verify on the truth: radius {}",
            a.b, v.spectral_radius
        );
    }
    let coulomb = f.model.coulomb_friction_n.unwrap();
    assert!((friction.0..friction.1).contains(&coulomb), "{coulomb} N");
    // Each scene's cogging: 2 mm of travel a period. Where the scene has
    // none, the search may still take up a little of what the band's
    // smooth terms leave (the belt drive: 0.008 N), never a fifth of the
    // friction.
    let none = twoport_identify::fit::cogging::Found {
        amplitude_n: 0.0,
        period_m: 0.0,
    };
    let c = match (cogging_n, f.cogging) {
        (Some(n), Some(c)) => {
            assert!((c.amplitude_n / n - 1.0).abs() < 0.15, "{c:?}");
            assert!((c.period_m / 2e-3 - 1.0).abs() < 0.05, "{c:?}");
            c
        }
        (None, None) => none,
        (None, Some(c)) => {
            assert!(c.amplitude_n < 0.2 * coulomb, "{c:?} beside {coulomb} N");
            c
        }
        (want, got) => panic!("cogging {want:?} N, found {got:?}"),
    };
    let q = f.model.encoder_quantum_m.unwrap();
    assert!((q / 1e-6 - 1.0).abs() < 1e-6, "{q} m");
    eprintln!(
        "{scene}: resonances {got:?} (true {want:?}); k at {b} N s/m: true {k_true:.0}, \
         fit {k_fit:.0}, robust {k_robust:.0}; verify on the truth: radius {}; friction {coulomb:.3} N; \
         cogging {:.4} N every {:.4} mm",
        verdict.spectral_radius,
        c.amplitude_n,
        c.period_m * 1e3
    );
}

/// The flexible Excalibur with its load cell: three modes in the band, at
/// 90 N s/m (the true model's 51,073 N/m). The plant's 0.2 N friction is
/// smoothed over 1 mm/s, so it pushes less at the slow end of the motion.
#[test]
#[cfg_attr(debug_assertions, ignore = "release only (CI runs it)")]
fn the_excalibur_is_identified_from_its_experiment() {
    let paper = Admittance {
        regulator: (51_000.0, 90.0),
        b: 500.0,
    };
    closes(
        "models/excalibur.toml",
        3,
        90.0,
        (0.1, 0.3),
        Some(0.05),
        Some(paper),
        Some(0.5),
    );
}

/// The capstan handle, one rigid body read by its encoder alone, at its
/// best damping (147.9 N s/m, the true model's 27,885 N/m).
#[test]
#[cfg_attr(debug_assertions, ignore = "release only (CI runs it)")]
fn the_capstan_is_identified_from_its_experiment() {
    closes(
        "models/capstan.toml",
        0,
        147.9,
        (0.03, 0.06),
        Some(0.01),
        None,
        None,
    );
}

/// The two-mass device, whose load cell is its one flexure: one mode, at
/// its best damping (302.5 N s/m, the true model's 109,053 N/m).
#[test]
#[cfg_attr(debug_assertions, ignore = "release only (CI runs it)")]
fn the_two_mass_device_is_identified_from_its_experiment() {
    let a = Admittance {
        regulator: (109_054.0, 302.5),
        b: 5_000.0,
    };
    closes(
        "models/two_mass.toml",
        1,
        302.5,
        (0.07, 0.12),
        Some(0.02),
        Some(a),
        None,
    );
}

/// A voice-coil handle on a centring spring (a free chain could not hold
/// it): held to the frame in the fit, its flexure's mode found, at 2 N s/m.
#[test]
#[cfg_attr(debug_assertions, ignore = "release only (CI runs it)")]
fn a_handle_on_a_centring_spring_is_identified_from_its_experiment() {
    closes(
        "models/bench/centring.toml",
        1,
        2.0,
        (0.01, 0.03),
        None,
        None,
        None,
    );
}

/// A handle on a flexure to the frame, past a cable from the motor.
#[test]
#[cfg_attr(debug_assertions, ignore = "release only (CI runs it)")]
fn a_handle_on_a_flexure_to_the_frame_is_identified_from_its_experiment() {
    closes(
        "models/bench/grounded_flexure.toml",
        1,
        2.0,
        (0.02, 0.04),
        None,
        None,
        None,
    );
}

/// A belt drive with its load cell past the belt's mode: the device's
/// modes as the two sensors see them.
#[test]
#[cfg_attr(debug_assertions, ignore = "release only (CI runs it)")]
fn a_belt_drive_with_its_load_cell_past_the_belt_is_identified_from_its_experiment() {
    closes(
        "models/bench/noncollocated.toml",
        1,
        2.0,
        (0.035, 0.065),
        None,
        None,
        None,
    );
}

/// Two modes 5% apart, an antiresonance between them: both found, at
/// the true model's best damping (1 N s/m, 1,552 N/m). (At 2 N s/m the
/// design leans on the 9.5 g handle's own damping, a hundredth of a N s/m
/// the encoder barely sees, and the fit's is 4% stiff.)
#[test]
#[cfg_attr(debug_assertions, ignore = "release only (CI runs it)")]
fn two_modes_five_percent_apart_are_identified_from_their_experiment() {
    closes(
        "models/bench/close_modes.toml",
        2,
        1.0,
        (0.01, 0.03),
        None,
        None,
        None,
    );
}
