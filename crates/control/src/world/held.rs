//! The host's VE as the board runs it (protocol 8): per axis, a surface
//! the host moves at its own rate and the board holds between updates,
//! and the VE point the coupling holds against it, solved at the servo's
//! rate, so that a delay on the link never lags the point behind the
//! handle in free space.

use super::World;
use crate::ve::{Port, VeOutput, VeTransfer};
use crate::{Position, Real, ZTransfer};

/// What an axis's held surface is to its VE point. It crosses the link as
/// it is (protocol 8's `VeUpdate`), so its variants' order is the wire's.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Contact {
    /// The point is the surface: rigid ground that does not yield to the
    /// coupling (admittance zero), moved only by the host.
    #[default]
    Held,
    /// The VE is solid above the surface: the point follows the coupling
    /// freely (no force) below it and stops at it.
    Above,
    /// Solid below the surface: free above it, stopped at it.
    Below,
    /// No surface: the point follows the coupling freely (no force).
    Free,
}

impl From<crate::ve::Solid> for Contact {
    /// A wall's surface: solid on the same side.
    fn from(s: crate::ve::Solid) -> Self {
        match s {
            crate::ve::Solid::Above => Contact::Above,
            crate::ve::Solid::Below => Contact::Below,
        }
    }
}

/// Surfaces the host moves, held between its updates, and the VE points
/// the coupling holds against them.
///
/// Each tick, an axis's point moves as a massless body would under the
/// coupling's law: where it is free, to where the coupling pulls no more
/// (`f = 0`); where its surface stops it, to the surface, rigidly. The law
/// is piecewise: free (impedance zero) or in contact (admittance zero),
/// both passive. The host's side then needs no fast answer: a surface
/// under a moving handle, sent at 1 kHz, is rendered at the servo's rate.
///
/// An update moves a surface there in a straight line over the next
/// `ramp` ticks, at the velocity that takes it there, so that a point
/// pushed by it moves as the sum of its velocities and a passivity layer at
/// the VE's port counts the energy the move puts in. A ramp as long as the
/// host's period spreads each move over the period (a first-order hold, one
/// period late) instead of one tick's jump, which the coupling's damper
/// would feel as a spike `b Δx / T` once a period. An update that comes
/// before a ramp ends starts a new one from where the surface is.
#[derive(Clone, Copy, Debug)]
pub struct Held<const N: usize> {
    points: [Position; N],
    surfaces: [Position; N],
    target: [Position; N],
    contact: [Contact; N],
    /// Ticks left to reach the target (0: there).
    left: u32,
    /// Ticks a move takes (at least 1).
    ramp: u32,
    /// T (s) and 1 / T (1/s).
    period_s: f32,
    rate_hz: f32,
}

impl<const N: usize> Held<N> {
    /// Points held at `at` (each axis [`Contact::Held`]), for a servo of
    /// period `period_s` (s, > 0), each update reached over `ramp_ticks`
    /// ticks (0 counts as 1: the next tick).
    pub fn new(at: [Position; N], period_s: f32, ramp_ticks: u32) -> Self {
        Held {
            points: at,
            surfaces: at,
            target: at,
            contact: [Contact::Held; N],
            left: 0,
            ramp: ramp_ticks.max(1),
            period_s,
            rate_hz: 1.0 / period_s,
        }
    }

    /// Move each axis's surface to `to`, starting at the next tick, and
    /// make it what `contact` says from then on.
    pub fn set(&mut self, to: [Position; N], contact: [Contact; N]) {
        self.target = to;
        self.contact = contact;
        self.left = self.ramp;
    }

    /// Where the surfaces are going, while they move.
    pub fn pending(&self) -> Option<[Position; N]> {
        (self.left > 0).then_some(self.target)
    }

    /// Ticks a move takes.
    pub fn ramp_ticks(&self) -> u32 {
        self.ramp
    }

