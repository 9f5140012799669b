//! `cargo xtask <task>`: the project's build, emulate and check tasks.
//!
//! - `ci`: everything CI checks (fmt, clippy, tests, the thumbv7em build of
//!   the control crate, the firmware's on-target tests in QEMU).
//! - `thumb`: build `twoport-control` for thumbv7em-none-eabihf.
//! - `firmware`: build the firmware workspace.
//! - `qemu`: build and run the on-target tests in QEMU mps2-an386.
//! - `pil [--board an386|stm32f405] [host-sim pil options]`:
//!   processor-in-the-loop, a board image in QEMU against host-sim's plant
//!   over `-serial pty` (e.g. `--json`, `--seconds 4`, `--link-loss-at-s 3`,
//!   `--check`, `--passivity`).
//! - `scope-board`: the scope's board mode against the firmware in QEMU.
//! - `watchdog`: hang the an386 image's loop on purpose; the watchdog
//!   resets it and it comes back disarmed with the reset as a fault.
//! - `fuzz [seconds]`: run each cargo-fuzz target (default 60 s each).
//! - `accuracy`: regenerate docs/accuracy.md and docs/accuracy.png.

mod counts;
mod toolchain;

use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode, Stdio};
use std::time::{Duration, Instant};
use toolchain::{Toolchain, TARGET};

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let result = match args.first().map(String::as_str) {
        Some("ci") => ci(),
        Some("thumb") => thumb(),
        Some("firmware") => firmware().map(|_| ()),
        Some("qemu") => qemu(),
        Some("pil") => pil(&args[1..]),
        Some("watchdog") => watchdog(),
        Some("scope-board") => scope_board(),
        Some("fuzz") => {
            let secs = args.get(1).map_or(Ok(60), |s| {
                s.parse::<u32>().map_err(|e| format!("seconds: {e}"))
            });
            secs.and_then(fuzz)
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
        _ => Err(format!(
            "usage: cargo xtask <ci|thumb|firmware|qemu|pil [--board an386|stm32f405] [options]|scope-board|watchdog|fuzz [seconds]|accuracy>\n  got: {}",
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

fn root() -> PathBuf {
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

/// Where cross builds go: beside the host build, in their own folders, so
/// that two compilers never share a directory.
fn cross_target_dir(name: &str) -> PathBuf {
    let base = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| root().join("target"));
    base.join(name)
}

fn run(what: &str, cmd: &mut Command) -> Result<(), String> {
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

fn cargo() -> Command {
    let mut c = Command::new(std::env::var("CARGO").unwrap_or("cargo".into()));
    c.current_dir(root());
    c
}

fn ci() -> Result<(), String> {
    run(
        "cargo fmt --check",
        cargo().args(["fmt", "--all", "--", "--check"]),
    )?;
    run(
        "cargo fmt --check (firmware)",
        cargo().args([
            "fmt",
            "--manifest-path",
            "firmware/Cargo.toml",
            "--all",
            "--",
            "--check",
        ]),
    )?;
    run(
        "cargo fmt --check (firmware/stm32f405)",
        cargo().args([
            "fmt",
            "--manifest-path",
            "firmware/stm32f405/Cargo.toml",
            "--all",
            "--",
            "--check",
        ]),
    )?;
    run(
        "cargo fmt --check (fuzz)",
        cargo().args([
            "fmt",
            "--manifest-path",
            "fuzz/Cargo.toml",
            "--all",
            "--",
            "--check",
        ]),
    )?;
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
    )?;
    // The crates' docs (each README is its crate's page) build without a
    // warning, and the design library builds without the CLI and plots.
    run(
        "cargo doc (warnings denied)",
        cargo()
            .args(["doc", "--workspace", "--no-deps"])
            .env("RUSTDOCFLAGS", "-D warnings"),
    )?;
    run(
        "twoport-design without its cli and plot features",
        cargo().args([
            "check",
            "-p",
            "twoport-design",
            "--no-default-features",
            "--lib",
            "--examples",
        ]),
    )?;
    thumb()?;
    qemu()?;
    // Processor-in-the-loop: bit for bit against the in-process loop, with
    // corrupted frames and a link loss, on both boards (for the STM32F405
    // image, its own loop on QEMU's netduinoplus2, with the log of what it
    // touches that QEMU does not model).
    for board in ["an386", "stm32f405"] {
        let args = [
            "--board",
            board,
            "--seconds",
            "4",
            "--link-loss-at-s",
            "3",
            "--check",
        ];
        pil(&args.map(String::from))?;
        // Homing onto the scene's hard stop, then armed: the state machine
        // bit for bit too.
        let homing = [
            "--board",
            board,
            "scenes/homing.toml",
            "--seconds",
            "2",
            "--check",
        ];
        pil(&homing.map(String::from))?;
        // The three-axis image on its building-block world.
        let xyz = [
            "--board",
            board,
            "scenes/xyz/pil_blocks.toml",
            "--seconds",
            "4",
            "--link-loss-at-s",
            "3",
            "--check",
        ];
        pil(&xyz.map(String::from))?;
    }
    // The passivity image too: the layered tick on the M4F against the
    // same code on the host.
    pil(&[
        "--passivity".into(),
        "--seconds".into(),
        "3".into(),
        "--check".into(),
    ])?;
    scope_board()?;
    watchdog()?;
    fuzz(40)?;
    // Last, closing on the total so that CI reads the whole count rather
    // than the last crate's doc-test line. The long hard cases (24 h of
    // ticks, 2 x 10^4 random terminations) are ignored in debug builds and
    // run here in release.
    let runs: [&[&str]; 4] = [
        &[
            "test",
            "--release",
            "--test",
            "hard_cases",
            "--test",
            "terminations",
            "--test",
            "verify_time_domain",
            "--test",
            "shipped_devices",
            "--",
            "--ignored",
        ],
        // The designer's soundness: the verify searches run in release only.
        &[
            "test",
            "--release",
            "-p",
            "twoport-design",
            "--test",
            "soundness",
        ],
        // The scope in a real window under Xvfb (screenshots) and an hour of
        // scope buffers.
        &[
            "test",
            "--release",
            "-p",
            "host-sim",
            "--test",
            "screenshot",
            "--test",
            "scope",
            "--test",
            "study",
            "--",
            "--ignored",
            "--skip",
            "board_mode",
        ],
        &["test", "--workspace"],
    ];
    let (mut passed, mut failed, mut ok) = (0, 0, true);
    for args in runs {
        let (p, f, good) = cargo_test_counts(args)?;
        (passed, failed, ok) = (passed + p, failed + f, ok && good);
    }
    println!("tests: {passed} passed, {failed} failed");
    if ok {
        Ok(())
    } else {
        Err("cargo test: failed".into())
    }
}

/// Run `cargo <args>`, passing its output through; returns the passed and
/// failed counts it reported and whether it succeeded.
fn cargo_test_counts(args: &[&str]) -> Result<(u64, u64, bool), String> {
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

fn thumb() -> Result<(), String> {
    let tc = Toolchain::detect()?;
    run(
        &format!(
            "build twoport-control, -link and -board for {TARGET} ({})",
            tc.describe()
        ),
        &mut tc.build(
            &root(),
            &cross_target_dir("thumbv7em-control"),
            &[
                "-p",
                "twoport-control",
                "-p",
                "twoport-link",
                "-p",
                "twoport-board",
            ],
        ),
    )
}

/// Build the firmware workspace; returns the folder holding the ELF files.
fn firmware() -> Result<PathBuf, String> {
    let tc = Toolchain::detect()?;
    let dir = cross_target_dir("firmware");
    run(
        &format!("build firmware: QEMU images ({})", tc.describe()),
        &mut tc.build(&root().join("firmware"), &dir, &[]),
    )?;
    let out = dir.join(TARGET).join("release");
    // With RTT logging first, copied aside, then the plain image last, so
    // that `twoport-stm32f405` is the plain one.
    stm32f405_variant("defmt", "twoport-stm32f405-defmt")?;
    stm32f405_variant("xyz", "twoport-stm32f405-xyz")?;
    run(
        &format!("build firmware: STM32F405 image ({})", tc.describe()),
        &mut tc.build(&root().join("firmware/stm32f405"), &dir, &[]),
    )?;
    // Flash and RAM of each image (text + data in flash; data + bss in RAM).
    let size = Command::new("arm-none-eabi-size")
        .args([
            "twoport-stm32f405",
            "twoport-stm32f405-defmt",
            "twoport-stm32f405-xyz",
            "twoport-an386",
            "twoport-probe",
        ])
        .current_dir(&out)
        .output();
    if let Ok(o) = size {
        eprint!("{}", String::from_utf8_lossy(&o.stdout));
    }
    Ok(out)
}

/// The an386 image built with the passivity layer; returns its ELF. It
/// shares the firmware's target folder, so only the image's own crate is
/// rebuilt (the feature is its alone), and is copied aside, because the
/// next plain build writes the same file.
fn passivity_image() -> Result<PathBuf, String> {
    an386_image_with("passivity")
}

/// The an386 image built with `feature`; returns its ELF, copied aside as
/// `twoport-an386-<feature>`.
fn an386_image_with(feature: &str) -> Result<PathBuf, String> {
    let tc = Toolchain::detect()?;
    let dir = cross_target_dir("firmware");
    run(
        &format!("build firmware: the {feature} image ({})", tc.describe()),
        &mut tc.build(
            &root().join("firmware"),
            &dir,
            &["-p", "twoport-an386", "--features", feature],
        ),
    )?;
    let out = dir.join(TARGET).join("release");
    let elf = out.join(format!("twoport-an386-{feature}"));
    std::fs::copy(out.join("twoport-an386"), &elf)
        .map_err(|e| format!("copy the {feature} image: {e}"))?;
    Ok(elf)
}

/// The watchdog test: the an386 image that hangs its loop on purpose
/// after 1,500 armed ticks, against host-sim's check that the CMSDK
/// watchdog resets it and that it comes back disarmed, outputs off, with
/// the reset latched as a fault.
fn watchdog() -> Result<(), String> {
    let elf = an386_image_with("watchdog-test")?;
    host_test_against_an386(
        "watchdog reset in QEMU",
        &elf,
        "pil",
        "a_hung_loop_is_reset_by_the_watchdog_and_comes_back_disarmed",
    )
}

/// Run the ignored host-sim test `name` (in test file `file`) against
/// the an386 image `elf` in QEMU, its link's pty in `TWOPORT_PTY`.
fn host_test_against_an386(what: &str, elf: &Path, file: &str, name: &str) -> Result<(), String> {
    let mut qemu = qemu_an386(elf);
    qemu.args(["-serial", "pty"]);
    with_board_in_qemu(qemu, |pty| {
        run(
            what,
            cargo()
                .env("TWOPORT_PTY", pty)
                .args(["test", "--release", "-p", "host-sim", "--test", file])
                .args(["--", "--ignored", "--exact", name]),
        )
    })
}

/// The STM32F405 image's `qemu` build (three-axis with `xyz`), for QEMU's
/// netduinoplus2; returns its ELF.
fn stm32f405_qemu_image(xyz: bool) -> Result<PathBuf, String> {
    match xyz {
        true => stm32f405_variant("qemu,xyz", "twoport-stm32f405-qemu-xyz"),
        false => stm32f405_variant("qemu", "twoport-stm32f405-qemu"),
    }
}

/// The STM32F405 image built with `features`, its ELF copied aside as
/// `name` (the next build overwrites the plain one); returns that copy.
fn stm32f405_variant(features: &str, name: &str) -> Result<PathBuf, String> {
    let tc = Toolchain::detect()?;
    let dir = cross_target_dir("firmware");
    run(
        &format!(
            "build firmware: the STM32F405 image, {features} ({})",
            tc.describe()
        ),
        &mut tc.build(
            &root().join("firmware/stm32f405"),
            &dir,
            &["--features", features],
        ),
    )?;
    let out = dir.join(TARGET).join("release");
    let elf = out.join(name);
    std::fs::copy(out.join("twoport-stm32f405"), &elf)
        .map_err(|e| format!("copy the {features} image: {e}"))?;
    Ok(elf)
}

/// Processor-in-the-loop: start a board image in QEMU with its link on a
/// pty, point `host-sim pil` at it, and fail if either side fails. The
/// an386 image by default (`--passivity`: its passivity build); with
/// `--board stm32f405`, the STM32F405 image's own loop on netduinoplus2,
/// whose accesses to devices QEMU does not model are logged and summed up.
fn pil(extra: &[String]) -> Result<(), String> {
    let mut args = extra.to_vec();
    let board = match args.iter().position(|a| a == "--board") {
        Some(i) if i + 1 < args.len() => {
            let b = args.remove(i + 1);
            args.remove(i);
            b
        }
        Some(_) => return Err("pil: --board needs a name (an386 or stm32f405)".into()),
        None => "an386".into(),
    };
    run(
        "build host-sim",
        cargo().args(["build", "--release", "-q", "-p", "host-sim"]),
    )?;
    let host = |pty: &str| {
        run(
            "host-sim pil",
            cargo()
                .args(["run", "--release", "-q", "-p", "host-sim", "--"])
                .args(["pil", "--port", pty])
                .args(&args),
        )
    };
    let xyz = args.iter().any(|a| declares_three_axes(a));
    match board.as_str() {
        "an386" => {
            let elf = if args.iter().any(|a| a == "--passivity") {
                passivity_image()?
            } else if xyz {
                an386_image_with("xyz")?
            } else {
                firmware()?.join("twoport-an386")
            };
            let mut qemu = qemu_an386(&elf);
            qemu.args(["-serial", "pty"]);
            with_board_in_qemu(qemu, host)
        }
        "stm32f405" => {
            if args.iter().any(|a| a == "--passivity") {
                return Err("pil: the STM32F405 image has no passivity build".into());
            }
            let elf = stm32f405_qemu_image(xyz)?;
            let log = cross_target_dir("firmware").join("qemu-unmodelled-stm32f405.log");
            let _ = std::fs::remove_file(&log);
            let mut qemu = qemu_netduino(&elf);
            // USART2 is the second serial port.
            qemu.args(["-serial", "null", "-serial", "pty"])
                .args(["-d", "unimp,guest_errors", "-D"])
                .arg(&log);
            let result = with_board_in_qemu(qemu, host);
            eprint!("{}", unmodelled_summary(&log));
            result
        }
        other => Err(format!(
            "pil: no board image called {other:?} (an386 or stm32f405)"
        )),
    }
}

/// Whether `arg` names a scene file that declares three axes (`axes = 3`
/// at its top level, read as host-sim reads it), for which the three-axis
/// image runs.
fn declares_three_axes(arg: &str) -> bool {
    if !arg.ends_with(".toml") {
        return false;
    }
    let text = std::fs::read_to_string(root().join(arg)).unwrap_or_default();
    let axes = text
        .parse::<toml::Table>()
        .ok()
        .and_then(|t| t.get("axes").and_then(toml::Value::as_integer));
    axes == Some(3)
}

/// What QEMU logged of the image's accesses to devices it does not model:
/// a line per device, with its read and write counts.
fn unmodelled_summary(log: &Path) -> String {
    let Ok(text) = std::fs::read_to_string(log) else {
        return format!("xtask: no QEMU log at {}\n", log.display());
    };
    let mut seen: Vec<(String, u64, u64)> = Vec::new();
    let mut other = 0u64;
    for line in text.lines() {
        let Some((device, rest)) = line.split_once(": unimplemented device ") else {
            other += u64::from(!line.trim().is_empty());
            continue;
        };
        let i = match seen.iter().position(|(d, _, _)| d == device) {
            Some(i) => i,
            None => {
                seen.push((device.to_string(), 0, 0));
                seen.len() - 1
            }
        };
        if rest.starts_with("read") {
            seen[i].1 += 1;
        } else {
            seen[i].2 += 1;
        }
    }
    let mut s = format!(
        "xtask: devices the image touches that QEMU does not model (log: {}):\n",
        log.display()
    );
    for (d, r, w) in &seen {
        s += &format!("  {d:<10} {r:>6} reads {w:>6} writes\n");
    }
    if other > 0 {
        s += &format!("  and {other} other lines (guest errors)\n");
    }
    s
}

/// The scope's board mode against the firmware in QEMU.
fn scope_board() -> Result<(), String> {
    let elf = firmware()?.join("twoport-an386");
    host_test_against_an386(
        "scope board mode against QEMU",
        &elf,
        "scope",
        "board_mode_shows_telemetry_and_the_boards_gain_answers",
    )
}

/// Run `f` with a board image in QEMU (`qemu`, its link on a `-serial
/// pty`), passing it the pty; fails if the firmware stops (a panic or
/// HardFault exits QEMU) or `f` fails. QEMU is killed, not asked, to stop:
/// under `-icount sleep=off` it may not answer a SIGTERM.
fn with_board_in_qemu(
    mut qemu: Command,
    f: impl FnOnce(&str) -> Result<(), String>,
) -> Result<(), String> {
    use std::io::{BufRead, BufReader, Read};
    let mut qemu = qemu
        .args(["-display", "none", "-monitor", "none"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| format!("qemu-system-arm: could not start ({e}); install qemu-system-arm"))?;
    // QEMU names the pty on stdout, where the board's semihosting prints go
    // too; both are kept to show if the run fails.
    let stdout = qemu.stdout.take().ok_or("qemu's stdout")?;
    let mut lines = BufReader::new(stdout).lines();
    let pty = loop {
        match lines.next() {
            Some(Ok(l)) => {
                if let Some(rest) = l.strip_prefix("char device redirected to ") {
                    break rest.split_whitespace().next().unwrap_or("").to_string();
                }
            }
            _ => {
                let _ = qemu.kill();
                return Err("qemu did not say where its serial pty is".into());
            }
        }
    };
    let board_out = std::thread::spawn(move || lines.map_while(Result::ok).collect::<Vec<_>>());
    let mut stderr = qemu.stderr.take().ok_or("qemu's stderr")?;
    std::thread::spawn(move || {
        let mut s = String::new();
        let _ = stderr.read_to_string(&mut s);
    });
    eprintln!("xtask: firmware in QEMU on {pty}");
    let host = f(&pty);
    let early_exit = qemu.try_wait().ok().flatten();
    let _ = qemu.kill();
    let _ = qemu.wait();
    let printed = board_out.join().unwrap_or_default().join("\n");
    if let Some(st) = early_exit {
        return Err(format!(
            "the firmware stopped during the run ({st}):\n{printed}"
        ));
    }
    host.map_err(|e| format!("{e}; the board printed:\n{printed}"))
}

/// The cargo-fuzz targets in fuzz/.
const FUZZ_TARGETS: [&str; 4] = [
    "link_decoder",
    "config_record",
    "model_parser",
    "scene_parser",
];

/// Run each fuzz target for `secs` seconds on a scratch copy of its seed
/// corpus. On a stable toolchain cargo-fuzz needs RUSTC_BOOTSTRAP=1 for its
/// sanitizer flags.
fn fuzz(secs: u32) -> Result<(), String> {
    let has = Command::new(std::env::var("CARGO").unwrap_or("cargo".into()))
        .args(["fuzz", "--version"])
        .output()
        .is_ok_and(|o| o.status.success());
    if !has {
        return Err("cargo-fuzz is not installed: cargo install cargo-fuzz --locked".into());
    }
    for t in FUZZ_TARGETS {
        let work = cross_target_dir("fuzz-corpus").join(t);
        std::fs::create_dir_all(&work).map_err(|e| format!("{}: {e}", work.display()))?;
        let seeds = root().join("fuzz/corpus").join(t);
        for f in std::fs::read_dir(&seeds)
            .map_err(|e| format!("{}: {e}", seeds.display()))?
            .flatten()
        {
            let _ = std::fs::copy(f.path(), work.join(f.file_name()));
        }
        run(
            &format!("fuzz {t} for {secs} s"),
            cargo()
                .env("RUSTC_BOOTSTRAP", "1")
                .args(["fuzz", "run", t])
                .arg(&work)
                .args([
                    "--",
                    &format!("-max_total_time={secs}"),
                    // A slow input is a finding (a model once spun the
                    // matrix exponential forever), not a 20-minute stall.
                    "-timeout=10",
                    "-max_len=4096",
                    "-print_final_stats=1",
                ]),
        )?;
    }
    Ok(())
}

/// QEMU's Cortex-M4F board running `elf`, with semihosting (prints and
/// exit codes) and virtual time from the instruction count, so that the
/// images' SysTick measurements are deterministic.
fn qemu_an386(elf: &Path) -> Command {
    let mut c = Command::new("qemu-system-arm");
    c.args(["-machine", "mps2-an386", "-cpu", "cortex-m4"])
        .args(["-icount", "shift=6"])
        .args(["-semihosting-config", "enable=on,target=native", "-kernel"])
        .arg(elf)
        .stdin(Stdio::null());
    c
}

/// QEMU's netduinoplus2 (an STM32F405 SoC) running `elf`, with
/// semihosting, and virtual time from the instruction count, 16 ns each
/// (the image's `ICOUNT_SHIFT`), so that its TIM5 counts instructions and
/// its TIM2 control interrupt is periodic in them.
fn qemu_netduino(elf: &Path) -> Command {
    let mut c = Command::new("qemu-system-arm");
    c.args(["-machine", "netduinoplus2"])
        .args(["-icount", "shift=4"])
        .args(["-semihosting-config", "enable=on,target=native", "-kernel"])
        .arg(elf)
        .stdin(Stdio::null());
    c
}

fn qemu() -> Result<(), String> {
    let elf = firmware()?.join("twoport-probe");
    eprintln!("xtask: run {} in QEMU mps2-an386", elf.display());
    let mut child = qemu_an386(&elf)
        .arg("-nographic")
        .stdout(Stdio::piped())
        .spawn()
        .map_err(|e| format!("qemu-system-arm: could not start ({e}); install qemu-system-arm"))?;
    // Echo the probe's lines as they come, and keep them for the counts.
    let stdout = child.stdout.take().ok_or("qemu: no stdout")?;
    let reader = std::thread::spawn(move || {
        use std::io::BufRead;
        let mut all = String::new();
        for line in std::io::BufReader::new(stdout)
            .lines()
            .map_while(Result::ok)
        {
            println!("{line}");
            all.push_str(&line);
            all.push('\n');
        }
        all
    });
    // A hung target (a lost exit, a fault loop) must not hang CI.
    let deadline = Instant::now() + Duration::from_secs(300);
    let status = loop {
        match child.try_wait() {
            Ok(Some(status)) => break status,
            Ok(None) if Instant::now() > deadline => {
                let _ = child.kill();
                return Err("on-target tests timed out after 300 s".into());
            }
            Ok(None) => std::thread::sleep(Duration::from_millis(50)),
            Err(e) => return Err(format!("waiting for qemu: {e}")),
        }
    };
    let output = reader
        .join()
        .map_err(|_| "qemu: the output reader failed")?;
    if !status.success() {
        return Err(format!("on-target tests failed ({status})"));
    }
    check_counts(&output)
}

/// The probe's counts against `firmware/probe/counts.txt`.
fn check_counts(output: &str) -> Result<(), String> {
    let path = root().join("firmware/probe/counts.txt");
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let problems = counts::compare(&counts::measured(output)?, &counts::expected(&text, &path)?);
    if problems.is_empty() {
        eprintln!(
            "xtask: every instruction count within its tolerance ({})",
            path.display()
        );
        Ok(())
    } else {
        Err(format!(
            "instruction counts moved (change the code back, or {} with it):\n  {}",
            path.display(),
            problems.join("\n  ")
        ))
    }
}
