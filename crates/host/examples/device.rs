//! A device the PC drives, opened by name as `twoport devices` lists it
//! (`haply-2diy`, `falcon`, `touch`), as the C and Python examples open
//! it: calibrated where the handle is held, at its image's rest pose, then
//! armed against the image's own wall 5 mm under it for two seconds.
//!
//! ```sh
//! cargo run --release -p twoport-host --example device -- NAME PATH [FILE]
//! ```
//!
//! `PATH` is a serial port (a Touch: its name in Touch Setup, `""` for
//! the default one); `FILE` a Falcon's firmware or a Touch's HD library.
//! Exits 0 when the device stayed armed for two seconds with no fault.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::{Duration, Instant};
use twoport_host::{attached, BoardMode, BoardPort, HostBoard, LinkError};

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (name, path, file) = match args.as_slice() {
        [name, path] => (name, path, None),
        [name, path, file] => (name, path, Some(PathBuf::from(file))),
        _ => {
            eprintln!("usage: device NAME PATH [FILE]");
            return ExitCode::from(2);
        }
    };
    match run(name, path, file) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("device: {e}");
            ExitCode::FAILURE
        }
    }
}

/// Serve the link for `d`, a millisecond between polls.
fn poll_for<P: BoardPort>(b: &mut HostBoard<P>, d: Duration) -> Result<(), LinkError> {
    let until = Instant::now() + d;
    while Instant::now() < until {
        b.poll()?;
        std::thread::sleep(Duration::from_millis(1));
    }
    Ok(())
}

fn run(name: &str, path: &str, file: Option<PathBuf>) -> Result<(), LinkError> {
    let rest = attached::rest_pose(name)?;
    let (pc, axes) = attached::open(name, path, file.as_deref())?;
    let mut b = HostBoard::open(pc, axes)?;
    println!("{name}: {axes} axes; calibrating with the handle at the rest pose");
    b.calibrate(&rest)?;
    b.stream(10)?;
    poll_for(&mut b, Duration::from_millis(100))?;
    let up = |b: &HostBoard<_>| {
        b.latest()
            .map_or(0.0, |s| s.axes[usize::from(axes) - 1].position_m)
    };
    let from = up(&b);
    b.arm()?;
    poll_for(&mut b, Duration::from_secs(2))?;
    let s = *b
        .latest()
        .ok_or(LinkError::Device("no state streamed".into()))?;
    let last = &s.axes[usize::from(axes) - 1];
    println!(
        "handle {:.2} mm below the rest pose (the wall is at 5 mm), force {:.3} N, faults {}",
        (from - last.position_m) * 1e3,
        last.actuator_n,
        s.faults
    );
    let t = b.port().timing();
    println!(
        "loop: period p50 {:.3} ms, p99 {:.3} ms; latency p99 {:.3} ms; {} late ticks",
        t.period_s.p50 * 1e3,
        t.period_s.p99 * 1e3,
        t.latency_s.p99 * 1e3,
        t.late
    );
    b.disarm()?;
    b.close()?;
    if s.mode != BoardMode::Armed || s.faults != 0 {
        return Err(LinkError::Device(
            "the device did not stay armed without a fault".into(),
        ));
    }
    println!("device: {name} armed for 2 s");
    Ok(())
}
