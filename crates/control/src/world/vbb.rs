//! The virtual building-block world of the paper's Excalibur demonstration,
//! in 3-D: a cursor and up to `B` box blocks on a floor, under gravity. The
//! user grabs the block the cursor touches and moves it; the other blocks
//! are obstacles its faces slide on, with Coulomb friction; a released block
//! falls onto the floor or onto the blocks below it.
//!
//! The coupled body (the cursor, or the cursor with the block it holds) is
//! a mass stepped by backward Euler against every axis's coupling port and
//! its contacts in one implicit solve: a contact stops the body exactly at
//! the face it would cross this tick (a speculative contact, no
//! penetration, no bounce), and friction on the other axes is the implicit
//! Coulomb law, sticking while the port's pull is inside the cone. Each of
//! these takes energy out or stores it (gravity), so the world is passive
//! at its ports: whatever the couplings do, it never gives back more than
//! it was given.
//!
//! Axes: 0 is x, 1 is y, 2 is z, up; gravity acts along -z. Positions are
//! integer nanometres ([`Position`]); a block is its lowest corner and its
//! size.

use super::World;
use crate::ve::{Port, VeOutput, VeTransfer};
use crate::{param, Integrator, ParamError, Position, Real, ZTransfer};

/// Standard gravity (m/s²).
pub const G_MPS2: f32 = 9.806_65;

/// One box block.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Block {
    /// The lowest corner (x, y, z).
    pub min: [Position; 3],
    /// The size along each axis (nm), > 0.
    pub size_nm: [i32; 3],
    /// Mass (kg), > 0.
    pub mass_kg: f32,
}

impl Block {
    /// A block of `size_m` (m, per axis) and `mass_kg` (kg) whose lowest
    /// corner is at `min_m` (m); `None` for a size, mass or corner out of
    /// range.
    pub fn new(min_m: [f32; 3], size_m: [f32; 3], mass_kg: f32) -> Option<Block> {
        let mut b = Block {
            min: [Position::ZERO; 3],
            size_nm: [0; 3],
            mass_kg,
        };
        for a in 0..3 {
            b.min[a] = Position::from_m(min_m[a])?;
            let s = Position::from_m(size_m[a])?.nm();
            if s <= 0 {
                return None;
            }
            b.size_nm[a] = s;
        }
        (mass_kg.is_finite() && mass_kg > 0.0).then_some(b)
    }

    /// The far corner along `axis` (nm).
    fn max_nm(&self, axis: usize) -> i64 {
        self.min[axis].nm() as i64 + self.size_nm[axis] as i64
    }
}

/// The world's constants.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VbbConfig {
    /// Sample period `T` (s).
    pub period_s: f32,
    /// The cursor's mass (kg): the paper's explicit cursor needed 0.25 kg,
    /// the implicit one here is passive at any mass.
    pub cursor_mass_kg: f32,
    /// The cursor's half-width (nm): it touches blocks as a small cube.
    pub cursor_half_nm: i32,
    /// Coulomb friction coefficient between a held block (or the cursor)
    /// and what it slides on.
    pub friction: f32,
    /// Whether the held block's weight is felt.
    pub held_weight: bool,
    /// The workspace's lowest and highest corners: walls, and the floor at
    /// the lowest z.
    pub workspace: [[Position; 3]; 2],
    /// The knobs on every block's top, if the blocks have any.
    pub knobs: Option<Knobs>,
    /// Integrate the body as the paper's building blocks did, explicitly
    /// (forward-Euler velocity on last tick's force, trapezoidal position),
    /// instead of the passive backward Euler: to study why the paper's
    /// cursor needed 0.25 kg. Exact in free space only; not passive.
    pub explicit: bool,
}

/// Knobs on a block's top, in a square grid from its corner: a block set
/// on another rests on them, and mates (drops onto the top, and is held
/// there) when the grids line up and it is pressed down hard enough.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Knobs {
    /// The grid's pitch (nm), > 0.
    pub pitch_nm: i32,
    /// How far the knobs stand above the top (nm), >= 0.
    pub height_nm: i32,
    /// How far off the grid a block may be and still mate (nm).
    pub tolerance_nm: i32,
    /// The downward push that mates aligned blocks (N).
    pub mate_force_n: f32,
    /// The pull that parts mated blocks (N).
    pub part_force_n: f32,
}

