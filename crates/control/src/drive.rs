//! What a board drives, one code path for every device: the Cartesian
//! [`Servo`] itself (one motor per axis), or a [`LinkageServo`] around one
//! (motors on joints). Either way the gains, the world and the safety
//! layer are the Cartesian servo's; what differs is how the sensors reach
//! it and how its force reaches the motors.

use crate::kinematics::Kinematics;
use crate::linkage::{LinkageOutput, LinkageServo};
use crate::servo::{PortLayer, SensorFrame, Servo, ServoOutput};
use crate::world::World;
use crate::Position;

/// One tick of a [`Drive`]: the Cartesian servo's output, and what each
/// motor is commanded (N for a Cartesian axis's motor, N m for a joint's).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Driven<const N: usize> {
    /// The Cartesian servo's tick.
    pub cartesian: ServoOutput<f32, N>,
    /// Each motor's command (N or N m).
    pub motor: [f32; N],
}

impl<const N: usize> From<ServoOutput<f32, N>> for Driven<N> {
    /// A Cartesian servo's tick: a motor on each axis, driven with the
    /// axis's force.
    fn from(cartesian: ServoOutput<f32, N>) -> Self {
        Driven {
            cartesian,
            motor: cartesian.actuator_force_n,
        }
    }
}

impl<const N: usize> From<LinkageOutput<f32, N>> for Driven<N> {
    /// A linkage's tick: a motor on each joint, driven with its torque.
    fn from(out: LinkageOutput<f32, N>) -> Self {
        Driven {
            cartesian: out.cartesian,
            motor: out.torque_nm,
        }
    }
}

/// A device's servo as a board runs it, in f32.
pub trait Drive<const N: usize> {
    /// The Cartesian servo's world.
    type World: World<f32, N>;
    /// Its port layer.
    type Layer: PortLayer;
    /// Whether it homes by a run onto a stop, axis by axis (a linkage
    /// does not: it is calibrated at a known pose).
    const HOMES: bool;
    /// The Cartesian servo: gains, world, safety layer, display.
    fn servo(&self) -> &Servo<Self::World, f32, N, Self::Layer>;
    /// The same, to change between ticks.
    fn servo_mut(&mut self) -> &mut Servo<Self::World, f32, N, Self::Layer>;
    /// One control tick.
    fn tick(&mut self, frame: &SensorFrame<f32, N>) -> Driven<N>;
    /// One control tick against `world` in place of the servo's own (the
    /// host's VE): see [`Servo::tick_on`].
    fn tick_on<V: World<f32, N>>(
        &mut self,
        frame: &SensorFrame<f32, N>,
        world: &mut V,
    ) -> Driven<N>;
    /// One tick with `law` in place of the laws and the world (homing):
    /// see [`Servo::tick_with`].
    fn tick_with(
        &mut self,
        frame: &SensorFrame<f32, N>,
        law: impl FnMut(usize, Position, f32) -> f32,
    ) -> Driven<N>;
    /// Clear latched faults (and the reasons kept beside them).
    fn clear(&mut self);
    /// Calibrate from the host's word for where the device stands, in
    /// 1e-12 of the device's coordinates: a Cartesian axis's position
    /// (pm), a joint's angle (prad). `false`, changing nothing, if a value
    /// is out of range.
    fn calibrate_pico(&mut self, at: [i64; N]) -> bool;
}

impl<W: World<f32, N>, L: PortLayer, const N: usize> Drive<N> for Servo<W, f32, N, L> {
    type World = W;
    type Layer = L;
    const HOMES: bool = true;
    fn servo(&self) -> &Servo<W, f32, N, L> {
        self
    }
    fn servo_mut(&mut self) -> &mut Servo<W, f32, N, L> {
        self
    }
    fn tick(&mut self, frame: &SensorFrame<f32, N>) -> Driven<N> {
        Servo::tick(self, frame).into()
    }
    fn tick_on<V: World<f32, N>>(
        &mut self,
        frame: &SensorFrame<f32, N>,
        world: &mut V,
    ) -> Driven<N> {
        Servo::tick_on(self, frame, world).into()
    }
    fn tick_with(
        &mut self,
        frame: &SensorFrame<f32, N>,
        law: impl FnMut(usize, Position, f32) -> f32,
    ) -> Driven<N> {
        Servo::tick_with(self, frame, law).into()
    }
    fn clear(&mut self) {
        Servo::clear(self);
    }
    fn calibrate_pico(&mut self, at: [i64; N]) -> bool {
        let mut x = [Position::ZERO; N];
        for (x, pm) in x.iter_mut().zip(at) {
            let Ok(nm) = i32::try_from(pm / 1000) else {
                return false;
            };
            *x = Position::from_nm(nm);
        }
        self.calibrate(x);
        true
    }
}

impl<K: Kinematics<f32, N>, W: World<f32, N>, L: PortLayer, const N: usize> Drive<N>
    for LinkageServo<K, W, f32, N, L>
{
    type World = W;
    type Layer = L;
    const HOMES: bool = false;
    fn servo(&self) -> &Servo<W, f32, N, L> {
        self.cartesian()
    }
    fn servo_mut(&mut self) -> &mut Servo<W, f32, N, L> {
        self.cartesian_mut()
    }
    fn tick(&mut self, frame: &SensorFrame<f32, N>) -> Driven<N> {
        LinkageServo::tick(self, frame).into()
    }
    fn tick_on<V: World<f32, N>>(
        &mut self,
        frame: &SensorFrame<f32, N>,
        world: &mut V,
    ) -> Driven<N> {
        LinkageServo::tick_on(self, frame, world).into()
    }
    fn tick_with(
        &mut self,
        frame: &SensorFrame<f32, N>,
        law: impl FnMut(usize, Position, f32) -> f32,
    ) -> Driven<N> {
        LinkageServo::tick_with(self, frame, law).into()
    }
    fn clear(&mut self) {
        LinkageServo::clear(self);
    }
    fn calibrate_pico(&mut self, at: [i64; N]) -> bool {
        // (Beyond ±10⁶ rad a value is a host's error, not an angle.)
        if at
            .iter()
            .any(|p| p.unsigned_abs() > 1_000_000_000_000_000_000)
        {
            return false;
        }
        self.calibrate_joints(at.map(|p| (p as f64 * 1e-12) as f32));
        true
    }
}
