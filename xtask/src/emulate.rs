//! The images in QEMU against the host: processor in the loop, the
//! scope's board mode and the watchdog, each through a pty.

use crate::firmware::{
    an386_image_with, firmware, passivity_image, stm32f405_qemu_image, stm32f405_variant,
};
use crate::{cargo, cross_target_dir, root, run};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// QEMU's Cortex-M4F board running `elf`, with semihosting (prints and
/// exit codes) and virtual time from the instruction count, so that the
/// images' SysTick measurements are deterministic.
pub(crate) fn qemu_an386(elf: &Path) -> Command {
    qemu_an386_timed(elf, "shift=6")
}

/// [`qemu_an386`] with `icount` as QEMU's `-icount` option.
fn qemu_an386_timed(elf: &Path, icount: &str) -> Command {
    let mut c = Command::new("qemu-system-arm");
    c.args(["-machine", "mps2-an386", "-cpu", "cortex-m4"])
        .args(["-icount", icount])
        .args(["-semihosting-config", "enable=on,target=native", "-kernel"])
        .arg(elf)
        .stdin(Stdio::null());
    c
}

/// QEMU's netduinoplus2 (an STM32F405 SoC) running `elf`, with
/// semihosting, and virtual time from the instruction count, 16 ns each
/// (the image's `ICOUNT_SHIFT`), so that its TIM5 counts instructions and
/// its TIM2 control interrupt is periodic in them.
pub(crate) fn qemu_netduino(elf: &Path) -> Command {
    let mut c = Command::new("qemu-system-arm");
    c.args(["-machine", "netduinoplus2"])
        .args(["-icount", "shift=4"])
        .args(["-semihosting-config", "enable=on,target=native", "-kernel"])
        .arg(elf)
        .stdin(Stdio::null());
    c
}

/// The workspace's one release build, as the tests step makes it (its
/// tests' features unified over every member), and where its programs
/// are: every step that runs a host program or test uses this build, so
/// none of them compiles the workspace again with other features.
pub(crate) fn workspace_release_build() -> Result<std::path::PathBuf, String> {
    run(
        "build the workspace (release, as its tests)",
        cargo().args(["test", "--release", "--workspace", "--no-run", "-q"]),
    )?;
    Ok(crate::target_dir().join("release"))
}

/// Processor-in-the-loop: start a board image in QEMU with its link on a
/// pty, point `host-sim pil` at it, and fail if either side fails. The
/// an386 image by default (`--passivity`: its passivity build); with
/// `--board stm32f405`, the STM32F405 image's own loop on netduinoplus2,
/// whose accesses to devices QEMU does not model are logged and summed up.
pub(crate) fn pil(extra: &[String]) -> Result<(), String> {
    let (board, args) = board_of(extra)?;
    let elf = pil_image(&board, &args)?;
    pil_on(&workspace_release_build()?, &board, &args, &elf)
}

/// The board a PIL command line names (`--board NAME`, an386 by default)
/// and the rest of it.
fn board_of(extra: &[String]) -> Result<(String, Vec<String>), String> {
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
    Ok((board, args))
}

/// The image a PIL run with `args` needs on `board`, built, as an ELF of
/// its own: the next build of another image leaves it as it is, so that
/// runs can go on while other images are built or run.
pub(crate) fn pil_image(board: &str, args: &[String]) -> Result<PathBuf, String> {
    let has = |flag: &str| args.iter().any(|a| a == flag);
    // A teleoperation pair: two boards of the one-axis image.
    let xyz = !has("--teleop") && args.iter().any(|a| declares_three_axes(a));
    // (host-sim reads it too: the 4 kHz image's reference and period.)
    let fast = !has("--teleop") && has("--fast");
    // (host-sim checks the name; the image is built with it as a feature.)
    let linkage = match args.iter().position(|a| a == "--linkage") {
        Some(i) => match args.get(i + 1) {
            Some(l) if l == "serial-arm" || l == "delta" => Some(l.clone()),
            other => {
                return Err(format!(
                    "pil: --linkage takes serial-arm or delta, not {other:?}"
                ))
            }
        },
        None => None,
    };
    match board {
        "an386" if has("--passivity") => passivity_image(),
        "an386" => match &linkage {
            Some(l) => an386_image_with(l),
            None if xyz => an386_image_with("xyz"),
            None if fast => an386_image_with("fast"),
            None => {
                let out = firmware()?;
                let elf = out.join("twoport-an386-plain");
                std::fs::copy(out.join("twoport-an386"), &elf)
                    .map_err(|e| format!("copy the an386 image: {e}"))?;
                Ok(elf)
            }
        },
        "stm32f405" if has("--passivity") => {
            Err("pil: the STM32F405 image has no passivity build".into())
        }
        "stm32f405" => match &linkage {
            Some(l) => {
                stm32f405_variant(&format!("qemu,{l}"), &format!("twoport-stm32f405-qemu-{l}"))
            }
            None if fast => stm32f405_variant("qemu,fast", "twoport-stm32f405-qemu-fast"),
            None => stm32f405_qemu_image(xyz),
        },
        other => Err(format!(
            "pil: no board image called {other:?} (an386 or stm32f405)"
        )),
    }
}

