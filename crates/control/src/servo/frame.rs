//! What a tick reads and what it answers, per axis.

use crate::safety::Faults;
use crate::{Position, Real};

/// The sensors of one tick of a device with `N` axes (one unless named),
/// all sampled at one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SensorFrame<R = f32, const N: usize = 1> {
    /// Timer tick number (must increase by one every tick).
    pub tick: u32,
    /// Each axis's raw hardware encoder counter.
    pub encoder_raw: [u32; N],
    /// Each axis's load-cell force on the handle along the axis (N); only
    /// the admittance display reads them.
    pub load_cell_n: [R; N],
    /// Dead-man switch closed (operator present); one for the device.
    pub dead_man_closed: bool,
}

impl<R, const N: usize> SensorFrame<R, N> {
    /// Tick `tick`'s encoder counts and load-cell forces (N), with the
    /// dead-man switch closed: the operator holds the handle.
    pub const fn held(tick: u32, encoder_raw: [u32; N], load_cell_n: [R; N]) -> Self {
        SensorFrame {
            tick,
            encoder_raw,
            load_cell_n,
            dead_man_closed: true,
        }
    }
}

impl<R: Real, const N: usize> Default for SensorFrame<R, N> {
    fn default() -> Self {
        SensorFrame {
            tick: 0,
            encoder_raw: [0; N],
            load_cell_n: [R::ZERO; N],
            dead_man_closed: false,
        }
    }
}

/// The result of one tick of every axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ServoOutput<R = f32, const N: usize = 1> {
    /// Force to hold on each axis's actuator (N), after the safety layer;
    /// positive resists positive motion along the axis (the paper's `f_a`).
    pub actuator_force_n: [R; N],
    /// What the laws asked for before the safety layer (N).
    pub commanded_force_n: [R; N],
    /// Each axis's position from its encoder.
    pub position: [Position; N],
    /// Each axis's first-difference velocity (m/s).
    pub velocity_mps: [R; N],
    /// The VE's velocity along each axis, `v_e` (m/s).
    pub ve_velocity_mps: [R; N],
    /// The force on the VE along each axis, `f_e` (N).
    pub ve_force_n: [R; N],
    /// The force in each axis's virtual coupling (N).
    pub coupling_force_n: [R; N],
    /// Impedance display: the VE point each coupling holds; admittance
    /// display: each axis's position command `x_cmd`.
    pub reference: [Position; N],
    /// Latched faults, whichever axis found them: any gives zero force on
    /// every axis.
    pub faults: Faults,
    /// Whether the safety layer clipped each axis's force.
    pub limited: [bool; N],
}

impl<R: Real, const N: usize> ServoOutput<R, N> {
    /// No force on any axis, the device at `position` moving at
    /// `velocity_mps` (m/s): a disarmed board's last output before its
    /// first tick, and a faulted tick's.
    #[inline(always)]
    pub fn at_rest(position: [Position; N], velocity_mps: [R; N]) -> Self {
        ServoOutput {
            actuator_force_n: [R::ZERO; N],
            commanded_force_n: [R::ZERO; N],
            position,
            velocity_mps,
            ve_velocity_mps: [R::ZERO; N],
            ve_force_n: [R::ZERO; N],
            coupling_force_n: [R::ZERO; N],
            reference: position,
            faults: Faults::NONE,
            limited: [false; N],
        }
    }
}

impl<R: Real, const N: usize> Default for ServoOutput<R, N> {
    fn default() -> Self {
        Self::at_rest([Position::ZERO; N], [R::ZERO; N])
    }
}
