//! A haptic display on a linkage: joint encoders in, joint torques out,
//! the coupling and the VE in Cartesian space between them.
//!
//! [`LinkageServo`] reads each joint's encoder, runs the device's
//! [`Kinematics`] to the handle's position and Jacobian, and hands the
//! position to the N-axis Cartesian [`Servo`]: the same estimator, laws,
//! world and safety layer as a Cartesian device's, so the gains the
//! designer proves over the workspace are the gains it runs. The
//! Cartesian force comes back through the Jacobian's transpose as joint
//! torques, and each motor's peak and I²t limits scale the torque vector
//! as a whole. A pose the kinematics cannot serve (singular, unreachable,
//! or outside the joint limits the proof covered) latches
//! [`Faults::KINEMATICS`] and the reason, and every motor holds zero
//! torque.

mod gravity;
mod hardware;
mod joints;
mod motors;
#[cfg(test)]
mod tests;

pub use gravity::Gravity;
pub use hardware::Hardware;
pub use joints::{JointEncoder, JointEncoderError};
pub use motors::{LimitedTorques, MotorConfig, MotorLimits};

use crate::kinematics::{Jointed, Kinematics, KinematicsFault};
use crate::safety::AxisError;
use crate::servo::{Direct, Gains, GainsError, PortLayer, SensorFrame, Servo, ServoOutput};
use crate::world::World;
use crate::{Encoder, Faults, ParamError, Position, Real, SafetyConfig};

/// The joint angles the proof covered: each joint's `[lo, hi]` (rad).
pub type JointLimits<const N: usize> = [[f32; 2]; N];

/// One tick of a linkage: the motors' torques and the Cartesian servo's
/// tick behind them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LinkageOutput<R, const N: usize> {
    /// Each motor's torque at its joint (N m), positive resisting positive
    /// joint motion (`τ = J^T f_a`, the paper's `f_a` at the handle).
    pub torque_nm: [R; N],
    /// Whether the motors' limits scaled the torques down.
    pub torque_limited: bool,
    /// The joint angles read this tick (rad).
    pub q_rad: [R; N],
    /// The Cartesian servo's tick: position, velocities, forces (N),
    /// faults.
    pub cartesian: ServoOutput<R, N>,
}

/// Why a linkage servo was refused.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum LinkageError {
    /// A Cartesian axis's gains or limits.
    Cartesian(AxisError<GainsError>),
    /// A motor's limits.
    Motor(AxisError),
    /// A joint limit that is not a finite `lo < hi`.
    JointLimit(usize),
    /// A joint's encoder (its counts per turn or its zero).
    Joint(usize, JointEncoderError),
}

impl core::fmt::Display for LinkageError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            LinkageError::Cartesian(e) => write!(f, "Cartesian {e}"),
            LinkageError::Motor(e) => write!(f, "motor {}: {}", e.axis, e.error),
            LinkageError::JointLimit(j) => {
                write!(f, "joints.limits_rad[{j}] must be finite with lo < hi")
            }
            LinkageError::Joint(j, e) => write!(f, "joint {j}'s encoder: {e}"),
        }
    }
}

impl core::error::Error for LinkageError {}