/// One PIL run of `elf` on `board` against the host program in `bin`
/// (the workspace's release build); a teleoperation pair (`--teleop`) runs
/// two boards of the image, each in its own QEMU, the host between them.
pub(crate) fn pil_on(bin: &Path, board: &str, args: &[String], elf: &Path) -> Result<(), String> {
    let exe = bin.join("host-sim");
    let qemu = || -> Command {
        match board {
            "an386" => {
                let mut q = qemu_an386(elf);
                q.args(["-serial", "pty"]);
                q
            }
            // USART2 is the second serial port.
            _ => {
                let mut q = qemu_netduino(elf);
                q.args(["-serial", "null", "-serial", "pty"]);
                q
            }
        }
    };
    if args.iter().any(|a| a == "--teleop") {
        return with_board_in_qemu(qemu(), |master| {
            with_board_in_qemu(qemu(), |slave| {
                run(
                    "host-sim pil --teleop",
                    Command::new(&exe)
                        .args(["pil", "--port", master, "--slave-port", slave])
                        .args(args),
                )
            })
        });
    }
    let host = |pty: &str| {
        run(
            "host-sim pil",
            Command::new(&exe).args(["pil", "--port", pty]).args(args),
        )
    };
    if board == "an386" {
        return with_board_in_qemu(qemu(), host);
    }
    let log = cross_target_dir("firmware").join(format!(
        "qemu-unmodelled-{}.log",
        elf.file_name()
            .and_then(|n| n.to_str())
            .unwrap_or("stm32f405")
    ));
    let _ = std::fs::remove_file(&log);
    let mut q = qemu();
    q.args(["-d", "unimp,guest_errors", "-D"]).arg(&log);
    let result = with_board_in_qemu(q, host);
    eprint!("{}", unmodelled_summary(&log));
    result
}