impl VbbConfig {
    /// The paper's Excalibur workspace, 300 x 300 x 200 mm with the floor
    /// at z = 0, a 0.25 kg cursor 2 mm across, friction 0.3, the held
    /// block's weight felt, at period `period_s` (s).
    pub fn excalibur(period_s: f32) -> Self {
        let p = Position::from_nm;
        VbbConfig {
            period_s,
            cursor_mass_kg: 0.25,
            cursor_half_nm: 1_000_000,
            friction: 0.3,
            held_weight: true,
            workspace: [
                [p(-150_000_000), p(-150_000_000), p(0)],
                [p(150_000_000), p(150_000_000), p(200_000_000)],
            ],
            knobs: Some(Knobs {
                pitch_nm: 10_000_000,
                height_nm: 2_000_000,
                tolerance_nm: 1_000_000,
                mate_force_n: 5.0,
                part_force_n: 8.0,
            }),
            explicit: false,
        }
    }
}

/// A body's extent along the three axes (nm, lowest and highest).
#[derive(Clone, Copy, Debug)]
struct Extent {
    lo: [i64; 3],
    hi: [i64; 3],
}

impl Extent {
    /// Whether `self` and `o` overlap (by more than touching) on every axis
    /// but `axis`.
    fn faces(&self, o: &Extent, axis: usize) -> bool {
        (0..3).all(|b| b == axis || (self.lo[b] < o.hi[b] && o.lo[b] < self.hi[b]))
    }
}

fn extent_of(b: &Block) -> Extent {
    let lo = b.min.map(|p| p.nm() as i64);
    Extent {
        lo,
        hi: [0, 1, 2].map(|a| b.max_nm(a)),
    }
}

/// The building-block world, for the [`Servo`](crate::servo::Servo)'s
/// three axes, holding up to `B` blocks.
///
/// # Examples
///
/// ```
/// use twoport_control::world::vbb::{Block, Vbb, VbbConfig};
/// use twoport_control::world::World;
/// use twoport_control::ve::Port;
/// // A 30 mm cube on the floor, the cursor resting on its top.
/// let cube = Block::new([0.0, 0.0, 0.0], [0.03; 3], 0.1).unwrap();
/// let mut w = Vbb::<f32, 4>::new(VbbConfig::excalibur(1e-3), &[cube])?;
/// w.place_cursor([0.015, 0.015, 0.031]);
/// // Push down with 5 N: the cube's top holds the cursor.
/// let push = [0.0, 0.0, -5.0].map(|f0_n| Port { f0_n, z_nspm: 100.0 });
/// for _ in 0..100 {
///     w.step_axes(&push);
/// }
/// assert!(w.cursor()[2].nm() >= 31_000_000 - 1_000_000);
/// // Grab it and pull up with 5 N: the block comes along, its 0.98 N of
/// // weight felt.
/// assert!(w.grab());
/// let lift = [0.0, 0.0, 5.0].map(|f0_n| Port { f0_n, z_nspm: 100.0 });
/// for _ in 0..100 {
///     w.step_axes(&lift);
/// }
/// assert!(w.blocks()[0].min[2].nm() > 1_000_000);
/// # Ok::<(), twoport_control::ParamError>(())
/// ```
#[derive(Clone, Copy, Debug)]
pub struct Vbb<R, const B: usize> {
    cfg: VbbConfig,
    blocks: [Block; B],
    count: usize,
    /// Each block's falling velocity (m/s, along z), while it falls.
    fall_mps: [R; B],
    /// Blocks whose support may have gone: checked each tick until they
    /// rest, then left alone (a world at rest costs no search for them).
    awake: [bool; B],
    /// The block each block is mated onto, if any.
    on: [Option<usize>; B],
    held: Option<usize>,
    /// The held block's corner minus the cursor (nm).
    grip_nm: [i32; 3],
    cursor: [Integrator<R>; 3],
    velocity_mps: [R; 3],
    /// The ports' forces last tick (N): the explicit scheme's input.
    last_force_n: [R; 3],
    t: R,
    g: R,
}

