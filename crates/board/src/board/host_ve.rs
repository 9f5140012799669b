//! The VE on the host (protocol 8): the coupling runs here at the servo's
//! rate against the points the host's VE sends at its own rate, held
//! between updates. An armed board that runs past its deadline on one
//! update faults to zero force: a late host never makes a force.

use super::Board;
use twoport_control::drive::Drive;
use twoport_control::world::{Held, World};
use twoport_control::{Faults, Position};
use twoport_link::{BoardMode, Message, ModeRefusal, ModeRequest, VeSource, VeUpdate};

/// The host's VE as the board holds it.
#[derive(Clone, Copy, Debug)]
pub(super) struct HostVe<const N: usize> {
    /// The points, held between updates.
    pub(super) world: Held<N>,
    /// Ticks one update may serve.
    deadline_ticks: u32,
    /// Ticks run since the last update taken (or since arming).
    age_ticks: u32,
    /// The last update taken.
    seq: Option<u32>,
}

impl<const N: usize> HostVe<N> {
    /// The last update's number, 0 before any.
    pub(super) fn seq(&self) -> u32 {
        self.seq.unwrap_or(0)
    }
}

impl<D: Drive<N>, const R: usize, const N: usize> Board<D, R, N> {
    /// Where the VE the coupling holds runs.
    pub fn ve_source(&self) -> VeSource {
        match &self.host {
            None => VeSource::Board,
            Some(h) => VeSource::Host {
                ramp_ticks: h.world.ramp_ticks(),
                deadline_ticks: h.deadline_ticks,
            },
        }
    }

    /// `SetVe`: a disarmed board switches its VE, and says which it runs.
    pub(super) fn set_ve(&mut self, source: VeSource) {
        if self.mode != BoardMode::Disarmed {
            let mode = self.mode;
            return self.refuse(ModeRequest::SetVe, ModeRefusal::NotDisarmed { mode });
        }
        self.host = match source {
            VeSource::Board => None,
            VeSource::Host {
                deadline_ticks: 0, ..
            } => return self.refuse(ModeRequest::SetVe, ModeRefusal::BadDeadline),
            VeSource::Host {
                ramp_ticks,
                deadline_ticks,
            } => {
                let period_s = self.servo.servo().safety().configs()[0].period_s;
                let x = self.servo.servo().position();
                Some(HostVe {
                    world: Held::new(x, period_s, ramp_ticks),
                    deadline_ticks,
                    age_ticks: 0,
                    seq: None,
                })
            }
        };
        let now = self.ve_source();
        self.queue(Message::Ve(now));
    }

    /// `VeUpdate`: the surfaces move at the next tick, if the board runs
    /// the host's VE, the update is newer than the last taken, it is for
    /// this board's axes and every surface is in range (±2.147 m). Any
    /// other is ignored, and a host that sends nothing else runs into its
    /// deadline.
    pub(super) fn ve_update(&mut self, u: VeUpdate) {
        let Some(h) = self.host.as_mut() else {
            return;
        };
        let newer = h.seq.is_none_or(|s| (u.seq.wrapping_sub(s) as i32) > 0);
        let (Some(pm), Some(contact)) = (u.position_pm.to_array::<N>(), u.contact.to_array::<N>())
        else {
            return;
        };
        let mut points = [Position::ZERO; N];
        for (x, pm) in points.iter_mut().zip(pm) {
            match i32::try_from(pm / 1000) {
                Ok(nm) => *x = Position::from_nm(nm),
                Err(_) => return,
            }
        }
        if newer {
            h.world.set(points, contact);
            h.age_ticks = 0;
            h.seq = Some(u.seq);
        }
    }

    /// Arming on the host's VE starts its points at the handle, at rest,
    /// with a whole deadline to run.
    pub(super) fn host_ve_armed(&mut self) {
        let x = self.servo.servo().position();
        if let Some(h) = self.host.as_mut() {
            World::<f32, N>::reset_axes(&mut h.world, &x);
            h.age_ticks = 0;
        }
    }

    /// The deadline's part of a tick, before the law runs: an armed board
    /// past it faults, so the tick's force is zero.
    pub(super) fn host_ve_tick(&mut self) {
        let armed = self.mode == BoardMode::Armed;
        if let Some(h) = self.host.as_mut() {
            h.age_ticks = h.age_ticks.saturating_add(1);
            if armed && h.age_ticks > h.deadline_ticks {
                self.servo.servo_mut().trip(Faults::VE_STALE);
            }
        }
    }
}