    /// The ramp's law in the z-domain, for a host that updates once every
    /// `ramp` ticks: each surface is the mean of the targets over the last
    /// `ramp` ticks, each target held from the tick it takes its first step
    /// (a zero-order hold), `S(z)/U(z) = (1/N) Σ_{i<N} z^-i` with `N` the
    /// ramp (to the steps' whole nanometres: within `N` nm).
    pub fn ramp_response(&self, z: num_complex::Complex64) -> num_complex::Complex64 {
        let zi = z.inv();
        let (mut sum, mut p) = (
            num_complex::Complex64::new(0.0, 0.0),
            num_complex::Complex64::new(1.0, 0.0),
        );
        for _ in 0..self.ramp {
            sum += p;
            p *= zi;
        }
        sum / f64::from(self.ramp)
    }

    /// Each axis's surface now.
    pub fn surfaces(&self) -> [Position; N] {
        self.surfaces
    }

    /// This tick's answer to every axis's port, committed (the world's
    /// step, on any number of axes).
    #[inline]
    fn step_points<R: Real>(&mut self, ports: &[Port<R>; N]) -> [VeOutput<R>; N] {
        let finite = ports
            .iter()
            .all(|p| p.f0_n.is_finite() && p.z_nspm.is_finite());
        if !finite {
            return core::array::from_fn(|i| ports[i].at(R::ZERO));
        }
        let moving = self.left > 0;
        let rate = R::of(self.rate_hz) * R::M_PER_NM;
        let t_nm = R::of(self.period_s) / R::M_PER_NM;
        let mut out = [VeOutput::default(); N];
        for i in 0..N {
            if moving {
                // The rest of the way in equal steps (the last lands on
                // the target exactly).
                let step = (self.target[i] - self.surfaces[i]) / self.left as i32;
                self.surfaces[i] = self.surfaces[i].offset_nm(step);
            }
            let (p, s) = (self.points[i], self.surfaces[i]);
            // Where the coupling would leave a free point: f = 0.
            let free = || {
                let d = ports[i].f0_n / ports[i].z_nspm * t_nm;
                let half = if d < R::ZERO { -R::HALF } else { R::HALF };
                p.offset_nm((d + half).trunc_i32())
            };
            let next = match self.contact[i] {
                Contact::Held => s,
                Contact::Free => free(),
                Contact::Above => free().min(s),
                Contact::Below => free().max(s),
            };
            out[i] = ports[i].at(next.nm_from::<R>(p) * rate);
            self.points[i] = next;
        }
        if moving {
            self.left -= 1;
        }
        out
    }

    fn reset_points(&mut self, x: &[Position; N]) {
        self.points = *x;
        self.surfaces = *x;
        self.target = *x;
        self.contact = [Contact::Held; N];
        self.left = 0;
    }

    /// Axis `axis`'s law: free, impedance zero; held or in contact (the
    /// piece a proof of a wall needs), admittance zero.
    fn tf_of(&self, axis: usize) -> VeTransfer {
        match self.contact.get(axis) {
            Some(Contact::Free) => VeTransfer::Impedance(ZTransfer::gain(0.0)),
            _ => VeTransfer::Admittance(ZTransfer::gain(0.0)),
        }
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

            fn axis_tf(&self, axis: usize) -> VeTransfer {
                self.tf_of(axis)
            }
        }
    )*};
}

held_world!(f32 f64);

#[cfg(test)]
mod tests {
    use super::*;

