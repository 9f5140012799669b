//! Position-position: each side a virtual coupling to the other's motion
//! as the channel delivers it.

use super::{Channel, Delayed, TeleopTransfer};
use crate::{ImpedanceCoupling, ParamError, Position, Real, ZTransfer};

/// What a device's side sends: its position and velocity estimate (m/s).
pub type Motion<R> = (Position, R);

/// The symmetric position-position teleoperator: the master is held to
/// the slave's motion and the slave to the master's, each by the spring
/// `k` and damper `b` of an impedance coupling, across a channel that
/// delays each side's motion by `d` ticks (at most `D`):
///
/// `f_m = k (x_m - x_s[k-d]) + b (v_m - v_s[k-d])`,
/// `f_s = k (x_s - x_m[k-d]) + b (v_s - v_m[k-d])`,
///
/// which is `F = Z V` with `Z_mm = Z_ss = Z_cI(z)` and `Z_ms = Z_sm =
/// -Z_cI(z) z^-d`, `Z_cI = b + kTz/(z - 1)` the paper's coupling (eq 20):
/// the velocities are the positions' backward differences, so
/// `X = T V/(1 - z^-1)` exactly. Forces are positive resisting each
/// device's positive motion.
#[derive(Clone, Copy, Debug)]
pub struct PositionPosition<R = f32, const D: usize = 64> {
    coupling: ImpedanceCoupling<R>,
    k: R,
    b: R,
    to_slave: Channel<Motion<R>, D>,
    to_master: Channel<Motion<R>, D>,
}

/// One tick's forces (N).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TeleopStep<R = f32> {
    /// On the master.
    pub master_n: R,
    /// On the slave.
    pub slave_n: R,
}

impl<R: Real, const D: usize> PositionPosition<R, D> {
    /// The teleoperator of stiffness `k_npm` (N/m) and damping `b_nspm`
    /// (N s/m) at `period_s` (s), its channel `delay_ticks` long each way
    /// (at most `D`), both devices at `at` until their motion arrives.
    ///
    /// # Examples
    ///
    /// ```
    /// use twoport_control::teleop::PositionPosition;
    /// use twoport_control::Position;
    /// let mut t = PositionPosition::<f32, 8>::new(1_000.0, 5.0, 1e-3, 2, Position::ZERO)?;
    /// // The master 1 mm ahead: its pull reaches the slave two ticks on.
    /// let ahead = (Position::from_nm(1_000_000), 0.0);
    /// let at_rest = (Position::ZERO, 0.0);
    /// let f: Vec<f32> = (0..3).map(|_| t.step(ahead, at_rest).slave_n).collect();
    /// assert_eq!(f, [0.0, 0.0, -1.0]);
    /// assert!(PositionPosition::<f32, 8>::new(1_000.0, 5.0, 1e-3, 9, Position::ZERO).is_err());
    /// # Ok::<(), twoport_control::ParamError>(())
    /// ```
    pub fn new(
        k_npm: f32,
        b_nspm: f32,
        period_s: f32,
        delay_ticks: usize,
        at: Position,
    ) -> Result<Self, ParamError> {
        let coupling = ImpedanceCoupling::<R>::new_in(k_npm, b_nspm, period_s)?;
        let channel = || {
            Channel::new(delay_ticks, (at, R::ZERO)).ok_or(ParamError {
                name: "delay (ticks)",
                value: delay_ticks as f32,
                problem: "must be at most the channel's length",
            })
        };
        Ok(PositionPosition {
            coupling,
            k: R::of(k_npm),
            b: R::of(b_nspm),
            to_slave: channel()?,
            to_master: channel()?,
        })
    }

    /// One tick: each device's position and velocity estimate (m/s) in,
    /// each its force out, against the other's motion as it arrives.
    #[inline]
    pub fn step(&mut self, master: Motion<R>, slave: Motion<R>) -> TeleopStep<R> {
        let from_slave = self.to_master.pass(slave);
        let from_master = self.to_slave.pass(master);
        let pull = |(x, v): Motion<R>, (x_r, v_r): Motion<R>| {
            self.k * x.nm_from::<R>(x_r) * R::M_PER_NM + self.b * (v - v_r)
        };
        TeleopStep {
            master_n: pull(master, from_slave),
            slave_n: pull(slave, from_master),
        }
    }

    /// Both devices at `at` and at rest, the channel emptied.
    pub fn reset(&mut self, at: Position) {
        self.to_slave.reset((at, R::ZERO));
        self.to_master.reset((at, R::ZERO));
    }

    /// Stiffness (N/m) and damping (N s/m).
    pub fn gains(&self) -> (f32, f32) {
        self.coupling.gains()
    }

    /// `F = Z V` with `Z_mm = Z_ss = Z_cI`, `Z_ms = Z_sm = -Z_cI z^-d`.
    pub fn tf(&self) -> TeleopTransfer {
        let zci = self.coupling.tf();
        let neg = ZTransfer {
            num: zci.num.map(|c| -c),
            den: zci.den,
        };
        let remote = Delayed::after(neg, self.to_slave.delay_ticks() as u32);
        let local = Delayed::now(zci);
        TeleopTransfer {
            z: [
                [local, remote, Delayed::ZERO],
                [remote, local, Delayed::ZERO],
            ],
        }
    }
}
