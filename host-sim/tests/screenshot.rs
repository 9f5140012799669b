//! The scope in a real window, as CI sees it: under Xvfb, the default scene
//! for three seconds, two screenshots. The window must not be blank and the
//! plots must have moved between the shots while the controls did not.
#![cfg(feature = "gui")]

use image::RgbaImage;
use std::path::Path;
use std::process::Command;

fn load(p: &Path) -> RgbaImage {
    image::open(p)
        .unwrap_or_else(|e| panic!("{}: {e}", p.display()))
        .to_rgba8()
}

/// Fraction of pixels in `[x0, x1) x [y0, y1)` that differ.
fn changed(a: &RgbaImage, b: &RgbaImage, (x0, x1): (u32, u32), (y0, y1): (u32, u32)) -> f64 {
    let mut n = 0u64;
    for y in y0..y1 {
        for x in x0..x1 {
            if a.get_pixel(x, y) != b.get_pixel(x, y) {
                n += 1;
            }
        }
    }
    n as f64 / ((x1 - x0) as f64 * (y1 - y0) as f64)
}

/// The scope on `scene` (under `scenes/`) in Xvfb for `seconds`: its
/// folder, and the shots at half-time and at the end.
fn shots(scene: &str, seconds: u32) -> (std::path::PathBuf, RgbaImage, RgbaImage) {
    let name = scene.replace(['/', '.'], "-");
    let dir = std::env::temp_dir().join(format!("twoport-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("shot.png");
    // (From the repository's root, where scenes name their model files.)
    let status = Command::new("xvfb-run")
        .current_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join(".."))
        .args(["-a", "-s", "-screen 0 1400x900x24"])
        .arg(env!("CARGO_BIN_EXE_host-sim"))
        .arg("--scene")
        .arg(
            Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../scenes")
                .join(scene),
        )
        .arg("--screenshot")
        .arg(&out)
        .args(["--exit-after", &seconds.to_string()])
        .status()
        .expect("xvfb-run runs (install xvfb)");
    assert!(status.success(), "host-sim under Xvfb: {status}");
    let first = load(&host_sim::scope::window::first_shot_path(&out));
    (dir, first, load(&out))
}

#[test]
#[ignore = "needs xvfb-run (CI installs xvfb); run with --ignored"]
fn the_scope_draws_and_its_plots_move() {
    let (dir, first, last) = shots("stiff_wall.toml", 3);
    assert_eq!(first.dimensions(), last.dimensions());
    let (w, h) = last.dimensions();
    assert!(w >= 800 && h >= 600, "{w} x {h}");
    // Not blank: many distinct colours (text, traces, light, grid).
    let colours = distinct_colours(&last);
    assert!(colours > 50, "{colours} colours");
    // The plot area (left of the 330-pt control panel, below the transport
    // bar) moved; the control panel's lower half (hand, wall, trigger,
    // board) did not.
    let plots = changed(&first, &last, (40, w - 400), (40, h - 20));
    assert!(plots > 0.01, "plot area changed by {:.4}", plots);
    let controls = changed(&first, &last, (w - 340, w), (h / 2, h));
    assert!(
        controls < plots,
        "controls {controls:.4} vs plots {plots:.4}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The three-axis scope under Xvfb: the stacking scene for three seconds.
/// The world view is drawn (blocks, cursor, the force plot) and the cursor
/// and the block it carries moved between the two shots.
#[test]
#[ignore = "needs xvfb-run (CI installs xvfb); run with --ignored"]
fn the_world_view_draws_and_its_blocks_move() {
    let (dir, first, last) = shots("xyz/stack_three.toml", 6);
    let (w, h) = last.dimensions();
    let colours = distinct_colours(&last);
    assert!(colours > 30, "{colours} colours");
    // The projections (the upper half) changed: the block was carried.
    let world = changed(&first, &last, (0, w), (60, h / 2));
    assert!(world > 0.001, "world view changed by {world:.4}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A teleoperation scene under Xvfb: both devices' positions and forces
/// are drawn on one time axis, and they moved between the two shots
/// while the heading and the controls did not.
#[test]
#[ignore = "needs xvfb-run (CI installs xvfb); run with --ignored"]
fn the_scope_shows_both_sides_of_a_teleoperator() {
    let (dir, first, last) = shots("teleop/capstan_wall.toml", 3);
    let (w, h) = last.dimensions();
    let colours = distinct_colours(&last);
    assert!(colours > 50, "{colours} colours");
    // Each device has its colour: the master's blue and the slave's red
    // traces are both drawn.
    let near = |c: [u8; 3]| {
        last.pixels()
            .filter(|p| (0..3).all(|i| p.0[i].abs_diff(c[i]) < 12))
            .count()
    };
    assert!(near([31, 119, 180]) > 200 && near([214, 39, 40]) > 200);
    let plots = changed(&first, &last, (60, w - 20), (80, h - 20));
    assert!(plots > 0.01, "plot area changed by {plots:.4}");
    let heading = changed(&first, &last, (0, w / 2), (0, 20));
    assert!(heading < 0.001, "heading changed by {heading:.4}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// How many distinct colours `shot` has: many where text, traces, light
/// and grid are drawn, few where a window is blank.
fn distinct_colours(shot: &RgbaImage) -> usize {
    let mut colours: Vec<[u8; 4]> = shot.pixels().map(|p| p.0).collect();
    colours.sort_unstable();
    colours.dedup();
    colours.len()
}
