//! What the drivers' tests against their emulators share: the hand, the
//! turns, the wall run and the faults mid-run. The emulators' plants
//! advance one period per command, so what is asserted does not depend on
//! the machine's speed (a tick later than the region allows engages the
//! images' passivity layer, and faults nothing: [`Pacing`] says what a
//! wall run can promise then).

use host_sim::emulate::{Emulator, Fault, Trace};
use std::sync::{Mutex, MutexGuard};
use std::time::{Duration, Instant};
use twoport_board::linkage::pc;
use twoport_control::servo::ImpedanceGains;
use twoport_host::{BoardPort, HostBoard, LinkError, PcBoard};

/// The hand of the wall runs.
pub use host_sim::emulate::PRESSING as HAND;

/// How long the drivers wait for a reply here: the emulator answers
/// every command once the machine schedules its thread, so how soon is
/// not what the tests assert (a silent device still trips it, well before
/// the loop counts as stalled, [`twoport_host::STALL`]).
pub const PATIENCE: Duration = Duration::from_millis(200);

/// The tests take turns: a loop's thread and the emulator's are the
/// machine's to schedule, and another test at once on two cores would
/// hold their ticks back.
static LOOP: Mutex<()> = Mutex::new(());

pub fn turn() -> MutexGuard<'static, ()> {
    LOOP.lock().unwrap_or_else(|p| p.into_inner())
}

/// Open the board on `port` (its `axes`), calibrate it at the image's
/// `rest_rad`, stream and arm: its region states the PC's latency.
pub fn armed_at<P: BoardPort>(port: P, axes: u8, rest_rad: &[f32]) -> HostBoard<P> {
    let mut b = HostBoard::open(port, axes).unwrap();
    assert_eq!(b.spec().latency_budget_s, pc::LATENCY_S);
    let rest: Vec<f64> = rest_rad.iter().map(|q| f64::from(*q)).collect();
    b.calibrate(&rest).unwrap();
    b.stream(10).unwrap();
    assert_eq!(b.arm().unwrap().mode, twoport_host::BoardMode::Armed);
    b
}

/// Wait up to `limit` for `done`, polling the board (with a pause
/// between polls where a thread runs its loop; none where each poll steps
/// it); the first error a poll meets ends the wait.
pub fn wait<P: BoardPort>(
    b: &mut HostBoard<P>,
    limit: Duration,
    mut done: impl FnMut(&mut HostBoard<P>) -> bool,
) -> Result<(), LinkError> {
    let until = Instant::now() + limit;
    let pause = if b.port().loop_timing().is_some() {
        2
    } else {
        0
    };
    while !done(b) && Instant::now() < until {
        b.poll()?;
        std::thread::sleep(Duration::from_millis(pause));
    }
    Ok(())
}

/// How the loop's ticks were paced, and so what a wall run can promise.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pacing {
    /// Each poll stepped one tick ([`twoport_host::SteppedPc`], no
    /// latency gate): the run is the same on any machine, so the handle
    /// holds still to within the quantum every tick of the second.
    Stepped,
    /// The loop ran in its thread ([`PcBoard`]): a tick the machine held
    /// back past the region's latency engages the image's passivity
    /// layer, which may ease that tick's torque and let the handle give a
    /// little. What holds on any machine is the second's mean position
    /// and mean torque.
    Threaded,
}

/// The pacing of the loop behind `b`.
pub fn pacing_of<P: BoardPort>(b: &HostBoard<P>) -> Pacing {
    if b.port().loop_timing().is_some() {
        Pacing::Threaded
    } else {
        Pacing::Stepped
    }
}

