//! The board's own VE's parameters from the host (protocol 9): a
//! disarmed board moves its surface or changes its stiffness or damping,
//! on one axis, and says what it set.

use super::Board;
use twoport_control::drive::Drive;
use twoport_control::world::World;
use twoport_link::{BoardMode, Message, ModeRefusal, ModeRequest, VeParam};

impl<D: Drive<N>, const R: usize, const N: usize> Board<D, R, N> {
    /// `SetVeParam`: disarmed only; an axis the board has not, a value
    /// out of range or a parameter its VE has not are refused
    /// (`BadVeParam`), the VE unchanged.
    pub(super) fn set_ve_param(&mut self, axis: u8, param: VeParam) {
        if self.mode != BoardMode::Disarmed {
            let mode = self.mode;
            return self.refuse(ModeRequest::SetVeParam, ModeRefusal::NotDisarmed { mode });
        }
        let a = usize::from(axis);
        let world = self.servo.servo_mut().world_mut();
        if a >= N || world.set_axis_param(a, param).is_err() {
            return self.refuse(ModeRequest::SetVeParam, ModeRefusal::BadVeParam);
        }
        self.queue(Message::VeParamSet { axis, param });
    }
}
