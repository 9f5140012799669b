//! A 1-D building-block world in the spirit of the paper's VBB: a cursor,
//! blocks on a line between two walls, grab one, push others, and mated
//! blocks that stick until pulled apart.

use crate::Error;
use twoport_control::ve::{Causality, CursorMass, Port, VeOutput, VeTransfer, VirtualEnvironment};
use twoport_control::{Position, ZTransfer};

/// One block.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LineBlock {
    /// Left edge.
    pub left: Position,
    /// Width (nm).
    pub width_nm: i32,
    /// Mass (kg).
    pub mass_kg: f32,
    /// Velocity (m/s).
    pub velocity_mps: f32,
}

impl LineBlock {
    fn right(&self) -> Position {
        self.left + self.width_nm
    }
}

/// The world. Admittance causality: it takes the coupling's force and
/// returns a velocity, solving the coupling's loop exactly each tick.
#[derive(Clone, Debug)]
pub struct Blocks {
    period_s: f32,
    cursor: CursorMass,
    blocks: Vec<LineBlock>,
    limits: [Position; 2],
    stick_n: f32,
    floor_nspm: f32,
    grabbed: Option<usize>,
    /// Cursor position minus the grabbed block's left edge (nm).
    offset_nm: i32,
    ticks: u64,
    grab_tick: Option<u64>,
    release_tick: Option<u64>,
}

/// Touching within 1 nm.
const TOUCH_NM: i32 = 1;

impl Blocks {
    /// A world; `grab_at_s`/`release_at_s` script the mouse button.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        period_s: f32,
        cursor_mass_kg: f32,
        blocks: Vec<LineBlock>,
        limits: [Position; 2],
        stick_n: f32,
        floor_nspm: f32,
        grab_at_s: Option<f64>,
        release_at_s: Option<f64>,
    ) -> Result<Self, Error> {
        let cursor =
            CursorMass::new(cursor_mass_kg, period_s, Position::ZERO).map_err(|e| e.to_string())?;
        let tick = |t: f64| (t / period_s as f64).round() as u64;
        Ok(Blocks {
            period_s,
            cursor,
            blocks,
            limits,
            stick_n,
            floor_nspm,
            grabbed: None,
            offset_nm: 0,
            ticks: 0,
            grab_tick: grab_at_s.map(tick),
            release_tick: release_at_s.map(tick),
        })
    }

    /// The blocks.
    pub fn blocks(&self) -> &[LineBlock] {
        &self.blocks
    }

    /// The grabbed block.
    pub fn grabbed(&self) -> Option<usize> {
        self.grabbed
    }

    /// Grab the block under the cursor, if any.
    pub fn grab(&mut self) -> Option<usize> {
        let x = self.cursor.position();
        let i = self
            .blocks
            .iter()
            .position(|b| b.left <= x && x <= b.right())?;
        self.offset_nm = x - self.blocks[i].left;
        self.grabbed = Some(i);
        Some(i)
    }

    /// Let go: the cursor continues from the block with its velocity.
    pub fn release(&mut self) {
        if let Some(i) = self.grabbed.take() {
            let b = self.blocks[i];
            self.cursor.reset(b.left + self.offset_nm);
        }
    }

    /// The contiguous touching chain around block `g`: indices `lo..=hi`.
    fn chain(&self, g: usize) -> (usize, usize) {
        let (mut lo, mut hi) = (g, g);
        while lo > 0 && self.blocks[lo].left - self.blocks[lo - 1].right() <= TOUCH_NM {
            lo -= 1;
        }
        while hi + 1 < self.blocks.len()
            && self.blocks[hi + 1].left - self.blocks[hi].right() <= TOUCH_NM
        {
            hi += 1;
        }
        (lo, hi)
    }

    fn group_solve(&self, port: Port, lo: usize, hi: usize) -> (f32, VeOutput) {
        let bs = &self.blocks[lo..=hi];
        let m: f32 = bs.iter().map(|b| b.mass_kg).sum();
        let p: f32 = bs.iter().map(|b| b.mass_kg * b.velocity_mps).sum();
        (m, port.solve_admittance(p / m, self.period_s / m))
    }

    fn step_grabbed(&mut self, port: Port, g: usize) -> VeOutput {
        let t = self.period_s;
        let (mut lo, mut hi) = self.chain(g);
        let (_, mut out) = self.group_solve(port, lo, hi);
        // Blocks behind the motion are dragged by the joint's friction: if
        // dragging them needs more than it holds, they stay.
        let v = out.velocity_mps;
        let behind: Vec<usize> = if v > 0.0 {
            (lo..g).collect()
        } else {
            (g + 1..=hi).collect()
        };
        let drag: f32 = behind
            .iter()
            .map(|&i| self.blocks[i].mass_kg * (v - self.blocks[i].velocity_mps).abs() / t)
            .sum();
        if !behind.is_empty() && drag > self.stick_n {
            if v > 0.0 {
                lo = g;
            } else {
                hi = g;
            }
            out = self.group_solve(port, lo, hi).1;
        }
        // The leading face stops exactly at the next obstacle this tick: the
        // move is clamped in integer nanometres, and the velocity follows
        // from it, so nothing ever overlaps.
        if !out.velocity_mps.is_finite() {
            return out;
        }
        let want = (out.velocity_mps as f64 * t as f64 * 1e9).round() as i32;
        let d = if want > 0 {
            let front = self.blocks[hi].right();
            let wall = self.blocks.get(hi + 1).map_or(self.limits[1], |b| b.left);
            want.min((wall - front).max(0))
        } else if want < 0 {
            let back = self.blocks[lo].left;
            let wall = if lo > 0 {
                self.blocks[lo - 1].right()
            } else {
                self.limits[0]
            };
            want.max(-(back - wall).max(0))
        } else {
            0
        };
        if d != want {
            out = port.at((d as f64 * 1e-9 / t as f64) as f32);
        }
        for b in &mut self.blocks[lo..=hi] {
            b.velocity_mps = out.velocity_mps;
            b.left = b.left + d;
        }
        self.drift_free(lo, hi);
        out
    }

    /// Free blocks coast against floor drag and stop at whatever they meet.
    fn drift_free(&mut self, lo: usize, hi: usize) {
        let t = self.period_s;
        for i in (0..self.blocks.len()).filter(|i| *i < lo || *i > hi) {
            let b = self.blocks[i];
            let v = b.velocity_mps / (1.0 + t * self.floor_nspm / b.mass_kg);
            let mut d = (v as f64 * t as f64 * 1e9) as i32;
            let left_wall = if i > 0 {
                self.blocks[i - 1].right()
            } else {
                self.limits[0]
            };
            let right_wall = self.blocks.get(i + 1).map_or(self.limits[1], |n| n.left);
            let mut v = v;
            if b.right() + d > right_wall {
                d = (right_wall - b.right()).max(0);
                v = 0.0;
            } else if b.left + d < left_wall {
                d = -(b.left - left_wall).max(0);
                v = 0.0;
            }
            self.blocks[i].velocity_mps = v;
            self.blocks[i].left = b.left + d;
        }
    }
}