    /// The ramp the designer analyses is the ramp the board runs: targets
    /// sent every `N` ticks along a sinusoid, each held surface against the
    /// mean of the targets over the last `N` ticks, and that mean's steady
    /// response to a sinusoid against `ramp_response`.
    #[test]
    fn a_host_updating_every_ramp_moves_the_surface_as_analysed() {
        use num_complex::Complex64;
        for n in [1u32, 4, 10] {
            let mut w = Held::<1>::new([Position::ZERO], 1e-4, n);
            let ports = [port(0.0)];
            // 16 whole periods over the 2,000 ticks fitted, so the hold's images
            // fall on other bins.
            let th = 2.0 * core::f64::consts::PI * 16.0 / 2000.0;
            let target = |k: u32| (2.0e5 * (th * f64::from(k)).sin()) as i32;
            let mut held = [0i32; 4000];
            let mut fit = (Complex64::new(0.0, 0.0), Complex64::new(0.0, 0.0));
            for k in 0..4000u32 {
                if k % n == 0 {
                    w.set([Position::from_nm(target(k))], [Contact::Held]);
                }
                held[k as usize] = target(k - k % n);
                World::<f32, 1>::step_axes(&mut w, &ports);
                let s = w.surfaces()[0].nm();
                let mean: f64 = (0..n as usize)
                    .map(|i| f64::from(held[(k as usize).saturating_sub(i)]))
                    .sum::<f64>()
                    / f64::from(n);
                assert!(
                    (f64::from(s) - mean).abs() <= f64::from(n),
                    "N {n} tick {k}: {s} against {mean}"
                );
                // The steady response of surface to the held target at θ
                // (one period of a host's update: the hold's phase is
                // the same at every update).
                if k >= 2000 {
                    let e = Complex64::from_polar(1.0, -th * f64::from(k));
                    fit.0 += f64::from(s) * e;
                    fit.1 += f64::from(held[k as usize]) * e;
                }
            }
            let h = w.ramp_response(Complex64::from_polar(1.0, th));
            assert!(
                (fit.0 / fit.1 - h).norm() < 1e-3 * h.norm(),
                "N {n}: {} against {h}",
                fit.0 / fit.1
            );
        }
    }

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
        w.set(
            [Position::from_nm(10_000), Position::from_nm(5_000)],
            [Contact::Held; 2],
        );
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
        w.set(
            [Position::from_nm(-3_000), Position::from_nm(5_000)],
            [Contact::Held; 2],
        );
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
        w.set([Position::from_nm(10_001)], [Contact::Held]);
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
        w.set([Position::ZERO], [Contact::Held]);
        World::<f64, 1>::step_axes(&mut w, &[port_f64()]);
        w.set([Position::from_nm(-4_000)], [Contact::Held]);
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

    /// A spring-damper coupling to a handle at `x_h` (m, at rest) seen as
    /// a port by a point at `p` (backward Euler, T = 1 ms).
    fn coupling(x_h: f64, p: Position) -> Port<f64> {
        let (k, b, t) = (51_000.0, 90.0, 1e-3);
        Port {
            f0_n: k * (x_h - p.nm() as f64 * 1e-9),
            z_nspm: b + k * t,
        }
    }

    /// Solid above a surface at 1 mm, a handle at 0.4 mm: the point
    /// joins the handle (as fast as the damper lets it: 36% of the way a
    /// tick) with no force left (to the nanometre's), and the
    /// handle at 1.5 mm presses it onto the surface, where it stops and
    /// the coupling's spring pushes back. Free, it follows the handle
    /// anywhere; below, it stops from underneath.
    #[test]
    fn a_surface_stops_the_point_only_on_its_solid_side() {
        let mut w = Held::new([Position::ZERO], 1e-3, 1);
        w.set([Position::from_nm(1_000_000)], [Contact::Above]);
        let step = |w: &mut Held<1>, x_h: f64| {
            let p = World::<f64, 1>::positions(w)[0];
            World::<f64, 1>::step_axes(w, &[coupling(x_h, p)])[0]
        };
        let mut last = VeOutput::default();
        for _ in 0..40 {
            last = step(&mut w, 0.4e-3);
        }
        let p = World::<f64, 1>::positions(&w)[0].nm();
        assert!((p - 400_000).abs() <= 1, "{p}");
        assert!(last.force_n.abs() < 0.1, "{last:?}");
        for _ in 0..40 {
            last = step(&mut w, 1.5e-3);
        }
        assert_eq!(World::<f64, 1>::positions(&w)[0].nm(), 1_000_000);
        assert!((last.force_n - 51_000.0 * 0.5e-3).abs() < 1e-6, "{last:?}");
        assert!(matches!(
            World::<f64, 1>::axis_tf(&w, 0),
            VeTransfer::Admittance(_)
        ));
        w.set([Position::from_nm(1_000_000)], [Contact::Free]);
        for _ in 0..40 {
            step(&mut w, 1.5e-3);
        }
        assert!((World::<f64, 1>::positions(&w)[0].nm() - 1_500_000).abs() <= 1);
        assert!(matches!(
            World::<f64, 1>::axis_tf(&w, 0),
            VeTransfer::Impedance(_)
        ));
        w.set([Position::from_nm(1_200_000)], [Contact::Below]);
        for _ in 0..40 {
            step(&mut w, 0.0);
        }
        assert_eq!(World::<f64, 1>::positions(&w)[0].nm(), 1_200_000);
    }
}
