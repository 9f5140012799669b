//! The on-target probe in QEMU mps2-an386, its instruction counts held to
//! `firmware/probe/counts.txt`.

use crate::counts;
use crate::emulate::qemu_an386;
use crate::firmware::firmware;
use crate::root;
use std::process::Stdio;
use std::time::{Duration, Instant};

pub(crate) fn qemu() -> Result<(), String> {
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
pub(crate) fn check_counts(output: &str) -> Result<(), String> {
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
