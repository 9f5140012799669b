//! The Python package: built by maturin as one abi3 wheel, installed into
//! a virtual environment of its own with its test dependencies (from
//! PyPI), and tested there with pytest.

use crate::{root, run, target_dir};
use std::path::PathBuf;
use std::process::Command;

/// The tools the step installs into its environment.
const TOOLS: [&str; 3] = ["maturin>=1.5,<2", "pytest", "numpy"];

/// Build the wheel, install it, run `crates/python/tests`.
pub(crate) fn python() -> Result<(), String> {
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
    run(
        "pytest crates/python/tests",
        Command::new(bin.join("python")).current_dir(root()).args([
            "-m",
            "pytest",
            "-q",
            "crates/python/tests",
        ]),
    )
}
