//! Every device in `models/` is designed, checked by `verify` (nothing at
//! the design, a counterexample 20% past it) and run in the time domain: the
//! README's table of shipped devices, row by row.

use host_sim::engine::scene::Coupling;
use host_sim::{Scene, Simulation};
use std::path::Path;
use twoport_control::{Gains, ImpedanceGains};
use twoport_design::analysis::*;
use twoport_design::network::HumanBound;
use twoport_design::verify::verify;
use twoport_design::DeviceModel;

const T: f64 = 1e-3;

fn root() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/.."))
}

/// Each shipped model with the scene that runs it.
const DEVICES: [(&str, &str); 3] = [
    ("models/excalibur.toml", "scenes/stiff_wall.toml"),
    ("models/capstan.toml", "scenes/devices/capstan_wall.toml"),
    ("models/two_mass.toml", "scenes/devices/two_mass_wall.toml"),
];

#[test]
fn every_model_has_a_scene_here() {
    let mut shipped: Vec<String> = std::fs::read_dir(root().join("models"))
        .unwrap()
        .map(|e| format!("models/{}", e.unwrap().file_name().to_string_lossy()))
        .filter(|p| p.ends_with(".toml"))
        .collect();
    shipped.sort();
    let mut listed: Vec<String> = DEVICES.iter().map(|d| d.0.to_string()).collect();
    listed.sort();
    assert_eq!(shipped, listed, "a new model needs a row here and a scene");
}

/// The impedance design with and without the human bound; verify finds
/// nothing at it and breaks 1.01 times its stiffness: on every shipped
/// device the bound is tight to 1%.
#[test]
#[ignore = "release only: run with --release --ignored (CI does)"]
fn every_device_design_survives_verify_and_breaks_past_it() {
    for (model, _) in DEVICES {
        let m = DeviceModel::load(&root().join(model)).unwrap();
        let a = Analysis::of(&m).unwrap();
        for human in [Some(HumanBound::PAPER), None] {
            let (k, b) = best_impedance(&a, &a.impedance_bound(human)).unwrap();
            let g = |k_npm| Gains::from(ImpedanceGains::new(k_npm as f32, b as f32));
            let at = verify(&m, T, &g(k), human).unwrap();
            assert!(!at.unstable, "{model} {human:?}: ({k}, {b}) broken: {at:?}");
            let past = verify(&m, T, &g(1.01 * k), human).unwrap();
            assert!(
                past.unstable,
                "{model} {human:?}: 1.01 x ({k}, {b}): {past:?}"
            );
        }
    }
}

/// Each device's scene runs gains the designer proves, and runs stably.
#[test]
#[ignore = "release only: run with --release --ignored (CI does)"]
fn every_device_scene_is_proven_and_stable() {
    for (model, scene) in DEVICES {
        let s = Scene::load(&root().join(scene), &[]).unwrap();
        let m = DeviceModel::load(&root().join(model)).unwrap();
        assert_eq!(
            s.plant.model.file_name(),
            Path::new(model).file_name(),
            "{scene} runs {model}"
        );
        let a = Analysis::of(&m).unwrap();
        let Coupling::Impedance { k, b } = s.coupling else {
            panic!("{scene}: an impedance coupling");
        };
        let c = check_impedance(&a, k, b, Some(HumanBound::PAPER)).unwrap();
        assert!(c.absolutely_stable, "{scene}: {c:?}");
        let mut s = s;
        s.plant.model = root().join(model);
        let r = Simulation::new(s).unwrap().run(|_| {});
        assert!(r.stable, "{scene}: {r:?}");
    }
}
