//! The scene's servo: the control crate's [`Servo`] on the scene's world, in
//! the float type the scene names (the board's f32, or f64 to take the
//! laws' rounding out of a study).

use crate::engine::layer::SceneLayer;
use crate::engine::linkage::{AnyKinematics, LinkageArm, Shifted};
use crate::engine::scene::{Precision, Scene, VeSpec};
use crate::engine::ve::from_scene::{axis_ve, set_wall};
use crate::engine::ve::SceneVe;
use crate::engine::world::SceneWorld;
use crate::Error;
use twoport_control::kinematics::Kinematics;
use twoport_control::linkage::LinkageServo;
use twoport_control::passivity::PassiveVe;
use twoport_control::servo::{Gains, PortLayer, SensorFrame, Servo, ServoOutput};
use twoport_control::world::vbb::Block as Block3;
use twoport_control::world::World;
use twoport_control::{Encoder, Position, Real, SafetyConfig};

/// The board's code for the scene's display on `N` axes, enabled.
#[derive(Clone, Debug)]
pub enum SceneServo<const N: usize = 1> {
    /// The board's f32 laws.
    F32(Box<Servo<SceneWorld<f32, N>, f32, N>>),
    /// The same laws computing in f64.
    F64(Box<Servo<SceneWorld<f64, N>, f64, N>>),
    /// The f32 laws with the scene's port layer (passivity, element delay).
    F32Layered(Box<LayeredServo<f32, N>>),
    /// The f64 laws with the scene's port layer.
    F64Layered(Box<LayeredServo<f64, N>>),
    /// A linkage's servo (f32, as its board runs it) around the scene's
    /// world: joint encoders in, joint torques out.
    Linkage(Box<LinkageSceneServo<N>>),
}

/// A linkage scene's servo.
pub type LinkageSceneServo<const N: usize> = LinkageServo<Shifted, SceneWorld<f32, N>, f32, N>;

/// The board's servo with the scene's port layer on each axis, computing
/// in `R`.
pub type LayeredServo<R, const N: usize = 1> = Servo<SceneWorld<R, N>, R, N, SceneLayer<R>>;

/// `$e` on the (Cartesian) servo whatever its variant, borrowed as the
/// call says: `each_servo!(&self, s => ...)` or
/// `each_servo!(&mut self, s => ...)`.
macro_rules! each_servo {
    (&$self:ident, $s:ident => $e:expr) => {
        match &*$self {
            SceneServo::F32($s) => $e,
            SceneServo::F64($s) => $e,
            SceneServo::F32Layered($s) => $e,
            SceneServo::F64Layered($s) => $e,
            SceneServo::Linkage(l) => {
                let $s = l.cartesian();
                $e
            }
        }
    };
    (&mut $self:ident, $s:ident => $e:expr) => {
        match &mut *$self {
            SceneServo::F32($s) => $e,
            SceneServo::F64($s) => $e,
            SceneServo::F32Layered($s) => $e,
            SceneServo::F64Layered($s) => $e,
            SceneServo::Linkage(l) => {
                let $s = l.cartesian_mut();
                $e
            }
        }
    };
}

/// Each axis's port layer, or `None` where the scene runs none.
fn scene_layers<R: Real, const N: usize>(
    scene: &Scene,
    safety: &SafetyConfig,
) -> Result<Option<[SceneLayer<R>; N]>, Error> {
    let mut layers = Vec::with_capacity(N);
    for a in 0..N {
        match SceneLayer::for_axis(scene, safety, a)? {
            Some(l) => layers.push(l),
            None => return Ok(None),
        }
    }
    Ok(Some(
        layers
            .try_into()
            .map_err(|_| Error::sim("one port layer per axis"))?,
    ))
}

