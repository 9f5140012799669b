//! Judging a PIL run: how far it drifts from its reference run, and why
//! it fails the check `host-sim pil --check` makes (bit for bit with the
//! in-process loop, every tick run, corrupted frames dropped, zero force
//! within the watchdog's deadline after a link loss).

use super::{Run, HOMING_TOLERANCE_M};
use crate::link::LinkFaults;
use twoport_board::excalibur;
use twoport_link::ConfigSource;

/// How far two runs of the same scene drift apart.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct Comparison {
    /// Ticks compared.
    pub ticks: u64,
    /// Largest handle-position difference (m).
    pub max_position_error_m: f64,
    /// Largest actuator-force difference (N).
    pub max_force_error_n: f64,
    /// Ticks whose duty differs.
    pub duty_mismatches: u64,
    /// Whether the two boards armed (or homed) at different ticks.
    pub start_differs: bool,
    /// Whether the two boards' specifications differ (but for the link's
    /// rate: a property of the board's hardware, not of its image).
    pub spec_differs: bool,
}

/// Compare a run with its reference, tick by tick, every axis.
pub fn compare<const N: usize>(a: &Run<N>, b: &Run<N>) -> Comparison {
    let mut c = Comparison {
        ticks: a.samples.len().min(b.samples.len()) as u64,
        ..Comparison::default()
    };
    for (x, y) in a.samples.iter().zip(&b.samples) {
        for i in 0..N {
            let dx = (x.handle_m[i] - y.handle_m[i]).abs();
            let df = (x.actuator_n[i] - y.actuator_n[i]).abs();
            c.max_position_error_m = c.max_position_error_m.max(dx);
            c.max_force_error_n = c.max_force_error_n.max(df);
        }
    }
    c.start_differs = (a.armed_at_tick, a.homing.map(|h| h.0), a.experiment)
        != (b.armed_at_tick, b.homing.map(|h| h.0), b.experiment);
    // (The link's rate, the count's rate and the latency measured are the
    // hardware's, not the image's.)
    let image = |s: Option<twoport_link::Spec>| {
        s.map(|s| twoport_link::Spec {
            link_bytes_per_s: None,
            count_hz: None,
            worst_latency_cycles: 0,
            ..s
        })
    };
    c.spec_differs = image(a.spec) != image(b.spec);
    c.duty_mismatches = a
        .duties
        .iter()
        .zip(&b.duties)
        .filter(|(x, y)| x != y)
        .count() as u64;
    c
}

/// Why a PIL run fails its check, or nothing where it passes. `run` is the
/// board's, compared with the in-process loop as `c`; it was to take
/// `ticks` ticks with the host's heartbeats stopping at `faults.link_loss_at`,
/// after which the board must have zeroed the force within
/// `deadline_ticks`. A run fails where the board differs from the loop at
/// all (bit for bit), where ticks are missing, where it dropped fewer frames
/// than were corrupted on purpose, or where it was late to zero the force
/// (or was not pushing before the loss, so the check would prove nothing).
pub fn failures<const N: usize>(
    run: &Run<N>,
    c: &Comparison,
    ticks: u64,
    faults: LinkFaults,
    deadline_ticks: u64,
) -> Vec<String> {
    let mut bad = Vec::new();
    if c.duty_mismatches > 0 || c.max_position_error_m > 0.0 || c.max_force_error_n > 0.0 {
        bad.push(format!(
            "the board differs from the in-process loop ({} duties, {:.3e} m, {:.3e} N)",
            c.duty_mismatches, c.max_position_error_m, c.max_force_error_n
        ));
    }
    match run.config {
        Some((ConfigSource::Defaults { .. }, ConfigSource::Stored { .. })) => {}
        Some((booted, saved)) => bad.push(format!(
            "a fresh board should boot on its defaults and save: {booted:?}, then {saved:?}"
        )),
        None => bad.push("the board never said where its configuration came from".into()),
    }
    if c.start_differs {
        bad.push(format!(
            "the board armed at tick {}, the in-process loop at another",
            run.armed_at_tick
        ));
    }
    if c.ticks != ticks {
        bad.push(format!("{} of {ticks} ticks ran", c.ticks));
    }
    if c.spec_differs {
        bad.push(format!(
            "the board's specification differs from the in-process image's: {:?}",
            run.spec
        ));
    }
    if let Some((x, at)) = run.experiment {
        // Every tick's telemetry, up to the run's end. A tick's telemetry
        // follows its actuator frame, so whether the run's last tick's
        // was read before the run stopped depends on the transport's
        // timing: either count is complete.
        let played = u64::from(x.period_ticks * x.periods);
        let ran = ticks.saturating_sub(at);
        let least = played.min(ran.saturating_sub(1));
        let most = played.min(ran);
        match run.experiment_log(false) {
            Some(Ok(log)) if (least..=most).contains(&(log.force_n.len() as u64)) => {}
            Some(Ok(log)) => bad.push(format!(
                "the experiment streamed {} of its {least} to {most} ticks",
                log.force_n.len()
            )),
            Some(Err(e)) => bad.push(e.to_string()),
            None => {}
        }
    }
    // A host VE's updates reached the board: the last telemetry holds one
    // sent at most a telemetry period before the end.
    if run.ve_updates_sent > 0 {
        let held = run.telemetry.last().map_or(0, |t| t.ve_seq);
        if held == 0 || held > run.ve_updates_sent {
            bad.push(format!(
                "the host sent {} VE updates and the board's last telemetry holds update {held}",
                run.ve_updates_sent
            ));
        }
    }
    if u64::from(run.board_stats.rx.dropped()) < run.corrupted_sent {
        bad.push(format!(
            "{} corrupted frames sent, the board dropped {}",
            run.corrupted_sent,
            run.board_stats.rx.dropped()
        ));
    }
    if let Some((n, err_m)) = run.homing {
        if err_m.is_nan() || err_m.abs() > HOMING_TOLERANCE_M {
            bad.push(format!(
                "homing calibrated {:.1} um off the plant (tolerance {:.0} um)",
                err_m * 1e6,
                HOMING_TOLERANCE_M * 1e6
            ));
        }
        let limit = excalibur::HOMING.force_limit_n as f64;
        let io = twoport_board::IoScale::EXCALIBUR;
        let peak = run.duties[..(n as usize + 1).min(run.duties.len())]
            .iter()
            .flat_map(|d| d.iter())
            .map(|d| io.force_n(*d).abs() as f64)
            .fold(0.0, f64::max);
        if peak > limit + 0.01 {
            bad.push(format!("homing pushed {peak:.2} N (limit {limit} N)"));
        }
    }
    if let (Some(t0), Some(z)) = (faults.link_loss_at, run.zero_after_loss_ticks) {
        let before = &run.duties[..(t0 as usize).min(run.duties.len())];
        if !before
            .iter()
            .rev()
            .take(10)
            .any(|d| d.iter().any(|d| *d != 0))
        {
            bad.push("no force before the link loss: the check would prove nothing".into());
        }
        if z > deadline_ticks {
            bad.push(format!(
                "zero force {z} ticks after the link loss (deadline {deadline_ticks})"
            ));
        }
    }
    bad
}
