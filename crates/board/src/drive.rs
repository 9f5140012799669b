//! What the loop drives: a servo of `N` axes, behind one trait, so that the
//! loop, its state machine and its stored configuration are written once
//! for the one-axis [`Servo`] (with or without a port layer) and the
//! `N`-axis [`AxesServo`].

use twoport_control::homing::Homing;
use twoport_control::safety::AxisError;
use twoport_control::servo::{
    AxesFrame, AxesOutput, AxesServo, Display, Gains, GainsError, PortLayer, SensorFrame, Servo,
};
use twoport_control::ve::VirtualEnvironment;
use twoport_control::world::World;
use twoport_control::{EncoderError, Faults, ParamError, Position, SafetyConfig};

/// A servo of `N` axes as the board loop runs it: every method speaks in
/// per-axis arrays, and a refusal names the axis.
pub trait Drive<const N: usize> {
    /// One control tick: the display's laws, or, while `homing` is given,
    /// each axis's homing law in their place (through the same safety
    /// layer).
    /// An axis whose run is `None` has homed and holds no force.
    fn tick(
        &mut self,
        frame: &AxesFrame<f32, N>,
        homing: Option<&mut [Option<Homing>; N]>,
    ) -> AxesOutput<f32, N>;
    /// The display every axis runs.
    fn display(&self) -> Display;
    /// Each axis's gains in force.
    fn gains(&self) -> [Gains; N];
    /// Change every axis's gains, all or (naming the axis) none.
    fn set_gains(&mut self, gains: [Gains; N]) -> Result<(), AxisError<GainsError>>;
    /// Each axis's safety limits.
    fn limits(&self) -> [SafetyConfig; N];
    /// New limits for every axis, while disabled.
    fn set_limits(&mut self, cfg: [SafetyConfig; N]) -> Result<(), AxisError<ParamError>>;
    /// The latched faults, and the first of them.
    fn faults(&self) -> (Faults, Faults);
    /// Enable force output (ramping in); refused while a fault is latched.
    fn enable(&mut self) -> Result<(), Faults>;
    /// Disable force output.
    fn disable(&mut self);
    /// Clear latched faults.
    fn clear(&mut self);
    /// A link heartbeat arrived.
    fn heartbeat(&mut self);
    /// Latch a fault found outside the tick.
    fn trip(&mut self, f: Faults);
    /// Each axis's position.
    fn position(&self) -> [Position; N];
    /// Where the virtual environment holds each axis.
    fn ve_position(&self) -> [Position; N];
    /// Every axis now reads its `position` (the host's word); the laws
    /// re-align once.
    fn calibrate(&mut self, position: [Position; N]);
    /// Axis `axis` now reads `position` (homing onto a stop).
    fn calibrate_axis(&mut self, axis: usize, position: Position);
    /// Axis `axis`'s counter read `raw` at `position` (an index pulse).
    fn calibrate_axis_at(
        &mut self,
        axis: usize,
        raw: u32,
        position: Position,
    ) -> Result<(), EncoderError>;
    /// The control period (s).
    fn period_s(&self) -> f32 {
        self.limits()[0].period_s
    }
}

/// The methods both servos answer alike, through their own inherent
/// methods of the same names.
macro_rules! shared {
    ($servo:ident) => {
        fn faults(&self) -> (Faults, Faults) {
            (self.safety().faults(), self.safety().first_fault())
        }
        fn enable(&mut self) -> Result<(), Faults> {
            $servo::enable(self)
        }
        fn disable(&mut self) {
            $servo::disable(self)
        }
        fn clear(&mut self) {
            $servo::clear(self)
        }
        fn heartbeat(&mut self) {
            $servo::heartbeat(self)
        }
        fn trip(&mut self, f: Faults) {
            $servo::trip(self, f)
        }
    };
}

impl<V: VirtualEnvironment, L: PortLayer> Drive<1> for Servo<V, f32, L> {
    #[inline(always)]
    fn tick(
        &mut self,
        frame: &AxesFrame<f32, 1>,
        homing: Option<&mut [Option<Homing>; 1]>,
    ) -> AxesOutput<f32, 1> {
        let frame = SensorFrame::from(*frame);
        let out = match homing {
            Some([Some(h)]) => self.tick_with(&frame, |x, v| h.step(x, v)),
            Some([None]) => self.tick_with(&frame, |_, _| 0.0),
            None => Servo::tick(self, &frame),
        };
        out.into()
    }
    fn display(&self) -> Display {
        Servo::display(self)
    }
    fn gains(&self) -> [Gains; 1] {
        [Servo::gains(self)]
    }
    fn set_gains(&mut self, [g]: [Gains; 1]) -> Result<(), AxisError<GainsError>> {
        Servo::set_gains(self, g).map_err(|error| AxisError { axis: 0, error })
    }
    fn limits(&self) -> [SafetyConfig; 1] {
        [*self.safety().config()]
    }
    fn set_limits(&mut self, [c]: [SafetyConfig; 1]) -> Result<(), AxisError<ParamError>> {
        Servo::set_limits(self, c).map_err(|error| AxisError { axis: 0, error })
    }
    shared!(Servo);
    fn position(&self) -> [Position; 1] {
        [Servo::position(self)]
    }
    fn ve_position(&self) -> [Position; 1] {
        [self.ve().position()]
    }
    fn calibrate(&mut self, [x]: [Position; 1]) {
        Servo::calibrate(self, x)
    }
    fn calibrate_axis(&mut self, _: usize, position: Position) {
        Servo::calibrate(self, position)
    }
    fn calibrate_axis_at(
        &mut self,
        _: usize,
        raw: u32,
        position: Position,
    ) -> Result<(), EncoderError> {
        self.calibrate_at(raw, position)
    }
}

impl<W: World<f32, N>, const N: usize> Drive<N> for AxesServo<W, f32, N> {
    #[inline(always)]
    fn tick(
        &mut self,
        frame: &AxesFrame<f32, N>,
        homing: Option<&mut [Option<Homing>; N]>,
    ) -> AxesOutput<f32, N> {
        match homing {
            Some(h) => self.tick_with(frame, |i, x, v| h[i].as_mut().map_or(0.0, |h| h.step(x, v))),
            None => AxesServo::tick(self, frame),
        }
    }
    fn display(&self) -> Display {
        AxesServo::display(self)
    }
    fn gains(&self) -> [Gains; N] {
        AxesServo::gains(self)
    }
    fn set_gains(&mut self, g: [Gains; N]) -> Result<(), AxisError<GainsError>> {
        AxesServo::set_gains(self, g)
    }
    fn limits(&self) -> [SafetyConfig; N] {
        *self.safety().configs()
    }
    fn set_limits(&mut self, c: [SafetyConfig; N]) -> Result<(), AxisError<ParamError>> {
        AxesServo::set_limits(self, c)
    }
    shared!(AxesServo);
    fn position(&self) -> [Position; N] {
        AxesServo::position(self)
    }
    fn ve_position(&self) -> [Position; N] {
        self.world().position()
    }
    fn calibrate(&mut self, position: [Position; N]) {
        AxesServo::calibrate(self, position)
    }
    fn calibrate_axis(&mut self, axis: usize, position: Position) {
        // (The loop calibrates only axes it has.)
        let _ = AxesServo::calibrate_axis(self, axis, position);
    }
    fn calibrate_axis_at(
        &mut self,
        axis: usize,
        raw: u32,
        position: Position,
    ) -> Result<(), EncoderError> {
        AxesServo::calibrate_axis_at(self, axis, raw, position).map_err(|e| e.error)
    }
}
