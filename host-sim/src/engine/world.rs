//! The scene's world on `N` axes: the scene's one-axis VE on every axis, or
//! the 3-D building-block world of the board's three-axis image.

use crate::engine::scene::{Scene, VeSpec, MAX_BLOCKS};
use crate::engine::ve::SceneVe;
use crate::Error;
use twoport_control::ve::{Port, VeOutput, VeTransfer, VirtualEnvironment};
use twoport_control::world::vbb::{Block, Vbb, VbbConfig};
use twoport_control::world::World;
use twoport_control::{Position, Real};

/// What the servo's world is, computing in `R` on `N` axes.
#[derive(Clone, Debug)]
pub enum SceneWorld<R: Real, const N: usize> {
    /// The scene's VE on each axis, each with its own state; the axes do
    /// not interact.
    Each([SceneVe<R>; N]),
    /// The 3-D building-block world (boxed: 2.6 kB of blocks), with the
    /// scene's grab and release times. Only built on three axes.
    Blocks(Box<BlockWorld<R>>),
}

/// The 3-D building-block world and the ticks its scene grabs and lets go.
#[derive(Clone, Debug)]
pub struct BlockWorld<R: Real> {
    /// The world.
    pub world: Vbb<R, MAX_BLOCKS>,
    grabs: Vec<u64>,
    releases: Vec<u64>,
    tick: u64,
}

impl<R: Real> BlockWorld<R> {
    /// Step against three ports, grabbing and letting go on the scene's
    /// ticks first.
    fn step(&mut self, ports: &[Port<R>; 3]) -> [VeOutput<R>; 3] {
        if self.grabs.contains(&self.tick) {
            self.world.grab();
        }
        if self.releases.contains(&self.tick) {
            self.world.release();
        }
        self.tick += 1;
        self.world.step_axes(ports)
    }
}

impl<R: Real, const N: usize> SceneWorld<R, N> {
    /// The scene's world; `each` builds axis `a`'s VE where the scene
    /// names a one-axis VE.
    pub fn new(
        scene: &Scene,
        period_s: f32,
        each: impl Fn(usize) -> Result<SceneVe<R>, Error>,
    ) -> Result<Self, Error> {
        let VeSpec::World {
            blocks,
            cursor_mass_kg,
            friction,
            knobs,
            explicit,
            grab_at_s,
            release_at_s,
        } = &scene.ve
        else {
            let mut ves = Vec::with_capacity(N);
            for a in 0..N {
                ves.push(each(a)?);
            }
            return ves
                .try_into()
                .map(SceneWorld::Each)
                .map_err(|_| Error::sim("one VE per axis"));
        };
        if N != 3 {
            return Err(sim_err!("ve.kind = \"world\" needs axes = 3, not {N}"));
        }
        let mut cfg = VbbConfig::excalibur(period_s);
        cfg.explicit = *explicit;
        cfg.cursor_mass_kg = *cursor_mass_kg as f32;
        cfg.friction = *friction as f32;
        if !knobs {
            cfg.knobs = None;
        }
        let mut list = Vec::with_capacity(blocks.len());
        for (i, b) in blocks.iter().enumerate() {
            let f = |v: [f64; 3]| v.map(|x| x as f32);
            list.push(
                Block::new(f(b.at_m), f(b.size_m), b.mass_kg as f32)
                    .ok_or_else(|| format!("ve.blocks[{i}]: out of the world's range"))?,
            );
        }
        let period = f64::from(period_s);
        let ticks = |ts: &[f64]| ts.iter().map(|t| (t / period).round() as u64).collect();
        Ok(SceneWorld::Blocks(Box::new(BlockWorld {
            world: Vbb::new(cfg, &list).map_err(|e| format!("ve: {e}"))?,
            grabs: ticks(grab_at_s),
            releases: ticks(release_at_s),
            tick: 0,
        })))
    }