impl<R: Real, const B: usize> Vbb<R, B> {
    /// A world of `blocks` (at most `B`), the cursor at rest at the
    /// workspace's centre, 10 mm above its floor.
    pub fn new(cfg: VbbConfig, blocks: &[Block]) -> Result<Self, ParamError> {
        let t = param::positive("vbb.period_s (s)", cfg.period_s)?;
        param::positive("vbb.cursor_mass_kg (kg)", cfg.cursor_mass_kg)?;
        param::non_negative("vbb.friction", cfg.friction)?;
        if blocks.len() > B {
            return Err(ParamError {
                name: "vbb.blocks",
                value: blocks.len() as f32,
                problem: "more blocks than the world holds",
            });
        }
        if let Some(k) = cfg.knobs {
            param::positive("vbb.knobs.pitch_nm", k.pitch_nm as f32)?;
            param::non_negative("vbb.knobs.height_nm", k.height_nm as f32)?;
            param::non_negative("vbb.knobs.tolerance_nm", k.tolerance_nm as f32)?;
            param::non_negative("vbb.knobs.mate_force_n (N)", k.mate_force_n)?;
            param::non_negative("vbb.knobs.part_force_n (N)", k.part_force_n)?;
        }
        let (lo, hi) = (cfg.workspace[0], cfg.workspace[1]);
        if (0..3).any(|a| lo[a].nm() >= hi[a].nm()) {
            return Err(ParamError {
                name: "vbb.workspace",
                value: 0.0,
                problem: "its lowest corner must be below its highest on every axis",
            });
        }
        let filler = Block {
            min: [Position::ZERO; 3],
            size_nm: [1; 3],
            mass_kg: 1.0,
        };
        let mut w = Vbb {
            cfg,
            blocks: [filler; B],
            count: blocks.len(),
            fall_mps: [R::ZERO; B],
            awake: [true; B],
            on: [None; B],
            held: None,
            grip_nm: [0; 3],
            cursor: [Integrator::new_in(t, Position::ZERO); 3],
            velocity_mps: [R::ZERO; 3],
            last_force_n: [R::ZERO; 3],
            t: R::of(t),
            g: R::of(G_MPS2),
        };
        w.blocks[..blocks.len()].copy_from_slice(blocks);
        let mid =
            |a: usize| Position::from_nm(((lo[a].nm() as i64 + hi[a].nm() as i64) / 2) as i32);
        w.place_cursor_at([mid(0), mid(1), lo[2].offset_nm(10_000_000)]);
        Ok(w)
    }

    /// Put the cursor at rest at `x_m` (m); a position out of range is
    /// ignored.
    pub fn place_cursor(&mut self, x_m: [f32; 3]) {
        if let (Some(x), Some(y), Some(z)) = (
            Position::from_m(x_m[0]),
            Position::from_m(x_m[1]),
            Position::from_m(x_m[2]),
        ) {
            self.place_cursor_at([x, y, z]);
        }
    }

    fn place_cursor_at(&mut self, x: [Position; 3]) {
        for (c, x) in self.cursor.iter_mut().zip(x) {
            c.reset(x);
        }
        self.velocity_mps = [R::ZERO; 3];
        self.last_force_n = [R::ZERO; 3];
        self.carry_held();
    }

    /// The blocks.
    pub fn blocks(&self) -> &[Block] {
        &self.blocks[..self.count]
    }

    /// The cursor's position.
    pub fn cursor(&self) -> [Position; 3] {
        self.cursor.map(|c| c.position())
    }

    /// The block the cursor holds, if any.
    pub fn held(&self) -> Option<usize> {
        self.held
    }

    /// Grab the block the cursor touches (within its half-width); whether
    /// one was there. The block then moves with the cursor.
    pub fn grab(&mut self) -> bool {
        if self.held.is_some() {
            return true;
        }
        let c = self.cursor_extent();
        // (A cursor resting on a block's knobs touches the block.)
        let knob = self.cfg.knobs.map_or(0, |k| k.height_nm as i64);
        let near = |e: &Extent| {
            (0..3).all(|a| e.lo[a] <= c.hi[a] && c.lo[a] <= e.hi[a] + knob * (a == 2) as i64)
        };
        let Some(i) = self.blocks().iter().position(|b| near(&extent_of(b))) else {
            return false;
        };
        let x = self.cursor();
        self.grip_nm = [0, 1, 2].map(|a| self.blocks[i].min[a].nm().saturating_sub(x[a].nm()));
        // The block at rest joins the moving cursor: momentum is kept, so
        // the grab takes kinetic energy out rather than adding it.
        let keep =
            R::of(self.cfg.cursor_mass_kg / (self.cfg.cursor_mass_kg + self.blocks[i].mass_kg));
        self.velocity_mps = self.velocity_mps.map(|v| v * keep);
        self.held = Some(i);
        self.fall_mps[i] = R::ZERO;
        self.awake = [true; B];
        true
    }

