//! The host's VE as the board runs it (protocol 8): one point per axis,
//! which the host moves at its own rate and the board holds between its
//! updates, so that the coupling runs at the servo's rate against a VE
//! that runs on the PC.

use super::World;
use crate::ve::{Port, VeOutput, VeTransfer};
use crate::{Position, Real, ZTransfer};

/// Points the host moves, held between its updates.
///
/// Between updates each point is rigid ground: it does not yield to the
/// coupling's force (admittance zero). An update moves it there in a
/// straight line over the next `ramp` ticks, at the velocity that takes it
/// there, so that the VE's positions stay the sum of its velocities and a
/// passivity layer at the VE's port counts the energy the move puts in.
/// A ramp as long as the host's period spreads each move over the period
/// (a first-order hold, one period late) instead of one tick's jump, which
/// the coupling's damper would feel as a spike `b Δx / T` once a period.
/// An update that comes before a ramp ends starts a new one from where the
/// point is.
#[derive(Clone, Copy, Debug)]
pub struct Held<const N: usize> {
    points: [Position; N],
    target: [Position; N],
    /// Ticks left to reach the target (0: there).
    left: u32,
    /// Ticks a move takes (at least 1).
    ramp: u32,
    /// 1 / T (1/s).
    rate_hz: f32,
}

impl<const N: usize> Held<N> {
    /// Points at `at`, for a servo of period `period_s` (s, > 0), each
    /// update reached over `ramp_ticks` ticks (0 counts as 1: the next
    /// tick).
    pub fn new(at: [Position; N], period_s: f32, ramp_ticks: u32) -> Self {
        Held {
            points: at,
            target: at,
            left: 0,
            ramp: ramp_ticks.max(1),
            rate_hz: 1.0 / period_s,
        }
    }

    /// Move each axis's point to `to`, starting at the next tick.
    pub fn set(&mut self, to: [Position; N]) {
        self.target = to;
        self.left = self.ramp;
    }

    /// Where the points are going, while they move.
    pub fn pending(&self) -> Option<[Position; N]> {
        (self.left > 0).then_some(self.target)
    }

    /// This tick's answer to every axis's port, committed (the world's
    /// step, on any number of axes).
    #[inline]
    fn step_points<R: Real>(&mut self, ports: &[Port<R>; N]) -> [VeOutput<R>; N] {
        let finite = ports
            .iter()
            .all(|p| p.f0_n.is_finite() && p.z_nspm.is_finite());
        let moving = finite && self.left > 0;
        let next: [Position; N] = core::array::from_fn(|i| {
            if moving {
                // The rest of the way in equal steps (the last lands on
                // the target exactly).
                let step = (self.target[i] - self.points[i]) / self.left as i32;
                self.points[i].offset_nm(step)
            } else {
                self.points[i]
            }
        });
        let rate = R::of(self.rate_hz) * R::M_PER_NM;
        let out =
            core::array::from_fn(|i| ports[i].at(next[i].nm_from::<R>(self.points[i]) * rate));
        if moving {
            self.points = next;
            self.left -= 1;
        }
        out
    }

    fn reset_points(&mut self, x: &[Position; N]) {
        self.points = *x;
        self.target = *x;
        self.left = 0;
    }
}

// (For each float rather than every `R: Real`: a crate downstream could
// make `Held<1>` a one-axis VE of its own float, whose blanket world
// would overlap this one.)
macro_rules! held_world {
    ($($r:ty)*) => {$(
        impl<const N: usize> World<$r, N> for Held<N> {
            #[inline]
            fn step_axes(&mut self, ports: &[Port<$r>; N]) -> [VeOutput<$r>; N] {
                self.step_points(ports)
            }

            fn reset_axes(&mut self, x: &[Position; N]) {
                self.reset_points(x);
            }

            #[inline]
            fn positions(&self) -> [Position; N] {
                self.points
            }

            /// `V/F = 0`: between updates a point does not yield.
            fn axis_tf(&self, _axis: usize) -> VeTransfer {
                VeTransfer::Admittance(ZTransfer::gain(0.0))
            }
        }
    )*};
}

held_world!(f32 f64);

#[cfg(test)]
mod tests {
    use super::*;

    fn port(f0_n: f32) -> Port<f32> {
        Port {
            f0_n,
            z_nspm: 100.0,
        }
    }