    /// The building-block world, where the scene runs it.
    pub fn blocks(&self) -> Option<&Vbb<R, MAX_BLOCKS>> {
        match self {
            SceneWorld::Blocks(b) => Some(&b.world),
            SceneWorld::Each(_) => None,
        }
    }

    /// The building-block world to grab and let go, where the scene runs
    /// it.
    pub fn blocks_mut(&mut self) -> Option<&mut Vbb<R, MAX_BLOCKS>> {
        match self {
            SceneWorld::Blocks(b) => Some(&mut b.world),
            SceneWorld::Each(_) => None,
        }
    }

    /// Axis `axis`'s one-axis VE, where the scene runs one per axis.
    pub fn axis_ve(&self, axis: usize) -> Option<&SceneVe<R>> {
        match self {
            SceneWorld::Each(v) => v.get(axis),
            SceneWorld::Blocks(_) => None,
        }
    }

    /// Every axis's one-axis VE, to change while running.
    pub fn axis_ves_mut(&mut self) -> &mut [SceneVe<R>] {
        match self {
            SceneWorld::Each(v) => v,
            SceneWorld::Blocks(_) => &mut [],
        }
    }
}

/// The first three of `N` values, or `fill` where there are fewer.
fn three<T: Copy>(v: &[T], fill: T) -> [T; 3] {
    core::array::from_fn(|i| v.get(i).copied().unwrap_or(fill))
}

/// `N` values from three, `fill` past them.
fn widen<T: Copy, const N: usize>(v: [T; 3], fill: T) -> [T; N] {
    core::array::from_fn(|i| v.get(i).copied().unwrap_or(fill))
}

/// The world on every axis count, for each float type the laws compute
/// in (a blanket impl over `R` would collide with the control crate's
/// one-axis impl for every VE).
macro_rules! scene_world {
    ($($r:ty),*) => {$(
        impl<const N: usize> World<$r, N> for SceneWorld<$r, N> {
            #[inline]
            fn step_axes(&mut self, ports: &[Port<$r>; N]) -> [VeOutput<$r>; N] {
                match self {
                    SceneWorld::Each(v) => core::array::from_fn(|i| v[i].step(ports[i])),
                    SceneWorld::Blocks(w) => {
                        let free = ports[0].at(<$r>::ZERO);
                        let still = Port {
                            f0_n: <$r>::ZERO,
                            z_nspm: <$r>::ZERO,
                        };
                        widen(w.step(&three(ports, still)), free)
                    }
                }
            }

            fn reset_axes(&mut self, x: &[Position; N]) {
                match self {
                    SceneWorld::Each(v) => {
                        for (ve, x) in v.iter_mut().zip(x) {
                            ve.reset(*x);
                        }
                    }
                    SceneWorld::Blocks(w) => w.world.reset_axes(&three(x, Position::ZERO)),
                }
            }

            #[inline]
            fn positions(&self) -> [Position; N] {
                match self {
                    SceneWorld::Each(v) => core::array::from_fn(|i| v[i].position()),
                    SceneWorld::Blocks(w) => widen(w.world.positions(), Position::ZERO),
                }
            }

            #[inline]
            fn offsets_m(&self, from: &[Position; N]) -> [$r; N] {
                match self {
                    SceneWorld::Each(v) => core::array::from_fn(|i| v[i].offset_m(from[i])),
                    SceneWorld::Blocks(w) => widen(
                        w.world.offsets_m(&three(from, Position::ZERO)),
                        <$r>::ZERO,
                    ),
                }
            }

            fn axis_tf(&self, axis: usize) -> VeTransfer {
                match self {
                    SceneWorld::Each(v) => v.get(axis).map_or(
                        VeTransfer::Impedance(twoport_control::ZTransfer::gain(0.0)),
                        |ve| ve.tf(),
                    ),
                    SceneWorld::Blocks(w) => w.world.axis_tf(axis),
                }
            }
        }
    )*};
}

scene_world!(f32, f64);