    /// Let go of the held block: it falls from where it is.
    pub fn release(&mut self) {
        self.held = None;
        self.awake = [true; B];
    }

    /// The mass the couplings move (kg): the cursor's, plus the held
    /// block's.
    pub fn body_mass_kg(&self) -> f32 {
        self.cfg.cursor_mass_kg + self.held.map_or(0.0, |i| self.blocks[i].mass_kg)
    }

    fn cursor_extent(&self) -> Extent {
        let x = self.cursor();
        let h = self.cfg.cursor_half_nm as i64;
        Extent {
            lo: x.map(|p| p.nm() as i64 - h),
            hi: x.map(|p| p.nm() as i64 + h),
        }
    }

    /// The coupled body's extent: the held block's, or the cursor's.
    fn body_extent(&self) -> Extent {
        match self.held {
            Some(i) => extent_of(&self.blocks[i]),
            None => self.cursor_extent(),
        }
    }

    fn carry_held(&mut self) {
        if let Some(i) = self.held {
            let x = self.cursor();
            for ((min, x), grip) in self.blocks[i].min.iter_mut().zip(x).zip(self.grip_nm) {
                *min = x.offset_nm(grip);
            }
        }
    }

    /// How far (nm, >= 0) `body` may move along `axis` in direction `dir`
    /// (+1 or -1) before a face of the workspace or of a block other than
    /// `me` (the body's own block) stops it, and which block that is. A
    /// block's top stands its knobs' height higher, except to the block
    /// mated onto it.
    fn gap_nm(
        &self,
        body: &Extent,
        axis: usize,
        dir: i64,
        me: Option<usize>,
    ) -> (i64, Option<usize>) {
        let ws = self.cfg.workspace;
        let mut gap = if dir > 0 {
            ws[1][axis].nm() as i64 - body.hi[axis]
        } else {
            body.lo[axis] - ws[0][axis].nm() as i64
        };
        let mut by = None;
        let knob = self.cfg.knobs.map_or(0, |k| k.height_nm as i64);
        for (i, b) in self.blocks().iter().enumerate() {
            if Some(i) == me {
                continue;
            }
            let e = extent_of(b);
            if !body.faces(&e, axis) {
                continue;
            }
            let g = if dir > 0 {
                e.lo[axis] - body.hi[axis]
            } else if axis == 2 && body.lo[2] >= e.hi[2] {
                // Onto a top: its knobs, unless mated to it; a body already
                // among the knobs stays where it is.
                let mated = me.is_some_and(|m| self.on[m] == Some(i));
                let k = if mated { 0 } else { knob };
                (body.lo[2] - e.hi[2] - k).max(0)
            } else {
                body.lo[axis] - e.hi[axis]
            };
            // (A block the body is already inside, as the bare cursor is
            // in the block it just let go of, does not hold it: it leaves
            // freely.)
            if g >= 0 && g < gap {
                gap = g;
                by = Some(i);
            }
        }
        (gap.max(0), by)
    }

    /// Line the held block `h` up exactly on `j`'s knob grid (it moves by
    /// at most the tolerance, under the cursor): knobs seat square.
    fn snap_to_grid(&mut self, h: usize, j: usize, k: &Knobs) {
        let p = k.pitch_nm as i64;
        for a in 0..2 {
            let d = (self.blocks[h].min[a].nm() as i64 - self.blocks[j].min[a].nm() as i64)
                .rem_euclid(p);
            let shift = if d <= p / 2 { -d } else { p - d };
            self.grip_nm[a] = self.grip_nm[a].saturating_add(shift as i32);
        }
        self.carry_held();
    }

    /// Whether blocks `i` and `j` line up on the knob grid.
    fn aligned(&self, i: usize, j: usize, k: &Knobs) -> bool {
        let (p, t) = (k.pitch_nm as i64, k.tolerance_nm as i64);
        (0..2).all(|a| {
            let d = (self.blocks[i].min[a].nm() as i64 - self.blocks[j].min[a].nm() as i64)
                .rem_euclid(p);
            d.min(p - d) <= t
        })
    }

