//! Everything CI checks, as a table of named steps: `cargo xtask ci` runs
//! them all in order, `cargo xtask ci <step>...` only the ones named, and
//! each step's time is printed at the end (CI's goal is 30 minutes from a
//! fresh clone).

use crate::emulate::{
    device, pil, pil_image, pil_on, scope_board, watchdog, workspace_release_build,
};
use crate::firmware::thumb;
use crate::fuzz::fuzz;
use crate::probe::qemu;
use crate::{at_once, cargo, run};
use std::process::Stdio;
use std::time::{Duration, Instant};

/// One named step of CI.
struct Step {
    name: &'static str,
    what: &'static str,
    run: fn() -> Result<(), String>,
}

/// The steps, in the order CI runs them: the quick checks first, the
/// tests' total last, so that a log's last line is the whole count.
const STEPS: [Step; 14] = [
    Step {
        name: "fmt",
        what: "rustfmt on the workspace, the firmware's two and fuzz's",
        run: fmt,
    },
    Step {
        name: "clippy",
        what: "clippy on every target, warnings denied",
        run: clippy,
    },
    Step {
        name: "doc",
        what: "the crates' docs (each README is its crate's page), warnings denied",
        run: doc,
    },
    Step {
        name: "design-lib",
        what: "the design library without its CLI and plots",
        run: design_lib,
    },
    Step {
        name: "thumb",
        what: "the no_std crates for the Cortex-M4F",
        run: thumb,
    },
    Step {
        name: "probe",
        what: "the on-target probe in QEMU, its instruction counts checked",
        run: qemu,
    },
    Step {
        name: "pil",
        what: "processor in the loop on both boards, bit for bit",
        run: pil_boards,
    },
    Step {
        name: "pil-passivity",
        what: "the passivity image in the loop",
        run: pil_passivity,
    },
    Step {
        name: "scope-board",
        what: "the scope's board mode against the firmware in QEMU",
        run: scope_board,
    },
    Step {
        name: "device",
        what: "a host application on the free-running board in QEMU",
        run: || device(&["--check".to_string()]),
    },
    Step {
        name: "python",
        what: "the Python wheel built (maturin, abi3), installed and tested (pytest)",
        run: crate::python::python,
    },
    Step {
        name: "watchdog",
        what: "a hung loop reset by the watchdog, seen by the host",
        run: watchdog,
    },
    Step {
        name: "fuzz",
        what: "each fuzz target for 20 s",
        run: || fuzz(20),
    },
    Step {
        name: "tests",
        what: "every test, the long ones included, in one release build",
        run: tests,
    },
];

/// Run every step, or only those `only` names; a name CI does not have is
/// an error that lists the names.
pub(crate) fn ci(only: &[String]) -> Result<(), String> {
    if let Some(bad) = only.iter().find(|n| !STEPS.iter().any(|s| s.name == *n)) {
        let names: Vec<&str> = STEPS.iter().map(|s| s.name).collect();
        return Err(format!(
            "ci has no step `{bad}`; its steps: {}",
            names.join(", ")
        ));
    }
    let mut took: Vec<(&str, Duration)> = Vec::new();
    let chosen = STEPS
        .iter()
        .filter(|s| only.is_empty() || only.iter().any(|n| n == s.name));
    for step in chosen {
        eprintln!("xtask: ci step `{}`: {}", step.name, step.what);
        let t = Instant::now();
        let result = (step.run)();
        took.push((step.name, t.elapsed()));
        if let Err(e) = result {
            report(&took);
            return Err(format!("ci step `{}`: {e}", step.name));
        }
    }
    report(&took);
    Ok(())
}

/// Each step's time, and the total.
fn report(took: &[(&str, Duration)]) {
    let total: Duration = took.iter().map(|(_, d)| *d).sum();
    eprintln!("xtask: ci steps' times");
    for (name, d) in took {
        eprintln!("  {name:<14} {:>7.1} s", d.as_secs_f64());
    }
    eprintln!("  {:<14} {:>7.1} s", "total", total.as_secs_f64());
}

fn fmt() -> Result<(), String> {
    run(
        "cargo fmt --check",
        cargo().args(["fmt", "--all", "--", "--check"]),
    )?;
    for manifest in [
        "firmware/Cargo.toml",
        "firmware/stm32f405/Cargo.toml",
        "fuzz/Cargo.toml",
    ] {
        run(
            &format!("cargo fmt --check ({manifest})"),
            cargo().args(["fmt", "--manifest-path", manifest, "--all", "--", "--check"]),
        )?;
    }
    Ok(())
}

fn clippy() -> Result<(), String> {
    run(
        "cargo clippy",
        cargo().args([
            "clippy",
            "--workspace",
            "--all-targets",
            "--",
            "-D",
            "warnings",
        ]),
    )
}

fn doc() -> Result<(), String> {
    run(
        "cargo doc (warnings denied)",
        cargo()
            .args(["doc", "--workspace", "--no-deps"])
            .env("RUSTDOCFLAGS", "-D warnings"),
    )
}

fn design_lib() -> Result<(), String> {
    run(
        "twoport-design without its plot feature",
        cargo().args([
            "check",
            "-p",
            "twoport-design",
            "--no-default-features",
            "--lib",
            "--examples",
        ]),
    )
}

