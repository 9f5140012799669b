//! The board's state machine: disarmed at boot with the outputs off,
//! homing to find the encoder's offset, armed only when it is safe to be.
//!
//! ```text
//!            Home (no fault)              stop found: calibrated
//! Disarmed ───────────────────▶ Homing ─────────────────────────▶ Disarmed
//!   │  ▲                          │ timeout: HOMING_FAILED fault ──▶ Disarmed
//!   │  │ Disarm, or any fault     │ Disarm, or any fault ──────────▶ Disarmed
//!   │  └───────────── Armed ◀─────┘ (never directly)
//!   └──── Arm: calibrated, proven gains, dead-man closed, no fault ───▶ Armed
//! ```
//!
//! Every change of mode is reported with a [`Message::Status`]; a refused
//! request with a [`Message::ModeRefused`] that names the reason.

use super::Board;
use crate::support::BoardSupport;
use twoport_control::drive::Drive;
use twoport_control::homing::{Homing, HomingState};
use twoport_control::servo::ServoOutput;
use twoport_control::Faults;
use twoport_link::{Axes, BoardMode, Message, ModeRefusal, ModeRequest, Status};

impl<D: Drive<N>, const R: usize, const N: usize> Board<D, R, N> {
    /// Where the state machine is.
    pub fn mode(&self) -> BoardMode {
        self.mode
    }

    /// Whether every axis's encoder offset is known (homed or calibrated).
    pub fn calibrated(&self) -> bool {
        self.calibrated
    }

    /// The state the link reports.
    pub fn status(&self) -> Status {
        let safety = self.servo.servo().safety();
        let (faults, first) = (safety.faults(), safety.first_fault());
        Status {
            mode: self.mode,
            calibrated: self.calibrated,
            faults: faults.0,
            first_fault: first.0,
            session: self.session,
        }
    }

    /// Latch a fault the board found outside the servo's checks (a
    /// watchdog reset at boot, a sensor that did not answer). It disarms
    /// the board at the next tick, like any fault.
    pub fn trip(&mut self, f: Faults) {
        self.servo.servo_mut().trip(f);
    }

    /// Whether the amplifier's outputs are on: only while homing or armed,
    /// switched by [`control_tick`](Self::control_tick) through
    /// [`BoardSupport::set_outputs`].
    pub fn outputs_on(&self) -> bool {
        self.outputs_on
    }

    pub(super) fn queue_status(&mut self) {
        self.queue(Message::Status(self.status()));
    }

    pub(super) fn refuse(&mut self, asked: ModeRequest, why: ModeRefusal) {
        self.queue(Message::ModeRefused { asked, why });
    }

    pub(super) fn set_mode(&mut self, mode: BoardMode) {
        if self.mode != mode {
            self.mode = mode;
            self.queue_status();
        }
    }

    pub(super) fn latched(&self) -> Option<ModeRefusal> {
        let f = self.servo.servo().safety().faults();
        (!f.is_empty()).then_some(ModeRefusal::Faulted { faults: f.0 })
    }

    /// `Arm`: the law runs and the outputs come on, ramping in, if every
    /// condition holds; otherwise the first that fails is named.
    pub(super) fn arm(&mut self) {
        let why = self
            .latched()
            .or(match self.mode {
                BoardMode::Homing | BoardMode::Identifying => {
                    Some(ModeRefusal::NotDisarmed { mode: self.mode })
                }
                _ => None,
            })
            .or((!self.calibrated).then_some(ModeRefusal::NotCalibrated))
            .or(self
                .check(&self.servo.servo().gains())
                .err()
                .map(|_| ModeRefusal::GainsNotProven))
            .or((!self.dead_man_closed).then_some(ModeRefusal::DeadManOpen));
        if let Some(why) = why {
            return self.refuse(ModeRequest::Arm, why);
        }
        match (self.mode, self.servo.servo_mut().enable()) {
            // Armed already: the answer is the status.
            (BoardMode::Armed, Ok(())) => self.queue_status(),
            (_, Ok(())) => {
                self.host_ve_armed();
                self.set_mode(BoardMode::Armed);
            }
            (_, Err(f)) => self.refuse(ModeRequest::Arm, ModeRefusal::Faulted { faults: f.0 }),
        }
    }