    /// Wake the blocks resting on the held block's top: it may move out
    /// from under them.
    fn wake_above_held(&mut self) {
        let Some(h) = self.held else { return };
        let top = extent_of(&self.blocks[h]);
        for (i, b) in self.blocks[..self.count].iter().enumerate() {
            let e = extent_of(b);
            if e.lo[2] == top.hi[2] && top.faces(&e, 2) {
                self.awake[i] = true;
            }
        }
    }

    /// Drop every awake free block that has nothing under it; one that
    /// rests goes to sleep.
    fn settle(&mut self) {
        for i in 0..self.count {
            if Some(i) == self.held || !self.awake[i] {
                continue;
            }
            let e = extent_of(&self.blocks[i]);
            let (below, _) = self.gap_nm(&e, 2, -1, Some(i));
            if below > 0 {
                self.on[i] = None;
            }
            let v = self.fall_mps[i] - self.g * self.t;
            let step = -v * self.t * R::NM_PER_M; // nm, > 0
            let fall = R::from_i64(below);
            if below == 0 || step >= fall {
                self.blocks[i].min[2] = self.blocks[i].min[2].offset_nm(-(below as i32));
                self.fall_mps[i] = R::ZERO;
                self.awake[i] = false;
            } else {
                self.blocks[i].min[2] = self.blocks[i].min[2].offset_nm(-step.trunc_i32());
                self.fall_mps[i] = v;
            }
        }
    }
}

impl<R: Real, const B: usize> Vbb<R, B> {
    /// The implicit step with no contact, `m (v - v0) = T (f0 - z v + w)`
    /// with the held block's weight `weight` on z: each axis's
    /// denominator and velocity. The explicit scheme's end-of-tick
    /// velocity, where it runs; the velocity is then the mean of the
    /// tick's two, the one the port sees.
    #[inline]
    fn free_step(&self, ports: &[Port<R>; 3], m: R, weight: R) -> ([R; 3], [R; 3], [R; 3]) {
        let t = self.t;
        let mut den = [R::ONE; 3];
        let mut v = [R::ZERO; 3];
        let mut v_end = [R::ZERO; 3];
        for a in 0..3 {
            let ext = if a == 2 { weight } else { R::ZERO };
            let v0 = self.velocity_mps[a];
            if self.cfg.explicit {
                den[a] = m;
                v_end[a] = v0 + t * (self.last_force_n[a] + ext) / m;
                v[a] = (v0 + v_end[a]) * R::HALF;
            } else {
                den[a] = m + t * ports[a].z_nspm;
                v[a] = (m * v0 + t * (ports[a].f0_n + ext)) / den[a];
            }
        }
        (den, v, v_end)
    }

    /// The knobs on a held block, pressed with `normal_z_n` (N) against
    /// the block it is `seated` on or the one `below` it: pulled up hard
    /// enough they let go; pressed onto an aligned block's knobs they give
    /// way, and it drops onto the top from the next tick (returned, to
    /// snap once the tick's motion is done).
    #[inline]
    fn knobs(
        &mut self,
        k: Knobs,
        (seated, below): (Option<usize>, Option<usize>),
        normal_z_n: R,
        rising: bool,
        resting: bool,
    ) -> Option<(usize, usize, Knobs)> {
        let h = self.held?;
        match (seated, below) {
            (Some(_), _) if rising && normal_z_n > R::of(k.part_force_n) => {
                self.on[h] = None;
                None
            }
            (None, Some(j))
                if resting && normal_z_n > R::of(k.mate_force_n) && self.aligned(h, j, &k) =>
            {
                self.on[h] = Some(j);
                Some((h, j, k))
            }
            _ => None,
        }
    }

    /// Coulomb friction on the axes with no contact of their own,
    /// implicit: it holds the body while the pull is inside the cone, else
    /// takes mu N off its velocity.
    #[inline]
    fn friction(&self, v: &mut [R; 3], normal_n: &[R; 3], den: &[R; 3]) {
        let mu = R::of(self.cfg.friction);
        for a in 0..3 {
            let n: R = (0..3)
                .filter(|&b| b != a)
                .fold(R::ZERO, |s, b| s + normal_n[b]);
            if normal_n[a] > R::ZERO || n == R::ZERO {
                continue;
            }
            let dv = self.t * mu * n / den[a];
            v[a] = if v[a].abs() <= dv {
                R::ZERO
            } else if v[a] > R::ZERO {
                v[a] - dv
            } else {
                v[a] + dv
            };
        }
    }
}

