//! The Python package: built by maturin as one abi3 wheel, installed into
//! a virtual environment of its own with its test dependencies (from
//! PyPI), and tested there with pytest. `overhead` times a design call
//! from Python against the same work from Rust.

use crate::{cargo, root, run, target_dir};
use std::path::{Path, PathBuf};
use std::process::Command;

/// The tools the step installs into its environment (dask: the campaign
/// example, across processes).
const TOOLS: [&str; 4] = ["maturin>=1.5,<2", "pytest", "numpy", "dask"];

/// Build the wheel, install it, run `crates/python/tests`, then the wall
/// example (`crates/python/examples/wall.py`) against the free-running
/// board in QEMU (home, arm, a wall from Python at 1 kHz, disarm) and
/// against a Touch opened by name through the stand-in HD library.
pub(crate) fn python() -> Result<(), String> {
    let bin = wheel()?;
    run(
        "pytest crates/python/tests",
        Command::new(bin.join("python")).current_dir(root()).args([
            "-m",
            "pytest",
            "-q",
            "crates/python/tests",
        ]),
    )?;
    let elf = crate::firmware::an386_image_with("sim-device")?;
    let wall = root().join("crates/python/examples/wall.py");
    crate::emulate::with_device(&elf, |pty| {
        run(
            "the Python example against the free-running board",
            Command::new(bin.join("python")).arg(&wall).arg(pty),
        )
    })?;
    let (_, standin) = crate::emulate::touch_standin()?;
    run(
        "the Python example opening a Touch by name (the stand-in HD library)",
        Command::new(bin.join("python"))
            .arg(&wall)
            .args(["--device", "touch", ""])
            .arg(&standin),
    )
}

/// The environment with the package's wheel built and installed; its
/// `bin` folder.
fn wheel() -> Result<PathBuf, String> {
    let venv = target_dir().join("python-venv");
    let bin = venv.join("bin");
    if !bin.join("python").exists() {
        run(
            "a Python environment for the package (python3 -m venv)",
            Command::new("python3").arg("-m").arg("venv").arg(&venv),
        )?;
    }
    run(
        "maturin, pytest and numpy into it (pip)",
        Command::new(bin.join("pip"))
            .args(["install", "-q", "--disable-pip-version-check"])
            .args(TOOLS),
    )?;
    let wheels: PathBuf = target_dir().join("wheels");
    let _ = std::fs::remove_dir_all(&wheels);
    run(
        "build the wheel (maturin, release, abi3)",
        Command::new(bin.join("maturin"))
            .current_dir(root())
            .args([
                "build",
                "--release",
                "-q",
                "-m",
                "crates/python/Cargo.toml",
                "-o",
            ])
            .arg(&wheels),
    )?;
    let wheel = std::fs::read_dir(&wheels)
        .map_err(|e| format!("{}: {e}", wheels.display()))?
        .filter_map(Result::ok)
        .map(|e| e.path())
        .find(|p| p.extension().is_some_and(|x| x == "whl"))
        .ok_or("maturin wrote no wheel")?;
    run(
        "install the wheel",
        Command::new(bin.join("pip"))
            .args([
                "install",
                "-q",
                "--force-reinstall",
                "--no-deps",
                "--disable-pip-version-check",
            ])
            .arg(&wheel),
    )?;
    Ok(bin)
}

/// `twoport.design_impedance` on the Excalibur's model from Python against
/// the same work from Rust (`crates/design/examples/design_call.rs`), each
/// timed the same way in its own process, in turns for `rounds` rounds so
/// both see the same machine; the ratio of their medians.
pub(crate) fn overhead(rounds: u32) -> Result<(), String> {
    let bin = wheel()?;
    run(
        "the Rust side (design_call, release)",
        cargo().args([
            "build",
            "--release",
            "-q",
            "-p",
            "twoport-design",
            "--example",
            "design_call",
        ]),
    )?;
    let model = root().join("models").join("excalibur.toml");
    let rust = target_dir()
        .join("release")
        .join("examples")
        .join("design_call");
    let script = root().join("crates/python/examples/overhead.py");
    let (mut from_rust, mut from_python) = (Vec::new(), Vec::new());
    for round in 1..=rounds {
        let r = median_of(Command::new(&rust).arg(&model))?;
        let p = median_of(Command::new(bin.join("python")).arg(&script).arg(&model))?;
        eprintln!(
            "xtask: round {round}: Rust {:.3} ms, Python {:.3} ms",
            r * 1e3,
            p * 1e3
        );
        from_rust.push(r);
        from_python.push(p);
    }
    let (r, p) = (median(&mut from_rust), median(&mut from_python));
    println!(
        "design_impedance(excalibur, b 90): Rust {:.3} ms, Python {:.3} ms, Python/Rust {:.3} (median of {rounds} rounds)",
        r * 1e3,
        p * 1e3,
        p / r
    );
    Ok(())
}

/// The `median_s` a timing program prints.
fn median_of(cmd: &mut Command) -> Result<f64, String> {
    let what = Path::new(cmd.get_program()).display().to_string();
    let out = cmd
        .output()
        .map_err(|e| format!("{what}: could not start: {e}"))?;
    if !out.status.success() {
        return Err(format!(
            "{what}: failed ({}): {}",
            out.status,
            String::from_utf8_lossy(&out.stderr)
        ));
    }
    let text = String::from_utf8_lossy(&out.stdout);
    text.lines()
        .find_map(|l| l.strip_prefix("median_s "))
        .ok_or_else(|| format!("{what}: printed no median_s line: {text}"))?
        .trim()
        .parse::<f64>()
        .map_err(|e| format!("{what}: median_s: {e}"))
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}