    /// `Disarm`, or any fault: zero force at once, outputs off at the tick.
    /// A homing run in progress is abandoned; the calibration stays what
    /// it was.
    pub(super) fn disarm(&mut self) {
        self.servo.servo_mut().disable();
        self.homing = None;
        self.experiment = None;
        self.set_mode(BoardMode::Disarmed);
    }

    /// `Home`: a disarmed board without faults starts every axis's homing
    /// run from where it stands.
    pub(super) fn home(&mut self) {
        let why = (!D::HOMES)
            .then_some(ModeRefusal::Unsupported)
            .or(self.latched())
            .or(match self.mode {
                BoardMode::Disarmed => None,
                m => Some(ModeRefusal::NotDisarmed { mode: m }),
            });
        if let Some(why) = why {
            return self.refuse(ModeRequest::Home, why);
        }
        let x = self.servo.servo().position();
        let runs: [Option<Homing>; N] =
            core::array::from_fn(|i| Homing::new(self.homing_cfg[i], x[i]).ok());
        if runs.iter().any(Option::is_none) {
            // The image's homing constants are wrong: as unsafe as a fault.
            self.servo.servo_mut().trip(Faults::HOMING_FAILED);
            return self.refuse(
                ModeRequest::Home,
                ModeRefusal::Faulted {
                    faults: Faults::HOMING_FAILED.0,
                },
            );
        }
        match self.servo.servo_mut().enable() {
            Ok(()) => {
                self.homing = Some(runs);
                self.set_mode(BoardMode::Homing);
            }
            Err(f) => self.refuse(ModeRequest::Home, ModeRefusal::Faulted { faults: f.0 }),
        }
    }

    /// `Calibrate`: a disarmed board takes the host's word for where each
    /// axis stands (all of them or, naming why, none).
    pub(super) fn calibrate(&mut self, position_pm: Axes<i64>) {
        if self.mode != BoardMode::Disarmed {
            let mode = self.mode;
            return self.refuse(ModeRequest::Calibrate, ModeRefusal::NotDisarmed { mode });
        }
        let Some(pm) = position_pm.to_array::<N>() else {
            let why = ModeRefusal::WrongAxisCount { axes: N as u8 };
            return self.refuse(ModeRequest::Calibrate, why);
        };
        if !self.servo.calibrate_pico(pm) {
            return self.refuse(ModeRequest::Calibrate, ModeRefusal::OutOfRange);
        }
        self.calibrated = true;
        self.queue_status();
    }

    /// The state machine's part of a tick: a fault disarms, and each
    /// axis's homing run that has ended calibrates its encoder (the axis
    /// then holds no force) or latches its failure. The board is
    /// calibrated when every axis has homed.
    pub(super) fn after_tick(&mut self, out: &ServoOutput<f32, N>) {
        if let Some(mut runs) = self.homing {
            let mut seeking = false;
            for (axis, run) in runs.iter_mut().enumerate() {
                let Some(h) = run else { continue };
                let cfg = *h.config();
                // Homing on an index: its first pulse calibrates the
                // encoder from the count it latched.
                let done = match (cfg.index_position, self.index[axis], h.state()) {
                    (Some(at), Some(raw), _) => self
                        .servo
                        .servo_mut()
                        .calibrate_axis_at(axis, raw, at)
                        .is_ok(),
                    (_, _, HomingState::Seeking) => {
                        seeking = true;
                        continue;
                    }
                    (_, _, HomingState::Found) => {
                        // (The loop calibrates only axes it has.)
                        let _ = self
                            .servo
                            .servo_mut()
                            .calibrate_axis(axis, cfg.stop_position);
                        true
                    }
                    (_, _, HomingState::TimedOut) => false,
                };
                if !done {
                    self.servo.servo_mut().trip(Faults::HOMING_FAILED);
                    return self.disarm();
                }
                *run = None;
            }
            self.homing = Some(runs);
            if !seeking {
                self.calibrated = true;
                self.disarm();
            }
        }
        if self.mode != BoardMode::Disarmed && !out.faults.is_empty() {
            self.disarm();
        }
    }

    /// Switch the outputs to follow the mode.
    pub(super) fn drive_outputs(&mut self, io: &mut impl BoardSupport<N>) {
        let on = self.mode != BoardMode::Disarmed;
        if on != self.outputs_on {
            io.set_outputs(on);
            self.outputs_on = on;
        }
    }
}
