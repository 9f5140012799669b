//! How to build for thumbv7em-none-eabihf on this machine: the rustup target
//! where it is installed, otherwise Debian's rustc with `build-std` and
//! arm-none-eabi-ld (see docs/firmware.md).

use std::path::Path;
use std::process::Command;

/// Cortex-M4F with FPU.
pub const TARGET: &str = "thumbv7em-none-eabihf";

/// A cargo invocation able to build for [`TARGET`].
pub enum Toolchain {
    /// `rustup target add thumbv7em-none-eabihf` has been done.
    Rustup,
    /// Debian's rustc-web/cargo-web/rust-web-src and gcc-arm-none-eabi.
    Debian,
}

impl Toolchain {
    /// Pick one, or say what to install.
    pub fn detect() -> Result<Self, String> {
        let rustup_has_target = Command::new("rustup")
            .args(["target", "list", "--installed"])
            .output()
            .map(|o| {
                String::from_utf8_lossy(&o.stdout)
                    .lines()
                    .any(|l| l.trim() == TARGET)
            })
            .unwrap_or(false);
        if rustup_has_target {
            return Ok(Toolchain::Rustup);
        }
        let debian = [
            "/usr/bin/rustc",
            "/usr/bin/cargo",
            "/usr/lib/rustlib/src/rust/library",
        ]
        .iter()
        .all(|p| Path::new(p).exists());
        let ld = Command::new("arm-none-eabi-ld")
            .arg("--version")
            .output()
            .is_ok();
        if debian && ld {
            return Ok(Toolchain::Debian);
        }
        Err(format!(
            "no toolchain for {TARGET}: either `rustup target add {TARGET}`, or install \
             Debian's rustc-web cargo-web rust-web-src gcc-arm-none-eabi"
        ))
    }

    /// `cargo build --release --target thumbv7em-none-eabihf` in `dir`, with
    /// artefacts under `target_dir`.
    pub fn build(&self, dir: &Path, target_dir: &Path, extra: &[&str]) -> Command {
        let mut c = match self {
            Toolchain::Rustup => Command::new(std::env::var("CARGO").unwrap_or("cargo".into())),
            Toolchain::Debian => {
                let mut c = Command::new("/usr/bin/cargo");
                c.env("RUSTC", "/usr/bin/rustc")
                    .env("RUSTC_BOOTSTRAP", "1")
                    // Debian's rustc has no rust-lld; the firmware's
                    // config.toml adds -Tlink.x, cargo merges this list in.
                    .env(
                        "CARGO_TARGET_THUMBV7EM_NONE_EABIHF_LINKER",
                        "arm-none-eabi-ld",
                    )
                    .env(
                        "CARGO_TARGET_THUMBV7EM_NONE_EABIHF_RUSTFLAGS",
                        "-C linker-flavor=ld",
                    )
                    .env_remove("RUSTUP_TOOLCHAIN")
                    .env_remove("CARGO");
                c
            }
        };
        c.current_dir(dir)
            .args(["build", "--release", "--target", TARGET, "--target-dir"])
            .arg(target_dir)
            .args(extra);
        if let Toolchain::Debian = self {
            c.arg("-Zbuild-std=core");
        }
        c
    }

    /// A name for messages.
    pub fn describe(&self) -> &'static str {
        match self {
            Toolchain::Rustup => "rustup target",
            Toolchain::Debian => "Debian rustc with build-std",
        }
    }
}