fn build<R: Real, const N: usize>(
    scene: &Scene,
    encoder: Encoder,
    safety: SafetyConfig,
) -> Result<Servo<SceneWorld<R, N>, R, N>, Error>
where
    SceneWorld<R, N>: World<R, N>,
{
    let world = SceneWorld::new(scene, safety.period_s, |_| axis_ve(scene, &safety))?;
    // The device's zero is where the world starts its point (the 3-D
    // world's cursor; 0 for every one-axis VE).
    let start = world.positions();
    let gains = core::array::from_fn(|a| scene.gains_of(a));
    let mut servo = Servo::new_in(gains, [encoder; N], [safety; N], world).map_err(|e| {
        if N == 1 {
            e.error.to_string()
        } else {
            e.to_string()
        }
    })?;
    if matches!(scene.ve, VeSpec::World { .. }) {
        servo.calibrate(start);
    }
    Ok(servo)
}

fn enabled<W: World<R, N>, R: Real, L: PortLayer<R>, const N: usize>(
    mut s: Servo<W, R, N, L>,
) -> Result<Box<Servo<W, R, N, L>>, Error> {
    s.enable()
        .map_err(|f| format!("the servo would not enable: {f}"))?;
    Ok(Box::new(s))
}

fn layered<R: Real, const N: usize>(
    s: Servo<SceneWorld<R, N>, R, N>,
    layers: [SceneLayer<R>; N],
) -> Result<Box<LayeredServo<R, N>>, Error>
where
    SceneWorld<R, N>: World<R, N>,
{
    enabled(s.with_layers(layers).map_err(|e| e.error.to_string())?)
}

/// The sensors as the f32 board reads them.
pub(crate) fn frame_f32<const N: usize>(f: &SensorFrame<f64, N>) -> SensorFrame<f32, N> {
    SensorFrame {
        tick: f.tick,
        encoder_raw: f.encoder_raw,
        load_cell_n: f.load_cell_n.map(|f| f as f32),
        dead_man_closed: f.dead_man_closed,
    }
}

/// An f32 servo's output, widened.
pub(crate) fn output_f64<const N: usize>(o: ServoOutput<f32, N>) -> ServoOutput<f64, N> {
    let wide = |x: [f32; N]| x.map(f64::from);
    ServoOutput {
        actuator_force_n: wide(o.actuator_force_n),
        commanded_force_n: wide(o.commanded_force_n),
        position: o.position,
        velocity_mps: wide(o.velocity_mps),
        ve_velocity_mps: wide(o.ve_velocity_mps),
        ve_force_n: wide(o.ve_force_n),
        coupling_force_n: wide(o.coupling_force_n),
        reference: o.reference,
        faults: o.faults,
        limited: o.limited,
    }
}

impl<const N: usize> SceneServo<N> {
    /// The scene's display, gains, world and port layer on `N` axes, in
    /// the scene's float type.
    pub fn new(scene: &Scene, encoder: Encoder, safety: SafetyConfig) -> Result<Self, Error> {
        Ok(match scene.integrator.controller {
            Precision::F32 => match scene_layers(scene, &safety)? {
                None => SceneServo::F32(enabled(build(scene, encoder, safety)?)?),
                Some(l) => SceneServo::F32Layered(layered(build(scene, encoder, safety)?, l)?),
            },
            Precision::F64 => match scene_layers(scene, &safety)? {
                None => SceneServo::F64(enabled(build(scene, encoder, safety)?)?),
                Some(l) => SceneServo::F64Layered(layered(build(scene, encoder, safety)?, l)?),
            },
        })
    }

    /// One tick on sensors given in f64 (rounded to f32 for the board's
    /// laws).
    #[inline]
    pub fn tick(&mut self, f: &SensorFrame<f64, N>) -> ServoOutput<f64, N> {
        match self {
            SceneServo::F32(s) => output_f64(s.tick(&frame_f32(f))),
            SceneServo::F64(s) => s.tick(f),
            SceneServo::F32Layered(s) => output_f64(s.tick(&frame_f32(f))),
            SceneServo::F64Layered(s) => s.tick(f),
            SceneServo::Linkage(s) => output_f64(s.tick(&frame_f32(f)).cartesian),
        }
    }

