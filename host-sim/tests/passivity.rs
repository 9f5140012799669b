//! The passivity scenes: what the layer is for, checked by the simulator's
//! own stability criterion (independent of the layer's energy books).
//!
//! - An explicitly integrated cursor, a coupling at 4x the proven stiffness
//!   and an element 5 (and 1) ticks late are unstable with the layer off and
//!   stable with it on.
//! - At 2x the proven stiffness the loop is stable alone; the layer never
//!   acts there, and the run is the same to the bit with it on or off.

use host_sim::study::passivity;
use host_sim::{Scene, Simulation};
use std::path::Path;

const DIR: &str = "../scenes/passivity";

fn forces(scene: &str, sets: &[&str]) -> (bool, Vec<u64>) {
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    let s = Scene::load(&Path::new(DIR).join(scene), &sets).unwrap();
    let mut f = Vec::new();
    let r = Simulation::new(s)
        .unwrap()
        .run(|s| f.push(s.actuator_n[0].to_bits()));
    (r.stable, f)
}

#[test]
fn the_layer_stabilises_what_the_proof_does_not_cover() {
    for scene in [
        "explicit_cursor.toml",
        "stiff_wall_4x.toml",
        "delayed_wall.toml",
    ] {
        let r = passivity::row(&Path::new(DIR).join(scene)).unwrap();
        assert!(!r.off.stable, "{scene}: stable without the layer");
        assert!(r.on.stable, "{scene}: {:?}", r.on.reason);
        assert!(r.dissipated_j > 0.0 && r.active_ticks > 0, "{scene}");
    }
    let one = ["effects.element_delay.ticks=1"];
    let (off, _) = forces(
        "delayed_wall.toml",
        &[&one[..], &["passivity.enabled=false"]].concat(),
    );
    let (on, _) = forces("delayed_wall.toml", &one);
    assert!(
        !off && on,
        "one tick late: off stable {off}, on stable {on}"
    );
}

#[test]
fn where_the_loop_is_passive_the_layer_changes_no_bit() {
    let (stable_off, off) = forces("stiff_wall_2x.toml", &["passivity.enabled=false"]);
    let (stable_on, on) = forces("stiff_wall_2x.toml", &[]);
    assert!(stable_off && stable_on);
    assert_eq!(off.len(), on.len());
    assert!(off == on, "the layer changed the force");
    let r = passivity::row(&Path::new(DIR).join("stiff_wall_2x.toml")).unwrap();
    assert_eq!(r.active_ticks, 0);
}

#[test]
fn a_bad_passivity_table_is_named() {
    let path = Path::new(DIR).join("stiff_wall_2x.toml");
    for (set, says) in [
        ("passivity.mass_kg=-1", "passivity.mass_kg"),
        ("passivity.port=\"ve\"", "passivity.port"),
        (
            "passivity.device_damping_nspm=nan",
            "passivity.device_damping_nspm",
        ),
    ] {
        let e = Scene::load(&path, &[set.to_string()])
            .unwrap_err()
            .to_string();
        assert!(e.contains(says), "{set}: {e}");
    }
}