/// A haptic display's servo on a linkage of `N` joints and `N` Cartesian
/// axes, computing in `R` (`f32` on the board).
///
/// Conventions: joint angles in rad, handle positions in m (integer nm
/// inside the Cartesian servo), torques in N m at the joints, forces in N
/// at the handle.
///
/// # Examples
///
/// A PHANToM-type arm holding the handle where it is:
///
/// ```
/// use twoport_control::kinematics::{Kinematics, SerialArm};
/// use twoport_control::linkage::{JointEncoder, LinkageServo, MotorConfig};
/// use twoport_control::servo::{ImpedanceGains, SensorFrame};
/// use twoport_control::ve::BilateralConstraint;
/// use twoport_control::world::PerAxis;
/// use twoport_control::{Position, SafetyConfig};
/// let arm = SerialArm::new(0.215, 0.17).unwrap();
/// let q = [0.0, 0.0, core::f32::consts::FRAC_PI_4];
/// let joints = q.map(|q| JointEncoder::new(32, 26_600.0, 0, q).unwrap());
/// // A constraint at the handle's position, 0.335 m out from the base.
/// let here = arm.forward(&q).unwrap().position_m;
/// let world = PerAxis(here.map(|x| BilateralConstraint::new(Position::from_m(x).unwrap())));
/// let gains = [ImpedanceGains::new(800.0, 0.0).into(); 3];
/// let safety = [SafetyConfig::new(1e-3, 8.0, 3.0); 3];
/// let motors = [MotorConfig::new(5.0, 1.0); 3];
/// let limits = [[-1.6, 1.6], [-2.2, 2.1], [-0.5, 3.7]];
/// // (The arm computes in f32 or f64: the servo says which.)
/// let mut s = LinkageServo::<_, _, f32, 3>::new(arm, joints, limits, gains, safety, motors, world)?;
/// s.enable().unwrap();
/// // The base turns 100 counts, one a tick: the handle moves 7.9 mm along
/// // +y, and the base's motor resists with `τ_1 = J^T f`, 800 N/m ·
/// // 7.9 mm · 0.335 m.
/// let mut out = s.tick(&SensorFrame::held(0, [0; 3], [0.0; 3]));
/// for k in 1..300 {
///     out = s.tick(&SensorFrame::held(k, [k.min(100), 0, 0], [0.0; 3]));
/// }
/// assert!((out.torque_nm[0] - 2.12).abs() < 0.02, "{:?}", out.torque_nm);
/// # Ok::<(), twoport_control::linkage::LinkageError>(())
/// ```
#[derive(Clone, Copy, Debug)]
pub struct LinkageServo<K, W, R = f32, const N: usize = 3, L = Direct> {
    joints: [JointEncoder; N],
    limits: JointLimits<N>,
    kinematics: K,
    cartesian: Servo<W, R, N, L>,
    motors: MotorLimits<R, N>,
    /// The last pose the kinematics served.
    pose: Jointed<R, N>,
    /// The handle's position there.
    handle: [Position; N],
    fault: Option<KinematicsFault>,
    gravity: Gravity,
}

impl<K: Kinematics<R, N>, W: World<R, N>, R: Real, const N: usize> LinkageServo<K, W, R, N> {
    /// A disabled servo on `hardware`: its encoders on `bits`-wide
    /// counters that read the pose `zero_rad` (rad) where they count 0, its
    /// joint limits and its motors.
    pub fn on(
        kinematics: K,
        hardware: &Hardware<N>,
        bits: u8,
        zero_rad: [f32; N],
        gains: [Gains; N],
        safety: [SafetyConfig; N],
        world: W,
    ) -> Result<Self, LinkageError> {
        let joints = hardware.encoders(bits, zero_rad)?;
        Self::new(
            kinematics,
            joints,
            hardware.limits_rad,
            gains,
            safety,
            hardware.motors(),
            world,
        )
    }

    /// A disabled servo computing in `R`, the kinematics' number type: the
    /// kinematics, each joint's encoder and the limits the proof covered, each Cartesian axis's gains and limits,
    /// each motor's torque limits, and the world. A device powered on at a
    /// pose the kinematics cannot serve starts with the fault latched.
    pub fn new(
        kinematics: K,
        joints: [JointEncoder; N],
        limits: JointLimits<N>,
        gains: [Gains; N],
        safety: [SafetyConfig; N],
        motors: [MotorConfig; N],
        world: W,
    ) -> Result<Self, LinkageError> {
        for (j, [lo, hi]) in limits.iter().enumerate() {
            if !(lo.is_finite() && hi.is_finite() && lo < hi) {
                return Err(LinkageError::JointLimit(j));
            }
        }
        let motors = MotorLimits::new(motors, safety[0].period_s).map_err(LinkageError::Motor)?;
        let q = joints.map(|j| R::of(j.angle_rad()));
        let served = serve(&kinematics, &limits, &q);
        let pose = *served.as_ref().unwrap_or(&Jointed {
            position_m: [R::ZERO; N],
            jacobian: [[R::ZERO; N]; N],
        });
        let handle = pose.position_m.map(|x| Position::from_nm(nm(x)));
        // (The Cartesian servo's encoders are never read: each tick hands
        // it the handle's position.)
        let encoders = handle.map(Encoder::nanometre_counter);
        let cartesian =
            Servo::new_in(gains, encoders, safety, world).map_err(LinkageError::Cartesian)?;
        let mut s = LinkageServo {
            joints,
            limits,
            kinematics,
            cartesian,
            motors,
            pose,
            handle,
            fault: None,
            gravity: Gravity::Off,
        };
        if let Err(f) = served {
            s.latch(f);
        }
        Ok(s)
    }
}

