//! What one PIL run recorded, and the identification experiment's log
//! read back from the board's telemetry.

use super::Start;
use crate::{Error, Sample};
use twoport_link::{Axes, BoardMode, ConfigSource, LinkStats, Telemetry};

/// One PIL run's record of a device of `N` axes.
#[derive(Clone, Debug)]
pub struct Run<const N: usize = 1> {
    /// One sample per tick.
    pub samples: Vec<Sample<N>>,
    /// The duties the board answered each tick, one per axis.
    pub duties: Vec<Axes<i16>>,
    /// Telemetry received.
    pub telemetry: Vec<Telemetry>,
    /// Frames the host injected corrupted.
    pub corrupted_sent: u64,
    /// The board's link counters at the end.
    pub board_stats: LinkStats,
    /// Host-side frames dropped from the board.
    pub host_dropped: u32,
    /// Ticks from the link loss to the first zero duty that stayed zero.
    pub zero_after_loss_ticks: Option<u64>,
    /// How the board was armed.
    pub start: Option<Start>,
    /// Where its configuration came from at boot, and after the run saved
    /// it (disarmed, before arming).
    pub config: Option<(ConfigSource, ConfigSource)>,
    /// The tick the board armed at.
    pub armed_at_tick: u64,
    /// Homing: the ticks it took, and how far the board's calibrated
    /// position was from the plant's then (m).
    pub homing: Option<(u64, f64)>,
    /// The identification experiment the scene asked for, and the tick
    /// the board started it at.
    pub experiment: Option<(twoport_link::ExperimentRequest, u64)>,
    /// What the board said it can do, asked before its first tick.
    pub spec: Option<twoport_link::Spec>,
    /// Host VE updates sent (0: the board's own VE ran).
    pub ve_updates_sent: u32,
}

impl<const N: usize> Default for Run<N> {
    fn default() -> Self {
        Run {
            samples: Vec::new(),
            duties: Vec::new(),
            telemetry: Vec::new(),
            corrupted_sent: 0,
            board_stats: LinkStats::default(),
            host_dropped: 0,
            zero_after_loss_ticks: None,
            spec: None,
            start: None,
            config: None,
            armed_at_tick: 0,
            homing: None,
            experiment: None,
            ve_updates_sent: 0,
        }
    }
}

impl<const N: usize> Run<N> {
    /// The identification experiment's record, from the board's
    /// telemetry of every tick it played: the excited axis's push (N,
    /// toward +x), encoder and, `with_load_cell`, load cell. `None` where
    /// the run played none; an error where a tick's telemetry is missing.
    pub fn experiment_log(
        &self,
        with_load_cell: bool,
    ) -> Option<Result<twoport_identify::log::Log, Error>> {
        let (x, _) = self.experiment?;
        Some(
            self.experiment_frames()
                .map(|frames| axis_log(&x, &frames, usize::from(x.axis), with_load_cell)),
        )
    }

    /// The experiment's record on every axis, the excited one's and the
    /// others' (their force is the hold's alone): what a fit of the
    /// coupling between axes needs.
    pub fn experiment_axes(&self) -> Option<Result<Vec<twoport_identify::log::Log>, Error>> {
        let (x, _) = self.experiment?;
        Some(
            self.experiment_frames()
                .map(|frames| (0..N).map(|a| axis_log(&x, &frames, a, false)).collect()),
        )
    }

    /// The telemetry of every tick the experiment played, or the gap in
    /// it.
    fn experiment_frames(&self) -> Result<Vec<&Telemetry>, Error> {
        let frames: Vec<&Telemetry> = self
            .telemetry
            .iter()
            .filter(|t| t.mode == BoardMode::Identifying)
            .collect();
        if let Some(w) = frames
            .windows(2)
            .find(|w| w[1].tick != w[0].tick.wrapping_add(1))
        {
            return Err(pil_err!(
                "the experiment's telemetry jumps from tick {} to {}: its record has a gap",
                w[0].tick,
                w[1].tick
            ));
        }
        Ok(frames)
    }
}

/// One axis's record of experiment `x` from its `frames`.
fn axis_log(
    x: &twoport_link::ExperimentRequest,
    frames: &[&Telemetry],
    axis: usize,
    with_load_cell: bool,
) -> twoport_identify::log::Log {
    let get = |f: &dyn Fn(&twoport_link::AxisTelemetry) -> f64| -> Vec<f64> {
        frames
            .iter()
            .map(|t| t.axes.get(axis).map_or(f64::NAN, f))
            .collect()
    };
    twoport_identify::log::Log {
        // (A PIL scene ticks at the board's 1 kHz.)
        period_s: 1e-3,
        force_n: get(&|a| -f64::from(a.actuator_n)),
        position_m: get(&|a| a.position_pm as f64 * 1e-12),
        load_cell_n: with_load_cell.then(|| get(&|a| f64::from(a.load_cell_n))),
        excitation: Some(twoport_identify::log::Excitation::Periodic {
            period_ticks: x.period_ticks as usize,
            first: x.first as usize,
            last: x.last as usize,
        }),
    }
}
