//! Running one of the project's command-line tools as a user does, for the
//! crates' CLI tests: from the repository root, one JSON object on stdout,
//! or exit code 2 with the reason on stderr. Included by each crate's
//! `tests/cli.rs` with `#[path]`, so that both use one helper.

use serde_json::Value;
use std::process::{Command, Output};

/// A tool binary, run from the repository root.
pub struct Tool {
    /// The binary (`env!("CARGO_BIN_EXE_...")`).
    pub bin: &'static str,
    /// The repository root.
    pub root: &'static str,
}

impl Tool {
    /// Run with `args`.
    pub fn run(&self, args: &[&str]) -> Output {
        Command::new(self.bin)
            .args(args)
            .current_dir(self.root)
            .output()
            .expect("run the tool")
    }

    /// Run with `args`; it must succeed and print one JSON object.
    pub fn json(&self, args: &[&str]) -> Value {
        let out = self.run(args);
        assert!(
            out.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let text = String::from_utf8(out.stdout).unwrap();
        assert_eq!(text.trim().lines().count(), 1, "one JSON object: {text}");
        serde_json::from_str(&text).unwrap()
    }

    /// Run with `args` and close its standard output before it writes
    /// (or after: then the report went into the pipe's buffer, and all is
    /// well too). It must end with code 0 and no panic, as a Unix filter
    /// whose reader stopped (`| head`) does.
    #[allow(dead_code)]
    pub fn closes_quietly(&self, args: &[&str]) {
        use std::process::Stdio;
        let mut child = Command::new(self.bin)
            .current_dir(self.root)
            .args(args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("run the tool");
        drop(child.stdout.take());
        let out = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        assert_eq!(out.status.code(), Some(0), "{args:?}: {err}");
    }

    /// Run with `args`; it must fail with exit code 2, print nothing on
    /// stdout, and say why on stderr, which is returned.
    #[allow(dead_code)]
    pub fn failure(&self, args: &[&str]) -> String {
        let out = self.run(args);
        assert_eq!(out.status.code(), Some(2), "{args:?} should fail with 2");
        assert!(out.stdout.is_empty());
        String::from_utf8(out.stderr).unwrap()
    }
}

/// A fresh folder under the system's temporary one for a test named
/// `name`, unique to this process; the test removes it when it ends.
#[allow(dead_code)]
pub fn scratch(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("twoport-cli-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}
