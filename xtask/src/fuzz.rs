//! The cargo-fuzz targets, each for a while.

use crate::{cargo, cross_target_dir, root, run};
use std::process::Command;

/// The cargo-fuzz targets in fuzz/.
pub(crate) const FUZZ_TARGETS: [&str; 5] = [
    "link_decoder",
    "config_record",
    "model_parser",
    "scene_parser",
    "device_packets",
];

/// Run each fuzz target for `secs` seconds on a scratch copy of its seed
/// corpus. On a stable toolchain cargo-fuzz needs RUSTC_BOOTSTRAP=1 for its
/// flags. The targets are safe Rust, whose findings are panics and
/// stalls, so they build without AddressSanitizer: a quarter less time to
/// build (3.9 against 5.2 minutes here) and more inputs a second.
pub(crate) fn fuzz(secs: u32) -> Result<(), String> {
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
                .args(["fuzz", "run", "--sanitizer", "none", t])
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