/// Processor in the loop, bit for bit against the in-process loop, with
/// corrupted frames and a link loss, on both boards (for the STM32F405
/// image, its own loop on QEMU's netduinoplus2, with the log of what it
/// touches that QEMU does not model): the plain scene, homing onto the
/// hard stop then armed (the state machine bit for bit too), an
/// identification experiment streaming every tick, the
/// three-axis image on its building-block world, the serial-arm and
/// delta images against their nonlinear arms, and a teleoperator: two
/// boards joined through the host.
fn pil_boards() -> Result<(), String> {
    let bin = workspace_release_build()?;
    // Every image first, one build at a time (they share a target folder),
    // each run's ELF a copy of its own.
    let mut plans = Vec::new();
    for board in ["an386", "stm32f405"] {
        let linkage = |device| {
            [
                "--linkage",
                device,
                "--seconds",
                "2",
                "--link-loss-at-s",
                "1.5",
                "--check",
            ]
        };
        let (arm, delta) = (linkage("serial-arm"), linkage("delta"));
        let runs: [&[&str]; 8] = [
            &["--seconds", "4", "--link-loss-at-s", "3", "--check"],
            // The 4 kHz image with the VE on the host at 1 kHz.
            &[
                "--fast",
                "scenes/pil/fast_host_ve.toml",
                "--host-ve-hz",
                "1000",
                "--seconds",
                "4",
                "--link-loss-at-s",
                "3",
                "--check",
            ],
            &["scenes/homing.toml", "--seconds", "2", "--check"],
            // Two whole periods of the identification experiment.
            &[
                "scenes/identify/excalibur.toml",
                "--seconds",
                "2.3",
                "--check",
            ],
            &[
                "scenes/xyz/pil_blocks.toml",
                "--seconds",
                "4",
                "--link-loss-at-s",
                "3",
                "--check",
            ],
            &arm,
            &delta,
            // Two boards through the host: a teleoperator.
            &[
                "--teleop",
                "scenes/pil/teleop_pair.toml",
                "--seconds",
                "2",
                "--check",
            ],
        ];
        for args in runs {
            let args: Vec<String> = args.iter().map(|a| a.to_string()).collect();
            let elf = pil_image(board, &args)?;
            plans.push((board, args, elf));
        }
    }
    // Then the two boards side by side: a run is one QEMU and one host
    // program in lockstep, about a core, and nothing in it waits on the
    // wall clock but a 5 s answer timeout.
    at_once(["an386", "stm32f405"].map(|board| {
        let (plans, bin) = (&plans, &bin);
        move || {
            plans
                .iter()
                .filter(|(b, _, _)| *b == board)
                .try_for_each(|(b, args, elf)| pil_on(bin, b, args, elf))
        }
    }))
}

/// The passivity image: the layered tick on the M4F against the same code
/// on the host.
fn pil_passivity() -> Result<(), String> {
    pil(&["--passivity", "--seconds", "3", "--check"].map(String::from))
}

/// Tests that need a board image running in QEMU: their own steps run
/// them (`watchdog`, `scope-board`, `device`).
const NEEDS_QEMU: [&str; 3] = [
    "a_hung_loop_is_reset_by_the_watchdog",
    "board_mode_shows_telemetry",
    "an_application_drives_the_free_running_board_in_qemu",
];

/// Every test, in one release build of the workspace (the build the
/// `pil`, `scope-board`, `device` and `watchdog` steps make first and run
/// from, so none compiles the workspace again with other features): the
/// ignored long cases (24 h of ticks, 2 x 10^4 random terminations, an
/// hour of scope buffers, the scope under Xvfb) included, but for those
/// that need QEMU. It closes on the total so that CI reads the whole count
/// rather than the last crate's doc-test line.
fn tests() -> Result<(), String> {
    let mut args = vec![
        "test",
        "--workspace",
        "--release",
        "--",
        "--include-ignored",
    ];
    for name in NEEDS_QEMU {
        args.extend(["--skip", name]);
    }
    let (passed, failed, ok) = cargo_test_counts(&args)?;
    println!("tests: {passed} passed, {failed} failed");
    if ok {
        Ok(())
    } else {
        Err("cargo test: failed".into())
    }
}

/// Run `cargo <args>`, passing its output through; returns the passed and
/// failed counts it reported and whether it succeeded.
pub(crate) fn cargo_test_counts(args: &[&str]) -> Result<(u64, u64, bool), String> {
    use std::io::{BufRead, BufReader};
    eprintln!("xtask: cargo {}", args.join(" "));
    let mut child = cargo()
        .args(args)
        .stdout(Stdio::piped())
        .spawn()
        .map_err(|e| format!("cargo test: could not start: {e}"))?;
    let (mut passed, mut failed) = (0u64, 0u64);
    let out = child.stdout.take().expect("stdout is piped");
    for line in BufReader::new(out).lines() {
        let line = line.map_err(|e| format!("cargo test output: {e}"))?;
        println!("{line}");
        if let Some(rest) = line.strip_prefix("test result: ") {
            let count = |word: &str| {
                rest.split(';')
                    .find_map(|part| {
                        part.trim()
                            .strip_suffix(word)?
                            .split_whitespace()
                            .last()?
                            .parse::<u64>()
                            .ok()
                    })
                    .unwrap_or(0)
            };
            passed += count(" passed");
            failed += count(" failed");
        }
    }
    let status = child.wait().map_err(|e| format!("cargo test: {e}"))?;
    Ok((passed, failed, status.success()))
}
