//! Any text as a scene: a clear error, or a scene that builds and runs 100
//! ticks; never a panic.
#![no_main]

use host_sim::{Scene, Simulation};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(scene) = Scene::parse(text, "fuzz", &[]) {
        if scene.integrator.substeps > 64 {
            return; // legal, but slow: not what this target is for
        }
        match scene.axes {
            1 => run::<1>(scene),
            2 => run::<2>(scene),
            _ => run::<3>(scene),
        }
    }
});

/// A hundred ticks of a scene of `N` axes, if it builds.
fn run<const N: usize>(scene: Scene) {
    if let Ok(mut sim) = Simulation::<N>::with_axes(scene) {
        for _ in 0..100.min(sim.total_ticks()) {
            sim.step();
        }
    }
}