/// The hand presses through the wall 5 mm under the rest pose along the
/// last axis and rests on it for 10 s (10,000 periods of the device),
/// the loop in its thread ([`PcBoard`]) or stepped by the polls
/// ([`twoport_host::SteppedPc`]), with no fault; [`wall_holds`] says
/// where it rests.
pub fn rests_on_the_wall<const N: usize, P: BoardPort>(
    emu: &Emulator<N>,
    b: &mut HostBoard<P>,
    coupling: ImpedanceGains,
    quantum_m: f64,
) {
    emu.press();
    let from = emu.ticks();
    let mut faults = 0;
    let pacing = pacing_of(b);
    wait(b, Duration::from_secs(600), |b| {
        faults = b.latest().map_or(0, |s| s.faults);
        faults != 0 || emu.ticks() >= from + 10_000
    })
    .unwrap();
    assert_eq!(faults, 0);
    wall_holds(&emu.trace(), coupling, quantum_m, pacing);
}

/// The trace `t` of a hand pressing from `t.pressed_at` rests on the
/// wall through the 10th second after: where the hand's spring meets the
/// coupling in series with the wall's 100 kN/m, to within `quantum_m`,
/// the motors holding it. Stepped, the handle moves less than `quantum_m`
/// in that second; threaded, its mean is where it rests ([`Pacing`]).
pub fn wall_holds<const N: usize>(
    t: &Trace<N>,
    coupling: ImpedanceGains,
    quantum_m: f64,
    pacing: Pacing,
) {
    let from = t.pressed_at.expect("the hand pressed") as usize;
    assert!(
        t.handle_m.len() >= from + 10_000,
        "{} periods",
        t.handle_m.len() - from
    );
    let up = |x: &[f64; N]| x[N - 1];
    let y0 = up(&t.handle_m[0]);
    let second = &t.handle_m[from + 9_000..from + 10_000];
    let (lo, hi) = second.iter().fold((f64::MAX, f64::MIN), |(lo, hi), x| {
        (lo.min(up(x)), hi.max(up(x)))
    });
    let k = f64::from(coupling.k_npm);
    let press = 0.005 * HAND.stiffness_npm / (HAND.stiffness_npm + k * 100e3 / (100e3 + k));
    let at = match pacing {
        Pacing::Stepped => {
            assert!(
                hi - lo < quantum_m,
                "moved {} mm in the 10th second",
                (hi - lo) * 1e3
            );
            0.5 * (lo + hi)
        }
        Pacing::Threaded => second.iter().map(up).sum::<f64>() / second.len() as f64,
    };
    let want = y0 - 0.005 - press;
    assert!(
        (want - at).abs() < quantum_m,
        "at {} mm, not {} mm",
        (at - y0) * 1e3,
        (want - y0) * 1e3
    );
    // The motors hold the hand's push through the second: their mean
    // torque, since an eased tick need not move the handle.
    let tau: Vec<f64> = (0..N)
        .map(|i| {
            t.torque_nm[from + 9_000..from + 10_000]
                .iter()
                .map(|x| f64::from(x[i]))
                .sum::<f64>()
                / 1e3
        })
        .collect();
    assert!(
        tau.iter().any(|t| t.abs() > 1e-3),
        "mean torque {tau:?} N m"
    );
}

/// Each fault of the device mid-run stops the loop with a message saying
/// what happened and what to do (`says`), and the motors' last command is
/// zero.
pub fn each_fault_stops_at_zero<const N: usize>(
    says: [(Fault, &str); 4],
    start: impl Fn(Fault) -> Emulator<N>,
    arm: impl Fn(&Emulator<N>) -> HostBoard<PcBoard>,
) {
    for (fault, says) in says {
        let emu = start(fault);
        let mut b = arm(&emu);
        emu.press();
        match wait(&mut b, Duration::from_secs(60), |_| false) {
            Err(LinkError::Device(why)) => assert!(why.contains(says), "{fault:?}: {why}"),
            e => panic!("{fault:?}: {e:?}"),
        }
        if fault != Fault::Unplug {
            // The zero command is sent before the error is reported; the
            // emulator's thread reads it when the machine runs it.
            let until = Instant::now() + Duration::from_secs(10);
            let last = loop {
                let last = emu.trace().torque_nm.last().copied();
                if last == Some([0.0; N]) || Instant::now() > until {
                    break last;
                }
                std::thread::sleep(Duration::from_millis(5));
            };
            assert_eq!(last, Some([0.0; N]), "{fault:?}");
        }
    }
}