    /// One tick that also answers each motor's command: an axis's force
    /// (N), or a linkage's joint torque (N m).
    pub fn tick_driven(&mut self, f: &SensorFrame<f64, N>) -> (ServoOutput<f64, N>, [f64; N]) {
        match self {
            SceneServo::Linkage(s) => {
                let out = s.tick(&frame_f32(f));
                (output_f64(out.cartesian), out.torque_nm.map(f64::from))
            }
            _ => {
                let out = self.tick(f);
                (out, out.actuator_force_n)
            }
        }
    }

    /// A linkage scene's servo on `arm`: the file's joints, limits and
    /// motors, the scene's gains and world, the Cartesian frame's zero
    /// where the world starts, the moving masses held up where the scene
    /// has gravity.
    pub fn linkage(
        scene: &Scene,
        arm: &LinkageArm<N>,
        safety: SafetyConfig,
    ) -> Result<Self, Error> {
        let t = safety.period_s;
        let world = SceneWorld::new(scene, t, |_| axis_ve(scene, &safety))?;
        let start = world.positions();
        let file = arm.plant.file();
        let kinematics = AnyKinematics::new(&file.geometry)?;
        let mut at = Shifted {
            kinematics,
            origin_m: [0.0; 3],
        };
        let q0 = arm.zero_rad().map(|q| q as f32);
        let x0 = Kinematics::<f32, N>::forward(&at, &q0)
            .map_err(|f| sim_err!("plant.pose_rad: {f:?}"))?
            .position_m;
        for i in 0..N {
            at.origin_m[i] = x0[i] - start[i].m();
        }
        let gains = core::array::from_fn(|a| scene.gains_of(a));
        let mut s = arm
            .servo(at, gains, [safety; N], world)
            .map_err(|e| sim_err!("plant.linkage: {e}"))?;
        if scene.plant.gravity_mps2 > 0.0 {
            s = s
                .with_gravity(file.gravity_compensation(scene.plant.gravity_mps2))
                .map_err(|e| sim_err!("plant.gravity_mps2: {e}"))?;
        }
        s.enable()
            .map_err(|f| sim_err!("the linkage's servo would not enable: {f}"))?;
        Ok(SceneServo::Linkage(Box::new(s)))
    }

    /// The point each axis's coupling holds in the world.
    pub fn ve_position(&self) -> [Position; N] {
        each_servo!(&self, s => s.world().positions())
    }

    /// The gains in force on each axis.
    pub fn gains(&self) -> [Gains; N] {
        each_servo!(&self, s => s.gains())
    }

    /// The 3-D building-block world, where the scene runs it, as the
    /// board's f32 world sees it: its blocks, the one held, the cursor.
    pub fn blocks(&self) -> Option<WorldView> {
        fn view<R: Real, const N: usize>(w: &SceneWorld<R, N>) -> Option<WorldView>
        where
            SceneWorld<R, N>: World<R, N>,
        {
            w.blocks().map(|b| WorldView {
                blocks: b.blocks().to_vec(),
                held: b.held(),
                cursor: b.cursor(),
            })
        }
        each_servo!(&self, s => view(s.world()))
    }

    /// Grab the block the world's cursor touches (the scope's button);
    /// whether one was there.
    pub fn grab(&mut self) -> bool {
        each_servo!(&mut self, s => s.world_mut().blocks_mut().is_some_and(|w| w.grab()))
    }

    /// Let go of the world's held block.
    pub fn release(&mut self) {
        each_servo!(&mut self, s => {
            if let Some(w) = s.world_mut().blocks_mut() {
                w.release();
            }
        })
    }