    /// A point stays put (zero velocity, the port's force at rest) until an
    /// update; the update moves it in one tick at `Δx / T`, and it stays
    /// there after. A tick with a non-finite port changes nothing and
    /// keeps the update for the next.
    #[test]
    fn points_hold_then_move_in_one_tick_at_the_velocity_that_takes_them_there() {
        let mut w = Held::new([Position::ZERO, Position::from_nm(5_000)], 1e-3, 1);
        let out = World::<f32, 2>::step_axes(&mut w, &[port(2.0), port(-1.0)]);
        assert_eq!(
            out.map(|o| (o.velocity_mps, o.force_n)),
            [(0.0, 2.0), (0.0, -1.0)]
        );
        w.set([Position::from_nm(10_000), Position::from_nm(5_000)]);
        let bad = World::<f32, 2>::step_axes(&mut w, &[port(f32::NAN), port(0.0)]);
        assert_eq!(bad.map(|o| o.velocity_mps), [0.0, 0.0]);
        assert_eq!(World::<f32, 2>::positions(&w)[0], Position::ZERO);
        let out = World::<f32, 2>::step_axes(&mut w, &[port(2.0), port(0.0)]);
        // 10 um in 1 ms: 10 mm/s, and the port's force at that velocity.
        assert!((out[0].velocity_mps - 0.01).abs() < 1e-9, "{out:?}");
        assert!((out[0].force_n - (2.0 - 100.0 * 0.01)).abs() < 1e-6);
        assert_eq!(out[1].velocity_mps, 0.0);
        assert_eq!(
            World::<f32, 2>::positions(&w),
            [Position::from_nm(10_000), Position::from_nm(5_000)]
        );
        let out = World::<f32, 2>::step_axes(&mut w, &[port(2.0), port(0.0)]);
        assert_eq!(out[0].velocity_mps, 0.0);
        // The positions are the sum of the velocities (times T, to the
        // f32 period's precision).
        w.set([Position::from_nm(-3_000), Position::from_nm(5_000)]);
        let v = World::<f64, 2>::step_axes(
            &mut w,
            &[Port {
                f0_n: 0.0,
                z_nspm: 1.0,
            }; 2],
        )[0]
        .velocity_mps;
        assert!(
            (10_000.0e-9 + v * 1e-3 - (-3_000.0e-9)).abs() < 1e-12,
            "{v}"
        );
        World::<f32, 2>::reset_axes(&mut w, &[Position::from_nm(7); 2]);
        assert_eq!(w.pending(), None);
        assert_eq!(World::<f32, 2>::positions(&w), [Position::from_nm(7); 2]);
    }

    /// A ramp of 4 ticks reaches the target in 4 equal steps at constant
    /// velocity, and exactly; an update in mid-ramp starts a new one from
    /// where the point is.
    #[test]
    fn a_ramp_spreads_the_move_over_its_ticks_and_lands_exactly() {
        let mut w = Held::new([Position::ZERO], 1e-3, 4);
        w.set([Position::from_nm(10_001)]);
        let mut path = std::vec::Vec::new();
        for _ in 0..5 {
            let [o] = World::<f64, 1>::step_axes(&mut w, &[port_f64()]);
            path.push((World::<f64, 1>::positions(&w)[0].nm(), o.velocity_mps));
        }
        let x: std::vec::Vec<i32> = path.iter().map(|p| p.0).collect();
        assert_eq!(x, [2_500, 5_000, 7_500, 10_001, 10_001]);
        assert_eq!(path[4].1, 0.0);
        for p in &path[..3] {
            assert!((p.1 - 2.5e-3).abs() < 1e-9, "{path:?}");
        }
        w.set([Position::ZERO]);
        World::<f64, 1>::step_axes(&mut w, &[port_f64()]);
        w.set([Position::from_nm(-4_000)]);
        let x: std::vec::Vec<i32> = (0..4)
            .map(|_| {
                World::<f64, 1>::step_axes(&mut w, &[port_f64()]);
                World::<f64, 1>::positions(&w)[0].nm()
            })
            .collect();
        // (From 7,501 nm, a quarter of the way to zero.)
        assert_eq!(x, [4_626, 1_751, -1_124, -4_000]);
    }

    fn port_f64() -> Port<f64> {
        Port {
            f0_n: 0.0,
            z_nspm: 1.0,
        }
    }
}
