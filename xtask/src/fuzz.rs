//! The fuzz targets (libFuzzer, through `libfuzzer-sys`), each for a while.
//!
//! The targets are built by cargo itself with the coverage flags cargo-fuzz
//! passes, so CI needs no cargo-fuzz (its install was a build of its own)
//! and the targets build in the fuzz workspace's release profile rather
//! than cargo-fuzz's single codegen unit with debug info. `cargo fuzz run
//! <target>` in `fuzz/` still works for a longer session by hand.

use crate::{at_once, cargo, cross_target_dir, root, run, target_dir};
use std::path::{Path, PathBuf};
use std::process::Command;

/// The fuzz targets in fuzz/.
pub(crate) const FUZZ_TARGETS: [&str; 5] = [
    "link_decoder",
    "config_record",
    "model_parser",
    "scene_parser",
    "device_packets",
];

/// SanitizerCoverage as libFuzzer reads it (cargo-fuzz's set), the
/// `fuzzing` cfg, and debug assertions so that an overflow is a finding.
/// The targets are safe Rust, whose findings are panics and stalls, so
/// they build without AddressSanitizer.
const RUSTFLAGS: [&str; 9] = [
    "-Cpasses=sancov-module",
    "-Cllvm-args=-sanitizer-coverage-level=4",
    "-Cllvm-args=-sanitizer-coverage-inline-8bit-counters",
    "-Cllvm-args=-sanitizer-coverage-pc-table",
    "-Cllvm-args=-sanitizer-coverage-trace-compares",
    "-Cllvm-args=-sanitizer-coverage-stack-depth",
    "--cfg=fuzzing",
    "-Cdebug-assertions",
    "-Coverflow-checks",
];

/// Build every target, then run each for `secs` seconds on a scratch copy
/// of its seed corpus, two at a time (libFuzzer runs on one core).
pub(crate) fn fuzz(secs: u32) -> Result<(), String> {
    let bins = build()?;
    for pair in FUZZ_TARGETS.chunks(2) {
        at_once(pair.iter().map(|t| || fuzz_one(&bins, t, secs)))?;
    }
    Ok(())
}

/// Run target `t` (its binary in `bins`) for `secs` seconds; its output
/// is printed when it ends, so that two runs' lines do not interleave.
fn fuzz_one(bins: &Path, t: &str, secs: u32) -> Result<(), String> {
    let work = cross_target_dir("fuzz-corpus").join(t);
    std::fs::create_dir_all(&work).map_err(|e| format!("{}: {e}", work.display()))?;
    let seeds = root().join("fuzz/corpus").join(t);
    for f in std::fs::read_dir(&seeds)
        .map_err(|e| format!("{}: {e}", seeds.display()))?
        .flatten()
    {
        let _ = std::fs::copy(f.path(), work.join(f.file_name()));
    }
    let out = Command::new(bins.join(t))
        .arg(&work)
        .args([
            &format!("-max_total_time={secs}"),
            // A slow input is a finding (a model once spun the matrix
            // exponential forever), not a 20-minute stall.
            "-timeout=10",
            "-max_len=4096",
            "-print_final_stats=1",
        ])
        .output()
        .map_err(|e| format!("fuzz {t}: could not start: {e}"))?;
    let log = String::from_utf8_lossy(&out.stderr);
    if out.status.success() {
        // The final stats, not every new input's line.
        let stats: Vec<&str> = log
            .lines()
            .filter(|l| l.starts_with("stat::") || l.starts_with("Done"))
            .collect();
        eprintln!("xtask: fuzz {t} for {secs} s\n{}", stats.join("\n"));
        Ok(())
    } else {
        eprintln!("{log}");
        Err(format!("fuzz {t}: failed ({})", out.status))
    }
}

/// Build the targets for the host named as a target, so that the flags
/// reach the targets and their dependencies but not build scripts and
/// procedural macros; the folder the binaries are in.
fn build() -> Result<PathBuf, String> {
    let host = host_triple()?;
    run(
        "build the fuzz targets (SanitizerCoverage, release)",
        cargo()
            .env("RUSTFLAGS", RUSTFLAGS.join(" "))
            .env_remove("CARGO_ENCODED_RUSTFLAGS")
            .args(["build", "--release", "--bins", "--manifest-path"])
            .arg(root().join("fuzz/Cargo.toml"))
            .args(["--target", &host, "--target-dir"])
            .arg(target_dir()),
    )?;
    Ok(target_dir().join(host).join("release"))
}

/// The triple rustc builds for by default.
fn host_triple() -> Result<String, String> {
    let rustc = std::env::var("RUSTC").unwrap_or("rustc".into());
    let out = Command::new(&rustc)
        .arg("-vV")
        .output()
        .map_err(|e| format!("{rustc} -vV: {e}"))?;
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .find_map(|l| l.strip_prefix("host: ").map(str::to_string))
        .ok_or_else(|| format!("{rustc} -vV named no host"))
}