impl<R: Real, const B: usize> World<R, 3> for Vbb<R, B> {
    fn step_axes(&mut self, ports: &[Port<R>; 3]) -> [VeOutput<R>; 3] {
        if !ports
            .iter()
            .all(|p| p.f0_n.is_finite() && p.z_nspm.is_finite())
        {
            return ports.map(|p| p.at(R::ZERO));
        }
        let m = R::of(self.body_mass_kg());
        let (t, body) = (self.t, self.body_extent());
        let weight = match self.held {
            Some(i) if self.cfg.held_weight => -R::of(self.blocks[i].mass_kg) * self.g,
            _ => R::ZERO,
        };
        let (den, mut v, v_end) = self.free_step(ports, m, weight);
        let free = v;
        // Contacts: an axis whose step would cross a face stops at it, and
        // the face's push on the body is the normal force.
        let mut normal_n = [R::ZERO; 3];
        // Where an axis stops at a face: the cursor's exact position there
        // (the integrator's rounding must not take it a nanometre in).
        let mut stop: [Option<Position>; 3] = [None; 3];
        let x = self.cursor();
        // A held block seated on the one it is mated to: the knobs hold it
        // sideways and down, and up until it is pulled hard enough.
        let seated = match self.held {
            Some(h) => self.on[h].filter(|&j| body.lo[2] == extent_of(&self.blocks[j]).hi[2]),
            None => None,
        };
        let mut below = None;
        let mated = self.held.and_then(|h| self.on[h]);
        let rising = v[2] > R::ZERO;
        // (Knobs answer a steady push, not the impulse of landing on them.)
        let resting = self.velocity_mps[2] == R::ZERO;
        for a in 0..3 {
            let dir = if v[a] > R::ZERO { 1 } else { -1 };
            let (gap, by) = match (mated, a) {
                // The knobs hold a mated block sideways, and up once seated.
                (Some(_), 0 | 1) => (0, None),
                (Some(_), _) if seated.is_some() && dir > 0 => (0, None),
                _ => self.gap_nm(&body, a, dir, self.held),
            };
            if a == 2 && dir < 0 {
                below = by;
            }
            let reach_m = R::from_i64(gap) * R::M_PER_NM;
            if (v[a] * t).abs() > reach_m {
                let allowed = if dir > 0 { reach_m / t } else { -reach_m / t };
                normal_n[a] = (den[a] * (v[a] - allowed) / t).abs();
                v[a] = allowed;
                stop[a] = Some(x[a].offset_nm((dir * gap) as i32));
            }
        }
        let snap = self
            .cfg
            .knobs
            .and_then(|k| self.knobs(k, (seated, below), normal_n[2], rising, resting));
        self.friction(&mut v, &normal_n, &den);
        let out = [0, 1, 2].map(|a| ports[a].at(v[a]));
        for a in 0..3 {
            // (Explicit: a face or friction that changed the step ends it
            // at rest along that axis, or at the step's own speed.)
            self.velocity_mps[a] = if self.cfg.explicit && v[a] == free[a] {
                v_end[a]
            } else {
                v[a]
            };
            self.last_force_n[a] = out[a].force_n;
            match stop[a] {
                Some(at) => self.cursor[a].reset(at),
                None => {
                    self.cursor[a].step(v[a]);
                }
            }
        }
        self.wake_above_held();
        self.carry_held();
        if let Some((h, j, k)) = snap {
            self.snap_to_grid(h, j, &k);
        }
        self.settle();
        out
    }

    fn reset_axes(&mut self, x: &[Position; 3]) {
        self.place_cursor_at(*x);
    }

    fn positions(&self) -> [Position; 3] {
        self.cursor()
    }

    #[inline]
    fn offsets_m(&self, from: &[Position; 3]) -> [R; 3] {
        [0, 1, 2].map(|a| self.cursor[a].offset_m(from[a]))
    }

    /// Free space: the body's mass, `(T/m) / (1 - z^-1)`.
    fn axis_tf(&self, _axis: usize) -> VeTransfer {
        let t_over_m = self.t.to_f64() / self.body_mass_kg() as f64;
        VeTransfer::Admittance(ZTransfer::first_order([t_over_m, 0.0], -1.0))
    }
}