impl<K: Kinematics<R, N>, W: World<R, N>, R: Real, const N: usize, L: PortLayer<R>>
    LinkageServo<K, W, R, N, L>
{
    /// This servo with `layers[i]` between Cartesian axis `i`'s port and
    /// its laws (a passivity layer: see [`Servo::with_layers`]).
    pub fn with_layers<M: PortLayer<R>>(
        self,
        layers: [M; N],
    ) -> Result<LinkageServo<K, W, R, N, M>, LinkageError> {
        Ok(LinkageServo {
            joints: self.joints,
            limits: self.limits,
            kinematics: self.kinematics,
            cartesian: self
                .cartesian
                .with_layers(layers)
                .map_err(LinkageError::Cartesian)?,
            motors: self.motors,
            pose: self.pose,
            handle: self.handle,
            fault: self.fault,
            gravity: self.gravity,
        })
    }

    fn latch(&mut self, f: KinematicsFault) {
        self.fault.get_or_insert(f);
        self.cartesian.trip(Faults::KINEMATICS);
    }

    /// One control tick: joint encoders in, joint torques out.
    pub fn tick(&mut self, frame: &SensorFrame<R, N>) -> LinkageOutput<R, N> {
        let q = self.read(frame);
        let cartesian = self.cartesian.tick_at(frame, &self.handle);
        self.drive(q, cartesian)
    }

    /// [`tick`](Self::tick) against `world` in place of the Cartesian
    /// servo's own (see [`Servo::tick_on`]).
    pub fn tick_on<V: World<R, N>>(
        &mut self,
        frame: &SensorFrame<R, N>,
        world: &mut V,
    ) -> LinkageOutput<R, N> {
        let q = self.read(frame);
        let cartesian = self.cartesian.tick_at_on(frame, &self.handle, world);
        self.drive(q, cartesian)
    }

    /// One tick with `law` in place of the Cartesian laws and the world
    /// (as [`Servo::tick_with`]): `law` gets each Cartesian axis's index,
    /// the handle's position and velocity (m/s) and answers with the force
    /// on that axis (N), which goes out through `J^T` and the motors'
    /// limits like any other. Homing runs through this.
    pub fn tick_with(
        &mut self,
        frame: &SensorFrame<R, N>,
        law: impl FnMut(usize, Position, R) -> R,
    ) -> LinkageOutput<R, N> {
        let q = self.read(frame);
        let cartesian = self.cartesian.tick_with_at(frame, &self.handle, law);
        self.drive(q, cartesian)
    }

    /// The joints read and the handle found: the joint angles (rad). A bad
    /// counter or a pose the kinematics cannot serve latches its fault
    /// (the handle stays where it was last served).
    #[inline(always)]
    fn read(&mut self, frame: &SensorFrame<R, N>) -> [R; N] {
        let mut q = [R::ZERO; N];
        let mut sensors_ok = true;
        for ((q, j), raw) in q.iter_mut().zip(&mut self.joints).zip(frame.encoder_raw) {
            match j.update(raw) {
                Ok(a) => *q = R::of(a),
                Err(_) => sensors_ok = false,
            }
        }
        if !sensors_ok {
            self.cartesian.trip(Faults::ENCODER_INVALID);
        } else {
            match serve(&self.kinematics, &self.limits, &q) {
                Ok(pose) => {
                    self.pose = pose;
                    self.handle = pose.position_m.map(|x| Position::from_nm(nm(x)));
                }
                Err(f) => self.latch(f),
            }
        }
        q
    }

    /// The Cartesian tick's force out as the motors' torques, with gravity
    /// held up while the servo may push.
    #[inline(always)]
    fn drive(&mut self, q: [R; N], cartesian: ServoOutput<R, N>) -> LinkageOutput<R, N> {
        let mut torque = self.pose.torques_nm(&cartesian.actuator_force_n);
        if self.gravity != Gravity::Off
            && cartesian.faults.is_empty()
            && self.cartesian.safety().is_enabled()
        {
            let g = self.gravity.torques_nm(&q, &self.pose);
            for (t, g) in torque.iter_mut().zip(g) {
                *t = *t - g;
            }
        }
        let limited = self.motors.step(torque);
        LinkageOutput {
            torque_nm: limited.torque_nm,
            torque_limited: limited.limited,
            q_rad: q,
            cartesian,
        }
    }

    /// Enable force output (ramping in). Refused while a fault is latched.
    pub fn enable(&mut self) -> Result<(), Faults> {
        self.cartesian.enable()
    }

    /// Disable force output.
    pub fn disable(&mut self) {
        self.cartesian.disable();
    }

    /// Clear latched faults (the kinematics' reason too) and re-align.
    pub fn clear(&mut self) {
        self.fault = None;
        self.cartesian.clear();
    }

    /// A link heartbeat arrived.
    pub fn heartbeat(&mut self) {
        self.cartesian.heartbeat();
    }

    /// Latch a fault found outside the tick.
    pub fn trip(&mut self, f: Faults) {
        self.cartesian.trip(f);
    }

    /// Why the kinematics last refused a pose, until [`clear`](Self::clear).
    pub fn kinematics_fault(&self) -> Option<KinematicsFault> {
        self.fault
    }

    /// Calibrate the joints: where the device is now reads as `q_rad`
    /// (rad; a fixture or homing's result). The handle's position follows;
    /// a pose the kinematics cannot serve latches the fault. Meant for a
    /// disabled servo.
    pub fn calibrate_joints(&mut self, q_rad: [f32; N]) {
        for (j, q) in self.joints.iter_mut().zip(q_rad) {
            j.rezero(q);
        }
        match serve(&self.kinematics, &self.limits, &q_rad.map(R::of)) {
            Ok(pose) => {
                self.pose = pose;
                self.handle = pose.position_m.map(|x| Position::from_nm(nm(x)));
                self.cartesian.calibrate(self.handle);
            }
            Err(f) => self.latch(f),
        }
    }

    /// The same servo holding the moving masses up with `gravity`
    /// (refused unless finite).
    pub fn with_gravity(mut self, gravity: Gravity) -> Result<Self, ParamError> {
        if !gravity.is_finite() {
            return Err(ParamError {
                name: "gravity (N or N m)",
                value: f32::NAN,
                problem: "must be finite",
            });
        }
        self.gravity = gravity;
        Ok(self)
    }

    /// What it holds up.
    pub fn gravity(&self) -> Gravity {
        self.gravity
    }

    /// The Cartesian servo: gains, world, safety layer, laws.
    pub fn cartesian(&self) -> &Servo<W, R, N, L> {
        &self.cartesian
    }

    /// The Cartesian servo, to change its gains, limits or world between
    /// ticks (its calibration follows the joints': see
    /// [`calibrate_joints`](Self::calibrate_joints)).
    pub fn cartesian_mut(&mut self) -> &mut Servo<W, R, N, L> {
        &mut self.cartesian
    }

    /// Change every Cartesian axis's gains between ticks (all or none).
    pub fn set_gains(&mut self, gains: [Gains; N]) -> Result<(), AxisError<GainsError>> {
        self.cartesian.set_gains(gains)
    }

    /// The world, to change it between ticks.
    pub fn world_mut(&mut self) -> &mut W {
        self.cartesian.world_mut()
    }

    /// The last pose served: the handle's position (m) and the Jacobian.
    pub fn pose(&self) -> &Jointed<R, N> {
        &self.pose
    }

    /// The motors' limits and thermal state.
    pub fn motors(&self) -> &MotorLimits<R, N> {
        &self.motors
    }
}

/// The pose at `q` if every joint is within its limits and the kinematics
/// serve it.
#[inline(always)]
fn serve<K: Kinematics<R, N>, R: Real, const N: usize>(
    k: &K,
    limits: &JointLimits<N>,
    q: &[R; N],
) -> Result<Jointed<R, N>, KinematicsFault> {
    for (q, [lo, hi]) in q.iter().zip(limits) {
        // (NaN fails both comparisons: the kinematics names it.)
        if *q < R::of(*lo) || *q > R::of(*hi) {
            return Err(KinematicsFault::OutsideLimits);
        }
    }
    k.forward(q)
}

/// `x` (m) to the nearest nm (saturating at ±2.147 m).
#[inline(always)]
fn nm<R: Real>(x: R) -> i32 {
    let n = x * R::NM_PER_M;
    (n + if n < R::ZERO { -R::HALF } else { R::HALF }).trunc_i32()
}
