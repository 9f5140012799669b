//! Position-force: the slave tracks the master's motion, the master
//! feels the environment's force as the slave's sensor reads it.

use super::position::Motion;
use super::{Channel, Delayed, TeleopStep, TeleopTransfer};
use crate::{param, ImpedanceCoupling, ParamError, Position, Real, ZTransfer};

/// Force reflection: the slave held to the master's motion by an
/// impedance coupling (`k`, `b`), the master pushed by the force the
/// slave's sensor reads, scaled by `k_f`, with damping `b_m` of its own,
/// across a channel of `d` ticks each way (at most `D`):
///
/// `f_m = b_m v_m - k_f f_e[k-d]`,
/// `f_s = k (x_s - x_m[k-d]) + b (v_s - v_m[k-d])`,
///
/// with `f_e` the environment's force on the slave along `+x` (a wall
/// ahead of it reads negative, and the master is held back). Its form:
/// `f_m = b_m v_m - k_f z^-d f_e`, `f_s = Z_cI (v_s - z^-d v_m)`.
#[derive(Clone, Copy, Debug)]
pub struct PositionForce<R = f32, const D: usize = 64> {
    coupling: ImpedanceCoupling<R>,
    k: R,
    b: R,
    k_f: R,
    b_m: R,
    to_slave: Channel<Motion<R>, D>,
    to_master: Channel<R, D>,
}

impl<R: Real, const D: usize> PositionForce<R, D> {
    /// The slave's coupling `k_npm` (N/m) and `b_nspm` (N s/m), the force
    /// scale `k_f` (the master's force per the environment's) and the
    /// master's damping `b_m_nspm` (N s/m), at `period_s` (s), the
    /// channel `delay_ticks` long each way, the master at `at` until its
    /// motion arrives.
    ///
    /// # Examples
    ///
    /// ```
    /// use twoport_control::teleop::PositionForce;
    /// use twoport_control::Position;
    /// let mut t = PositionForce::<f32, 8>::new(1_000.0, 5.0, 0.5, 2.0, 1e-3, 1, Position::ZERO)?;
    /// // The slave against a wall that pushes back 2 N: the master feels
    /// // half of it a tick later, holding it back.
    /// let rest = (Position::ZERO, 0.0);
    /// let f: Vec<f32> = (0..2).map(|_| t.step(rest, rest, -2.0).master_n).collect();
    /// assert_eq!(f, [0.0, 1.0]);
    /// # Ok::<(), twoport_control::ParamError>(())
    /// ```
    pub fn new(
        k_npm: f32,
        b_nspm: f32,
        k_f: f32,
        b_m_nspm: f32,
        period_s: f32,
        delay_ticks: usize,
        at: Position,
    ) -> Result<Self, ParamError> {
        let coupling = ImpedanceCoupling::<R>::new_in(k_npm, b_nspm, period_s)?;
        let k_f = param::non_negative("k_f (force scale)", k_f)?;
        let b_m = param::non_negative("b_m (N s/m)", b_m_nspm)?;
        let too_long = ParamError {
            name: "delay (ticks)",
            value: delay_ticks as f32,
            problem: "must be at most the channel's length",
        };
        Ok(PositionForce {
            coupling,
            k: R::of(k_npm),
            b: R::of(b_nspm),
            k_f: R::of(k_f),
            b_m: R::of(b_m),
            to_slave: Channel::new(delay_ticks, (at, R::ZERO)).ok_or(too_long)?,
            to_master: Channel::new(delay_ticks, R::ZERO).ok_or(too_long)?,
        })
    }

    /// One tick: each device's position and velocity estimate (m/s), and
    /// the environment's force on the slave as its sensor reads it (N,
    /// along `+x`), in; each device's force out.
    #[inline]
    pub fn step(&mut self, master: Motion<R>, slave: Motion<R>, env_n: R) -> TeleopStep<R> {
        let reflected = self.to_master.pass(env_n);
        let (x_m, v_m) = self.to_slave.pass(master);
        let (x_s, v_s) = slave;
        TeleopStep {
            master_n: self.b_m * master.1 - self.k_f * reflected,
            slave_n: self.k * x_s.nm_from::<R>(x_m) * R::M_PER_NM + self.b * (v_s - v_m),
        }
    }

    /// The master's motion at `at` and at rest, no force reflected, the
    /// channel emptied.
    pub fn reset(&mut self, at: Position) {
        self.to_slave.reset((at, R::ZERO));
        self.to_master.reset(R::ZERO);
    }

    /// `f_m = b_m v_m - k_f z^-d f_e`, `f_s = Z_cI (v_s - z^-d v_m)`.
    pub fn tf(&self) -> TeleopTransfer {
        let zci = self.coupling.tf();
        let d = self.to_slave.delay_ticks() as u32;
        let delayed = |tf| Delayed::after(tf, d);
        let neg = ZTransfer {
            num: zci.num.map(|c| -c),
            den: zci.den,
        };
        TeleopTransfer {
            z: [
                [
                    Delayed::now(ZTransfer::gain(self.b_m.to_f64())),
                    Delayed::ZERO,
                    delayed(ZTransfer::gain(-self.k_f.to_f64())),
                ],
                [delayed(neg), Delayed::now(zci), Delayed::ZERO],
            ],
        }
    }
}