/// Whether `arg` names a scene file that declares three axes (`axes = 3`
/// at its top level, read as host-sim reads it), for which the three-axis
/// image runs.
pub(crate) fn declares_three_axes(arg: &str) -> bool {
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
pub(crate) fn unmodelled_summary(log: &Path) -> String {
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
pub(crate) fn scope_board() -> Result<(), String> {
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
pub(crate) fn with_board_in_qemu(
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

/// The watchdog test: the an386 image that hangs its loop on purpose
/// after 1,500 armed ticks, against host-sim's check that the CMSDK
/// watchdog resets it and that it comes back disarmed, outputs off, with
/// the reset latched as a fault.
pub(crate) fn watchdog() -> Result<(), String> {
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
pub(crate) fn host_test_against_an386(
    what: &str,
    elf: &Path,
    file: &str,
    name: &str,
) -> Result<(), String> {
    let mut qemu = qemu_an386(elf);
    qemu.args(["-serial", "pty"]);
    with_board_in_qemu(qemu, |pty| {
        run(
            what,
            cargo()
                .env("TWOPORT_PTY", pty)
                .args(["test", "--release", "--workspace", "--test", file])
                .args(["--", "--ignored", "--exact", name]),
        )
    })
}

/// The an386 image that runs free against a device simulated on the chip,
/// in QEMU with virtual time held to the wall clock (`align=on`: QEMU
/// sleeps when the board runs ahead), its link's pty printed. With
/// `--check`, two applications drive it in turn: the host's device-object
/// test, and the C example built with the system C compiler against the
/// library and its committed header (itself checked against the crate);
/// then the C and Rust examples open a Touch by name, through the
/// stand-in HD library. Without, it runs until interrupted, for trying an
/// application on it.
pub(crate) fn device(args: &[String]) -> Result<(), String> {
    let check = match args {
        [] => false,
        [a] if a == "--check" => true,
        other => {
            return Err(format!(
                "device: unknown arguments {other:?} (only --check)"
            ))
        }
    };
    let elf = an386_image_with("sim-device")?;
    let example = if check {
        crate::header::header(true)?;
        Some(c_example()?)
    } else {
        None
    };
    with_device(&elf, |pty| {
        let Some((exe, lib)) = &example else {
            eprintln!(
                "xtask: open {pty} with twoport_host::HostBoard::open_serial; Ctrl-C stops it"
            );
            loop {
                std::thread::sleep(std::time::Duration::from_secs(3600));
            }
        };
        run(
            "the device object against the free-running board",
            cargo()
                .env("TWOPORT_PTY", pty)
                .args(["test", "--release", "--workspace", "--test", "qemu"])
                .args(["--", "--ignored"]),
        )?;
        run(
            "the C example against the free-running board",
            Command::new(exe).arg(pty).env("LD_LIBRARY_PATH", lib),
        )
    })?;
    if let Some((exe, lib)) = &example {
        let (release, standin) = touch_standin()?;
        run(
            "the C example opening a Touch by name (the stand-in HD library)",
            Command::new(exe)
                .args(["--device", "touch", ""])
                .arg(&standin)
                .env("LD_LIBRARY_PATH", lib),
        )?;
        run(
            "the Rust example opening a Touch by name (the stand-in HD library)",
            Command::new(release.join("examples").join("device"))
                .args(["touch", ""])
                .arg(&standin),
        )?;
    }
    Ok(())
}

/// The workspace's release build, and in it the stand-in for OpenHaptics'
/// HD library (`host-sim/hd-standin`): a Touch the examples open by name.
pub(crate) fn touch_standin() -> Result<(std::path::PathBuf, std::path::PathBuf), String> {
    let release = workspace_release_build()?;
    let name = format!(
        "{}twoport_hd_standin{}",
        std::env::consts::DLL_PREFIX,
        std::env::consts::DLL_SUFFIX
    );
    let standin = release.join("deps").join(&name);
    if standin.exists() {
        Ok((release, standin))
    } else {
        Err(format!("{}: not built", standin.display()))
    }
}

/// The `sim-device` image `elf` free-running
/// in QEMU, virtual time held to the wall clock; `f` gets its pty.
pub(crate) fn with_device(
    elf: &Path,
    f: impl FnOnce(&str) -> Result<(), String>,
) -> Result<(), String> {
    let mut qemu = qemu_an386_timed(elf, "shift=6,align=on");
    qemu.args(["-serial", "pty"]);
    with_board_in_qemu(qemu, f)
}

/// The C example, `crates/capi/examples/wall.c`, built with the system C
/// compiler (warnings are errors) against the release library; returns
/// the program and the library's folder.
fn c_example() -> Result<(std::path::PathBuf, std::path::PathBuf), String> {
    run(
        "build the C ABI's library",
        cargo().args(["build", "--release", "-q", "-p", "twoport-capi"]),
    )?;
    let lib = crate::target_dir().join("release");
    let capi = root().join("crates/capi");
    let exe = lib.join("twoport-wall");
    run(
        "build the C example (cc)",
        Command::new("cc")
            .args([
                "-std=c11",
                "-Wall",
                "-Wextra",
                "-Werror",
                "-D_POSIX_C_SOURCE=199309L",
            ])
            .arg("-I")
            .arg(capi.join("include"))
            .arg(capi.join("examples/wall.c"))
            .arg("-L")
            .arg(&lib)
            .args(["-ltwoport", "-lm", "-o"])
            .arg(&exe),
    )?;
    Ok((exe, lib))
}