    /// Axis `axis`'s passivity layer, if the scene runs one (at the
    /// device's port, or at the VE's), or its element delay.
    pub fn layer(&self, axis: usize) -> Option<LayerView<'_>> {
        match self {
            SceneServo::F32Layered(s) => s.layers().get(axis).map(LayerView::Device32),
            SceneServo::F64Layered(s) => s.layers().get(axis).map(LayerView::Device64),
            SceneServo::F32(s) => match s.world().axis_ve(axis) {
                Some(SceneVe::Passive(p)) => Some(LayerView::Ve32(p)),
                _ => None,
            },
            SceneServo::F64(s) => match s.world().axis_ve(axis) {
                Some(SceneVe::Passive(p)) => Some(LayerView::Ve64(p)),
                _ => None,
            },
            SceneServo::Linkage(_) => None,
        }
    }

    /// Change every axis's gains while running (the scope's sliders); they
    /// must be for the scene's display.
    pub fn set_gains(&mut self, g: [Gains; N]) -> Result<(), Error> {
        each_servo!(&mut self, s => s.set_gains(g)).map_err(|e| Error::Sim(e.error.to_string()))
    }

    /// Move the wall and change its stiffness on every axis while running
    /// (the scope's controls); an error if the scene's VE is not a wall.
    pub fn set_wall(&mut self, surface_m: f64, stiffness_npm: f64) -> Result<(), Error> {
        let x = Position::from_m_f64(surface_m).ok_or(format!(
            "wall position {surface_m} m is out of range (±2.147 m)"
        ))?;
        let k = stiffness_npm as f32;
        each_servo!(&mut self, s => {
            let ves = s.world_mut().axis_ves_mut();
            if ves.is_empty() {
                return Err("the scene's VE is not a wall".into());
            }
            ves.iter_mut().try_for_each(|ve| set_wall(ve, x, k))
        })
    }
}

/// The 3-D building-block world at one instant.
#[derive(Clone, Debug, PartialEq)]
pub struct WorldView {
    /// The blocks.
    pub blocks: Vec<Block3>,
    /// The block the cursor holds.
    pub held: Option<usize>,
    /// The cursor.
    pub cursor: [Position; 3],
}

/// A scene servo's passivity layer, where it sits and in its float type.
#[derive(Clone, Copy, Debug)]
pub enum LayerView<'a> {
    /// At the device's port, the f32 laws'.
    Device32(&'a SceneLayer<f32>),
    /// At the device's port, the f64 laws'.
    Device64(&'a SceneLayer<f64>),
    /// At the VE's port, the f32 laws'.
    Ve32(&'a PassiveVe<SceneVe<f32>, f32>),
    /// At the VE's port, the f64 laws'.
    Ve64(&'a PassiveVe<SceneVe<f64>, f64>),
}

impl LayerView<'_> {
    /// The energy (J) its observer has seen the element take in; NaN for
    /// an element delay without a controller.
    pub fn energy_in_j(&self) -> f64 {
        match self {
            LayerView::Device32(l) => l.energy_in_j(),
            LayerView::Device64(l) => l.energy_in_j(),
            LayerView::Ve32(p) => p.energy_in_j() as f64,
            LayerView::Ve64(p) => p.energy_in_j(),
        }
    }

    /// What it added this tick: damping (N s/m) at the device's port,
    /// conductance (m/(N s)) at a load cell or the VE's port.
    pub fn added(&self) -> f64 {
        match self {
            LayerView::Device32(l) => l.added(),
            LayerView::Device64(l) => l.added(),
            LayerView::Ve32(p) => p.conductance_mpns() as f64,
            LayerView::Ve64(p) => p.conductance_mpns(),
        }
    }

    /// The energy (J) it has dissipated so far.
    pub fn dissipated_j(&self) -> f64 {
        match self {
            LayerView::Device32(l) => l.dissipated_j(),
            LayerView::Device64(l) => l.dissipated_j(),
            LayerView::Ve32(p) => p.dissipated_j() as f64,
            LayerView::Ve64(p) => p.dissipated_j(),
        }
    }
}