impl VirtualEnvironment for Blocks {
    fn causality(&self) -> Causality {
        Causality::Admittance
    }

    fn step(&mut self, port: Port) -> VeOutput {
        self.ticks += 1;
        if self.grab_tick == Some(self.ticks) {
            self.grab();
        }
        if self.release_tick == Some(self.ticks) {
            self.release();
        }
        match self.grabbed {
            Some(g) => self.step_grabbed(port, g),
            None => {
                let n = self.blocks.len();
                self.drift_free(n, n);
                self.cursor.step(port)
            }
        }
    }

    fn reset(&mut self, x: Position) {
        self.grabbed = None;
        self.cursor.reset(x);
    }

    fn position(&self) -> Position {
        match self.grabbed {
            Some(g) => self.blocks[g].left + self.offset_nm,
            None => self.cursor.position(),
        }
    }

    /// A grabbed block sits on whole nanometres; the free cursor carries its
    /// integrator's remainder.
    fn offset_m(&self, from: Position) -> f32 {
        match self.grabbed {
            Some(_) => self.position().minus_m(from),
            None => self.cursor.offset_m(from),
        }
    }

    /// The coupled body's mass admittance `(T/m)/(1 - z^-1)`.
    fn tf(&self) -> VeTransfer {
        let m = match self.grabbed {
            Some(g) => self.blocks[g].mass_kg,
            None => self.cursor.mass_kg(),
        };
        VeTransfer::Admittance(ZTransfer::first_order(
            [(self.period_s / m) as f64, 0.0],
            -1.0,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const T: f32 = 1e-3;

    fn at(m: f64) -> Position {
        Position::from_m_f64(m).unwrap()
    }

    fn world(stick: f32) -> Blocks {
        let b = |left_m: f64| LineBlock {
            left: at(left_m),
            width_nm: 20_000_000,
            mass_kg: 0.5,
            velocity_mps: 0.0,
        };
        Blocks::new(
            T,
            0.25,
            vec![b(-0.01), b(0.01), b(0.1)],
            [at(-0.1), at(0.2)],
            stick,
            5.0,
            None,
            None,
        )
        .unwrap()
    }

    /// A steady pull of the port drives the grabbed block and the block
    /// mated to it along, into the third block, which is pushed to the wall
    /// where everything stops: no overlap, ever.
    #[test]
    fn pushing_a_chain_into_the_wall_never_overlaps() {
        let mut w = world(1e6);
        assert_eq!(w.grab(), Some(0));
        for _ in 0..5000 {
            let out = w.step(Port {
                f0_n: 30.0,
                z_nspm: 50.0,
            });
            assert!(out.velocity_mps.is_finite());
            let b = w.blocks();
            for i in 0..b.len() {
                let right_limit = if i + 1 < b.len() {
                    b[i + 1].left
                } else {
                    at(0.2)
                };
                assert!(b[i].right() <= right_limit, "overlap at block {i}");
            }
        }
        let b = w.blocks();
        assert!(
            (b[2].right() - at(0.2)).abs() <= TOUCH_NM,
            "pushed to the wall"
        );
        assert!(
            w.step(Port {
                f0_n: 30.0,
                z_nspm: 50.0
            })
            .velocity_mps
            .abs()
                < 1e-6
        );
    }

    /// Pulling away from a mated block: a weak joint lets go, a strong one
    /// drags the neighbour along.
    #[test]
    fn stick_friction_decides_whether_a_neighbour_follows() {
        for (stick, follows) in [(0.5f32, false), (1e6, true)] {
            let mut w = world(stick);
            // Mate block 1 to block 0's right face first.
            w.blocks[1].left = w.blocks[0].right();
            w.grab();
            for _ in 0..200 {
                w.step(Port {
                    f0_n: -20.0,
                    z_nspm: 50.0,
                });
            }
            let gap = w.blocks()[1].left - w.blocks()[0].right();
            assert_eq!(gap <= TOUCH_NM, follows, "stick {stick}: gap {gap} nm");
        }
    }
}
