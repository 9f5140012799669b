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
use twoport_control::homing::{Homing, HomingState};
use twoport_control::servo::{PortLayer, ServoOutput};
use twoport_control::ve::VirtualEnvironment;
use twoport_control::{Faults, Position};
use twoport_link::{Message, Mode, ModeRefusal, ModeRequest, Status};

impl<V: VirtualEnvironment, const R: usize, L: PortLayer> Board<V, R, L> {
    /// Where the state machine is.
    pub fn mode(&self) -> Mode {
        self.mode
    }

    /// Whether the encoder's offset is known (homed or calibrated).
    pub fn calibrated(&self) -> bool {
        self.calibrated
    }

    /// The state the link reports.
    pub fn status(&self) -> Status {
        let s = self.servo.safety();
        Status {
            mode: self.mode,
            calibrated: self.calibrated,
            faults: s.faults().0,
            first_fault: s.first_fault().0,
        }
    }

    /// Latch a fault the board found outside the servo's checks (a
    /// watchdog reset at boot, a sensor that did not answer). It disarms
    /// the board at the next tick, like any fault.
    pub fn trip(&mut self, f: Faults) {
        self.servo.trip(f);
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

    fn set_mode(&mut self, mode: Mode) {
        if self.mode != mode {
            self.mode = mode;
            self.queue_status();
        }
    }

    fn latched(&self) -> Option<ModeRefusal> {
        let f = self.servo.safety().faults();
        (!f.is_empty()).then_some(ModeRefusal::Faulted { faults: f.0 })
    }

    /// `Arm`: the law runs and the outputs come on, ramping in, if every
    /// condition holds; otherwise the first that fails is named.
    pub(super) fn arm(&mut self) {
        let why = self
            .latched()
            .or(match self.mode {
                Mode::Homing => Some(ModeRefusal::NotDisarmed { mode: self.mode }),
                _ => None,
            })
            .or((!self.calibrated).then_some(ModeRefusal::NotCalibrated))
            .or(self
                .check(&self.servo.gains())
                .err()
                .map(|_| ModeRefusal::GainsNotProven))
            .or((!self.dead_man_closed).then_some(ModeRefusal::DeadManOpen));
        if let Some(why) = why {
            return self.refuse(ModeRequest::Arm, why);
        }
        match (self.mode, self.servo.enable()) {
            // Armed already: the answer is the status.
            (Mode::Armed, Ok(())) => self.queue_status(),
            (_, Ok(())) => self.set_mode(Mode::Armed),
            (_, Err(f)) => self.refuse(ModeRequest::Arm, ModeRefusal::Faulted { faults: f.0 }),
        }
    }

    /// `Disarm`, or any fault: zero force at once, outputs off at the tick.
    /// A homing run in progress is abandoned; the calibration stays what
    /// it was.
    pub(super) fn disarm(&mut self) {
        self.servo.disable();
        self.homing = None;
        self.set_mode(Mode::Disarmed);
    }

    /// `Home`: a disarmed board without faults starts the homing run from
    /// where it stands.
    pub(super) fn home(&mut self) {
        let why = self.latched().or(match self.mode {
            Mode::Disarmed => None,
            m => Some(ModeRefusal::NotDisarmed { mode: m }),
        });
        if let Some(why) = why {
            return self.refuse(ModeRequest::Home, why);
        }
        let Ok(h) = Homing::new(self.homing_cfg, self.servo.position()) else {
            // The image's homing constants are wrong: as unsafe as a fault.
            self.servo.trip(Faults::HOMING_FAILED);
            return self.refuse(
                ModeRequest::Home,
                ModeRefusal::Faulted {
                    faults: Faults::HOMING_FAILED.0,
                },
            );
        };
        match self.servo.enable() {
            Ok(()) => {
                self.homing = Some(h);
                self.set_mode(Mode::Homing);
            }
            Err(f) => self.refuse(ModeRequest::Home, ModeRefusal::Faulted { faults: f.0 }),
        }
    }

    /// `Calibrate`: a disarmed board takes the host's word for where it
    /// stands.
    pub(super) fn calibrate(&mut self, position_pm: i64) {
        if self.mode != Mode::Disarmed {
            let mode = self.mode;
            return self.refuse(ModeRequest::Calibrate, ModeRefusal::NotDisarmed { mode });
        }
        let nm = position_pm / 1000;
        let Ok(nm) = i32::try_from(nm) else {
            return self.refuse(ModeRequest::Calibrate, ModeRefusal::OutOfRange);
        };
        self.servo.calibrate(Position::from_nm(nm));
        self.calibrated = true;
        self.queue_status();
    }

    /// The state machine's part of a tick: a fault disarms, and a homing
    /// run that has ended calibrates the encoder or latches its failure.
    pub(super) fn after_tick(&mut self, out: &ServoOutput) {
        if let Some(h) = self.homing {
            // Homing on an index: its first pulse calibrates the encoder
            // from the count it latched.
            if let (Some(at), Some(raw)) = (h.config().index_position, self.index) {
                match self.servo.calibrate_at(raw, at) {
                    Ok(()) => self.calibrated = true,
                    Err(_) => self.servo.trip(Faults::HOMING_FAILED),
                }
                return self.disarm();
            }
            match h.state() {
                HomingState::Seeking => {}
                HomingState::Found => {
                    self.servo.calibrate(h.config().stop_position);
                    self.calibrated = true;
                    self.disarm();
                }
                HomingState::TimedOut => {
                    self.servo.trip(Faults::HOMING_FAILED);
                    self.disarm();
                }
            }
        }
        if self.mode != Mode::Disarmed && !out.faults.is_empty() {
            self.disarm();
        }
    }

    /// Switch the outputs to follow the mode.
    pub(super) fn drive_outputs(&mut self, io: &mut impl BoardSupport) {
        let on = self.mode != Mode::Disarmed;
        if on != self.outputs_on {
            io.set_outputs(on);
            self.outputs_on = on;
        }
    }
}
