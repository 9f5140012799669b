//! `cargo xtask <task>`: the project's build, emulate and check tasks.
//!
//! - `ci [step...]`: everything CI checks, as named steps (fmt, clippy,
//!   doc, the M4F build, the probe, processor in the loop, the watchdog,
//!   fuzzing, the tests), or only the steps named; each step's time is
//!   printed at the end.
//! - `thumb`: build `twoport-control` for thumbv7em-none-eabihf.
//! - `firmware`: build the firmware workspace.
//! - `qemu`: build and run the on-target tests in QEMU mps2-an386.
//! - `pil [--board an386|stm32f405] [host-sim pil options]`:
//!   processor-in-the-loop, a board image in QEMU against host-sim's plant
//!   over `-serial pty` (e.g. `--json`, `--seconds 4`, `--link-loss-at-s 3`,
//!   `--fast` for the 4 kHz image, `--host-ve-hz 1000` for a VE on the host,
//!   `--check`, `--passivity`).
//! - `scope-board`: the scope's board mode against the firmware in QEMU.
//! - `watchdog`: hang the an386 image's loop on purpose; the watchdog
//!   resets it and it comes back disarmed with the reset as a fault.
//! - `python`: build the wheel into a venv of its own and run pytest.
//! - `overhead [rounds]`: a design call from Python against the same work
//!   from Rust, in turns (default 7 rounds); the ratio.
//! - `fuzz [seconds]`: build and run each fuzz target (default 60 s each).
//! - `accuracy`: regenerate docs/accuracy.md and docs/accuracy.png.

mod ci;
mod counts;
mod emulate;
mod firmware;
mod fuzz;
mod header;
mod probe;
mod python;
mod toolchain;

use std::path::PathBuf;
use std::process::{Command, ExitCode};

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let result = match args.first().map(String::as_str) {
        Some("ci") => ci::ci(&args[1..]),
        Some("thumb") => firmware::thumb(),
        Some("firmware") => firmware::firmware().map(|_| ()),
        Some("qemu") => probe::qemu(),
        Some("pil") => emulate::pil(&args[1..]),
        Some("watchdog") => emulate::watchdog(),
        Some("scope-board") => emulate::scope_board(),
        Some("device") => emulate::device(&args[1..]),
        Some("python") => python::python(),
        Some("overhead") => args.get(1).map_or(Ok(7), |s| {
            s.parse::<u32>()
                .ok()
                .filter(|&n| n > 0)
                .ok_or(format!("rounds: {s:?} is not a positive whole number"))
        })
        .and_then(python::overhead),
        Some("header") => header::header(args.get(1).is_some_and(|a| a == "--check")),
        Some("fuzz") => {
            let secs = args.get(1).map_or(Ok(60), |s| {
                s.parse::<u32>().map_err(|e| format!("seconds: {e}"))
            });
            secs.and_then(fuzz::fuzz)
        }
        Some("accuracy") => run(
            "host-sim accuracy (docs/accuracy.md, docs/accuracy.png)",
            cargo().args([
                "run",
                "--release",
                "-p",
                "host-sim",
                "--",
                "accuracy",
                "--out",
                "docs",
            ]),
        ),
        Some("verify-study") => run(
            "verify on random tight designs, at them and 1% past (docs/soundness.md)",
            cargo()
                .args([
                    "run",
                    "--release",
                    "-p",
                    "twoport-design",
                    "--example",
                    "verify_past",
                    "--",
                ])
                .args(&args[1..]),
        ),
        _ => Err(format!(
            "usage: cargo xtask <ci [step...]|thumb|firmware|qemu|pil [--board an386|stm32f405] [options]|scope-board|device [--check]|header [--check]|python|overhead [rounds]|watchdog|fuzz [seconds]|accuracy|verify-study [--seeds a,b] [--count n] [--out dir]>\n  got: {}",
            args.join(" ")
        )),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("xtask: {e}");
            ExitCode::FAILURE
        }
    }
}

pub(crate) fn root() -> PathBuf {
    // `cargo run` names the checkout it ran from; the path compiled in is
    // only the fallback. (Two checkouts sharing one CARGO_TARGET_DIR share
    // the xtask binary too, and a compiled-in path made one checkout's
    // `cargo xtask` quietly build the other's sources.)
    let dir = std::env::var_os("CARGO_MANIFEST_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")));
    dir.parent()
        .expect("xtask lives in the workspace root")
        .to_path_buf()
}

/// Where the host's builds go (`CARGO_TARGET_DIR`, or the checkout's
/// `target`).
pub(crate) fn target_dir() -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| root().join("target"))
}

/// Where cross builds go: beside the host build, in their own folders, so
/// that two compilers never share a directory.
pub(crate) fn cross_target_dir(name: &str) -> PathBuf {
    target_dir().join(name)
}

pub(crate) fn run(what: &str, cmd: &mut Command) -> Result<(), String> {
    eprintln!("xtask: {what}");
    let status = cmd
        .status()
        .map_err(|e| format!("{what}: could not start: {e}"))?;
    if status.success() {
        Ok(())
    } else {
        Err(format!("{what}: failed ({status})"))
    }
}

/// Run `jobs` at once, a thread each, and wait for all of them; the first
/// error, in the order given (a panic is one).
pub(crate) fn at_once<F>(jobs: impl IntoIterator<Item = F>) -> Result<(), String>
where
    F: FnOnce() -> Result<(), String> + Send,
{
    std::thread::scope(|s| {
        let running: Vec<_> = jobs.into_iter().map(|job| s.spawn(job)).collect();
        running.into_iter().try_for_each(|h| {
            h.join()
                .unwrap_or_else(|_| Err("a job run at once panicked".into()))
        })
    })
}

pub(crate) fn cargo() -> Command {
    let mut c = Command::new(std::env::var("CARGO").unwrap_or("cargo".into()));
    c.current_dir(root());
    c
}
