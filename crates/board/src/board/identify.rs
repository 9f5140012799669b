//! Identification experiments: an armed board plays a multisine on one
//! axis, holds every axis where it stood, and streams every tick.
//!
//! ```text
//!          Identify: armed, calibrated, dead-man closed, no fault,
//!          a playable experiment whose hold is proven
//! Armed ─────────────────────────────────────────────▶ Identifying
//!                                                          │ every period played
//!                  Disarmed ◀──────────────────────────────┤ Disarm, or any fault
//! ```
//!
//! The experiment's law goes through the same safety layer as the
//! display's (`Drive::tick_with`), and it ends at zero force: disarmed,
//! as after homing, so that nothing the board did before the experiment
//! resumes where the device now stands.

use super::Board;
use twoport_control::drive::Drive;
use twoport_control::experiment::Experiment;
use twoport_control::multisine::Multisine;
use twoport_control::servo::{Display, Gains, ImpedanceGains};
use twoport_control::ImpedanceCoupling;
use twoport_link::{BoardMode, ExperimentRequest as Request, ModeRefusal, ModeRequest};

impl<D: Drive<N>, const R: usize, const N: usize> Board<D, R, N> {
    /// The experiment in progress, if any.
    pub fn experiment(&self) -> Option<&Experiment<N>> {
        self.experiment.as_ref()
    }

    /// `Identify`: an armed board that could arm now starts `req`, or the
    /// first condition that fails is named.
    pub(super) fn identify(&mut self, req: Request) {
        let why = self
            .latched()
            .or(match self.mode {
                BoardMode::Armed => None,
                mode => Some(ModeRefusal::NotArmed { mode }),
            })
            .or((!self.calibrated).then_some(ModeRefusal::NotCalibrated))
            .or((!self.dead_man_closed).then_some(ModeRefusal::DeadManOpen));
        if let Some(why) = why {
            return self.refuse(ModeRequest::Identify, why);
        }
        match self.experiment_for(&req) {
            Some(x) => {
                self.experiment = Some(x);
                self.set_mode(BoardMode::Identifying);
            }
            None => self.refuse(ModeRequest::Identify, ModeRefusal::BadExperiment),
        }
    }

    /// `req` as this board would play it from where the device stands, if
    /// it can: an axis it has, a band below Nyquist, a peak within the
    /// axis's continuous force and no lower than the multisine's rms (a
    /// host's peak that cannot be), and a hold inside every axis's proven
    /// region (the hold is a coupling to a fixed point). Whatever the
    /// host says, the safety layer bounds every tick's force.
    fn experiment_for(&self, req: &Request) -> Option<Experiment<N>> {
        let servo = self.servo.servo();
        let axis = usize::from(req.axis);
        let cfg = servo.safety().configs().get(axis)?;
        // (A peak that is not a number fails the rms check below.)
        if req.peak_n > cfg.continuous_force_n {
            return None;
        }
        let hold = Gains::Impedance(ImpedanceGains::new(req.hold_k_npm, req.hold_b_nspm));
        if self
            .regions
            .iter()
            .any(|r| r.check(Display::Impedance, &hold).is_err())
        {
            return None;
        }
        let excitation =
            Multisine::with_amplitude(req.period_ticks, req.first, req.last, req.amplitude_n)
                .ok()?;
        if excitation
            .rms()
            .partial_cmp(&req.peak_n)
            .is_none_or(|o| o.is_gt())
        {
            return None;
        }
        let coupling =
            ImpedanceCoupling::new(req.hold_k_npm, req.hold_b_nspm, cfg.period_s).ok()?;
        Experiment::new(axis, excitation, coupling, req.periods, servo.position()).ok()
    }

    /// The experiment's part of a tick, after its law ran: on to the next
    /// tick, and disarmed once every period has been played, or as soon as
    /// the dead-man switch opens (a record with a gap in its force is no
    /// longer periodic, and nobody is holding the handle).
    pub(super) fn after_experiment_tick(&mut self) {
        let Some(x) = self.experiment.as_mut() else {
            return;
        };
        x.advance();
        if x.done() || !self.dead_man_closed {
            self.disarm();
        }
    }
}
