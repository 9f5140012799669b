//! Lawrence's four-channel teleoperator, of which position-position and
//! position-force are the common cases.

use super::{Channel, Delayed, TeleopTransfer};
use crate::{param, ParamError, Position, Real, ZTransfer};

/// What a device's side sends: its position and velocity estimate (m/s).
pub type Motion<R> = (Position, R);

/// One tick's forces (N).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TeleopStep<R = f32> {
    /// On the master.
    pub master_n: R,
    /// On the slave.
    pub slave_n: R,
}

/// The gains of a [`FourChannel`] teleoperator, SI units. Each side's
/// coupling is a spring and damper on its position error against the
/// other side's delayed motion (Lawrence's local controller and position
/// channel in one, `C_m = -C_4`, `C_s = -C_1`). Read from text, a gain
/// not named is off ([`OFF`](Self::OFF)).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default, deny_unknown_fields))]
pub struct FourChannelGains {
    /// The master's coupling to the slave's motion: stiffness (N/m).
    pub k_m_npm: f32,
    /// Its damping (N s/m).
    pub b_m_nspm: f32,
    /// The master's own damping, on its velocity alone (N s/m).
    pub b_local_nspm: f32,
    /// The slave's coupling to the master's motion: stiffness (N/m).
    pub k_s_npm: f32,
    /// Its damping (N s/m).
    pub b_s_nspm: f32,
    /// `C_2`: the environment's sensed force fed to the master (the
    /// master's force per the environment's).
    pub c2: f32,
    /// `C_3`: the operator's sensed force fed to the slave.
    pub c3: f32,
    /// `C_5`: the environment's force fed back on the slave itself.
    pub c5: f32,
    /// `C_6`: the operator's force fed back on the master itself.
    pub c6: f32,
}

impl Default for FourChannelGains {
    fn default() -> Self {
        FourChannelGains::OFF
    }
}

impl FourChannelGains {
    /// Every channel off: the start of a law that turns some on.
    pub const OFF: FourChannelGains = FourChannelGains {
        k_m_npm: 0.0,
        b_m_nspm: 0.0,
        b_local_nspm: 0.0,
        k_s_npm: 0.0,
        b_s_nspm: 0.0,
        c2: 0.0,
        c3: 0.0,
        c5: 0.0,
        c6: 0.0,
    };

    /// Each gain by its name (as files, reports, the command line and
    /// Python spell it), in the struct's order, to read or set.
    pub fn named_mut(&mut self) -> [(&'static str, &mut f32); 9] {
        [
            ("k_m_npm", &mut self.k_m_npm),
            ("b_m_nspm", &mut self.b_m_nspm),
            ("b_local_nspm", &mut self.b_local_nspm),
            ("k_s_npm", &mut self.k_s_npm),
            ("b_s_nspm", &mut self.b_s_nspm),
            ("c2", &mut self.c2),
            ("c3", &mut self.c3),
            ("c5", &mut self.c5),
            ("c6", &mut self.c6),
        ]
    }

    /// Each gain by its name, as [`named_mut`](Self::named_mut) gives them.
    pub fn named(&self) -> [(&'static str, f32); 9] {
        let mut copy = *self;
        copy.named_mut().map(|(name, v)| (name, *v))
    }

    /// Set the gain called `name` to `value`; `false` where no gain has
    /// that name.
    pub fn set(&mut self, name: &str, value: f32) -> bool {
        match self.named_mut().into_iter().find(|(n, _)| *n == name) {
            Some((_, gain)) => {
                *gain = value;
                true
            }
            None => false,
        }
    }

    /// Position-position: each side held to the other's motion by the
    /// spring `k_npm` (N/m) and damper `b_nspm` (N s/m), no force sensed.
    pub const fn position_position(k_npm: f32, b_nspm: f32) -> Self {
        FourChannelGains {
            k_m_npm: k_npm,
            b_m_nspm: b_nspm,
            k_s_npm: k_npm,
            b_s_nspm: b_nspm,
            ..FourChannelGains::OFF
        }
    }

    /// Force reflection: the slave held to the master's motion by the
    /// spring `k_npm` (N/m) and damper `b_nspm` (N s/m); the master pushed
    /// by the slave's sensed force scaled by `k_f`, with damping
    /// `b_m_nspm` (N s/m) of its own.
    pub const fn position_force(k_npm: f32, b_nspm: f32, k_f: f32, b_m_nspm: f32) -> Self {
        FourChannelGains {
            b_local_nspm: b_m_nspm,
            k_s_npm: k_npm,
            b_s_nspm: b_nspm,
            c2: k_f,
            ..FourChannelGains::OFF
        }
    }
}

/// Lawrence's four-channel teleoperator across a channel that delays
/// what each side sends by `d` ticks (at most `D`):
///
/// `f_m = k_m (x_m - x_s[k-d]) + b_m (v_m - v_s[k-d]) + b_l v_m
///        - c_2 f_e[k-d] + c_6 f_h`,
/// `f_s = k_s (x_s - x_m[k-d]) + b_s (v_s - v_m[k-d])
///        - c_3 f_h[k-d] + c_5 f_e`,
///
/// with `f_h` the operator's force on the master and `f_e` the
/// environment's on the slave, each along `+x` as the device's force
/// sensor reads it, and forces positive resisting each device's positive
/// motion (the paper's actuator force). Its form, with `Z_i = b_i + k_i
/// T z/(z - 1)` (the velocities being the positions' backward
/// differences):
///
/// `f_m = (Z_m + b_l) v_m - Z_m z^-d v_s - c_2 z^-d f_e + c_6 f_h`,
/// `f_s = -Z_s z^-d v_m + Z_s v_s + c_5 f_e - c_3 z^-d f_h`.
///
/// [`position_position`](Self::position_position) and
/// [`position_force`](Self::position_force) are its two common cases.
#[derive(Clone, Copy, Debug)]
pub struct FourChannel<R = f32, const D: usize = 64> {
    gains: FourChannelGains,
    period_s: f32,
    k_m: R,
    b_m: R,
    b_l: R,
    k_s: R,
    b_s: R,
    c: [R; 4],
    to_slave: Channel<(Motion<R>, R), D>,
    to_master: Channel<(Motion<R>, R), D>,
}

impl<R: Real, const D: usize> FourChannel<R, D> {
    /// The teleoperator of `gains` at `period_s` (s), its channel
    /// `delay_ticks` long each way (at most `D`), both devices at `at`
    /// until their motion arrives. Gains must be finite, the springs and
    /// dampers not negative.
    ///
    /// # Examples
    ///
    /// ```
    /// use twoport_control::teleop::{FourChannel, FourChannelGains};
    /// use twoport_control::Position;
    /// let gains = FourChannelGains {
    ///     k_m_npm: 1_000.0, b_m_nspm: 5.0, b_local_nspm: 0.0,
    ///     k_s_npm: 1_000.0, b_s_nspm: 5.0,
    ///     c2: 1.0, c3: 1.0, c5: 0.0, c6: 0.0,
    /// };
    /// let mut t = FourChannel::<f32, 8>::new(gains, 1e-3, 1, Position::ZERO)?;
    /// // The operator pushes 2 N: the slave pushes with it a tick later.
    /// let rest = (Position::ZERO, 0.0);
    /// let f: Vec<f32> = (0..2).map(|_| t.step(rest, rest, 2.0, 0.0).slave_n).collect();
    /// assert_eq!(f, [0.0, -2.0]);
    /// # Ok::<(), twoport_control::ParamError>(())
    /// ```
    pub fn new(
        gains: FourChannelGains,
        period_s: f32,
        delay_ticks: usize,
        at: Position,
    ) -> Result<Self, ParamError> {
        let period_s = param::positive("T (s)", period_s)?;
        let g = gains;
        let k_m = param::non_negative("k_m (N/m)", g.k_m_npm)?;
        let b_m = param::non_negative("b_m (N s/m)", g.b_m_nspm)?;
        let b_l = param::non_negative("b_local (N s/m)", g.b_local_nspm)?;
        let k_s = param::non_negative("k_s (N/m)", g.k_s_npm)?;
        let b_s = param::non_negative("b_s (N s/m)", g.b_s_nspm)?;
        let c = [
            param::finite("c2", g.c2)?,
            param::finite("c3", g.c3)?,
            param::finite("c5", g.c5)?,
            param::finite("c6", g.c6)?,
        ];
        let channel = || {
            Channel::new(delay_ticks, ((at, R::ZERO), R::ZERO)).ok_or(ParamError {
                name: "delay (ticks)",
                value: delay_ticks as f32,
                problem: "must be at most the channel's length",
            })
        };
        Ok(FourChannel {
            gains,
            period_s,
            k_m: R::of(k_m),
            b_m: R::of(b_m),
            b_l: R::of(b_l),
            k_s: R::of(k_s),
            b_s: R::of(b_s),
            c: c.map(R::of),
            to_slave: channel()?,
            to_master: channel()?,
        })
    }

    /// The symmetric position-position teleoperator: each side held to
    /// the other's delayed motion by the spring `k_npm` (N/m) and damper
    /// `b_nspm` (N s/m), no force sensed.
    ///
    /// # Examples
    ///
    /// ```
    /// use twoport_control::teleop::FourChannel;
    /// use twoport_control::Position;
    /// let mut t = FourChannel::<f32, 8>::position_position(1_000.0, 5.0, 1e-3, 2, Position::ZERO)?;
    /// // The master 1 mm ahead: its pull reaches the slave two ticks on.
    /// let ahead = (Position::from_nm(1_000_000), 0.0);
    /// let at_rest = (Position::ZERO, 0.0);
    /// let f: Vec<f32> = (0..3).map(|_| t.step(ahead, at_rest, 0.0, 0.0).slave_n).collect();
    /// assert_eq!(f, [0.0, 0.0, -1.0]);
    /// assert!(FourChannel::<f32, 8>::position_position(1_000.0, 5.0, 1e-3, 9, Position::ZERO).is_err());
    /// # Ok::<(), twoport_control::ParamError>(())
    /// ```
    pub fn position_position(
        k_npm: f32,
        b_nspm: f32,
        period_s: f32,
        delay_ticks: usize,
        at: Position,
    ) -> Result<Self, ParamError> {
        let gains = FourChannelGains::position_position(k_npm, b_nspm);
        Self::new(gains, period_s, delay_ticks, at)
    }

    /// Force reflection: the slave held to the master's delayed motion by
    /// the spring `k_npm` (N/m) and damper `b_nspm` (N s/m); the master
    /// pushed by the force the slave's sensor reads, scaled by `k_f`, with
    /// damping `b_m_nspm` (N s/m) of its own.
    ///
    /// # Examples
    ///
    /// ```
    /// use twoport_control::teleop::FourChannel;
    /// use twoport_control::Position;
    /// let mut t = FourChannel::<f32, 8>::position_force(1_000.0, 5.0, 0.5, 2.0, 1e-3, 1, Position::ZERO)?;
    /// // The slave against a wall that pushes back 2 N: the master feels
    /// // half of it a tick later, holding it back.
    /// let rest = (Position::ZERO, 0.0);
    /// let f: Vec<f32> = (0..2).map(|_| t.step(rest, rest, 0.0, -2.0).master_n).collect();
    /// assert_eq!(f, [0.0, 1.0]);
    /// # Ok::<(), twoport_control::ParamError>(())
    /// ```
    pub fn position_force(
        k_npm: f32,
        b_nspm: f32,
        k_f: f32,
        b_m_nspm: f32,
        period_s: f32,
        delay_ticks: usize,
        at: Position,
    ) -> Result<Self, ParamError> {
        let gains = FourChannelGains::position_force(
            k_npm,
            b_nspm,
            param::non_negative("k_f (force scale)", k_f)?,
            param::non_negative("b_m (N s/m)", b_m_nspm)?,
        );
        Self::new(gains, period_s, delay_ticks, at)
    }

    /// One tick: each device's position and velocity estimate (m/s), the
    /// operator's force on the master and the environment's on the slave
    /// as their sensors read them (N, along `+x`; zero where a side has no
    /// sensor), in; each device's force out.
    #[inline]
    pub fn step(
        &mut self,
        master: Motion<R>,
        slave: Motion<R>,
        hand_n: R,
        env_n: R,
    ) -> TeleopStep<R> {
        let at_master = self.to_master.pass((slave, env_n));
        let at_slave = self.to_slave.pass((master, hand_n));
        self.forces(master, slave, hand_n, env_n, at_master, at_slave)
    }

    /// The forces this tick given what has arrived, whatever the channel
    /// that carried it: at the master the slave's motion and sensed force
    /// as last received, at the slave the master's. [`step`](Self::step)
    /// is this across the law's own channel of constant delay; a channel
    /// whose delay varies, or that drops packets, hands over what it has.
    #[inline]
    pub fn forces(
        &self,
        master: Motion<R>,
        slave: Motion<R>,
        hand_n: R,
        env_n: R,
        at_master: (Motion<R>, R),
        at_slave: (Motion<R>, R),
    ) -> TeleopStep<R> {
        let ((x_s, v_s), f_e) = at_master;
        let ((x_m, v_m), f_h) = at_slave;
        let [c2, c3, c5, c6] = self.c;
        let spring = |k: R, x: Position, x_r: Position| k * x.nm_from::<R>(x_r) * R::M_PER_NM;
        TeleopStep {
            master_n: spring(self.k_m, master.0, x_s)
                + self.b_m * (master.1 - v_s)
                + self.b_l * master.1
                - c2 * f_e
                + c6 * hand_n,
            slave_n: spring(self.k_s, slave.0, x_m) + self.b_s * (slave.1 - v_m) - c3 * f_h
                + c5 * env_n,
        }
    }

    /// Both devices at `at` and at rest, no force sensed, the channel
    /// emptied.
    pub fn reset(&mut self, at: Position) {
        self.to_slave.reset(((at, R::ZERO), R::ZERO));
        self.to_master.reset(((at, R::ZERO), R::ZERO));
    }

    /// Its gains.
    pub fn gains(&self) -> FourChannelGains {
        self.gains
    }

    /// The channel's delay each way (ticks).
    pub fn delay_ticks(&self) -> usize {
        self.to_slave.delay_ticks()
    }

    /// Its form: see [`FourChannel`].
    pub fn tf(&self) -> TeleopTransfer {
        let t = f64::from(self.period_s);
        let g = self.gains;
        // b + k T z/(z - 1), and its negative.
        let pd = |k: f32, b: f32, sign: f64| {
            let (b, kt) = (f64::from(b), f64::from(k) * t);
            ZTransfer::first_order([sign * (b + kt), -sign * b], -1.0)
        };
        let d = self.delay_ticks() as u32;
        let gain = |c: f32| ZTransfer::gain(f64::from(c));
        let (b_m, b_l) = (f64::from(g.b_m_nspm), f64::from(g.b_local_nspm));
        let kt_m = f64::from(g.k_m_npm) * t;
        let local_m = ZTransfer::first_order([b_m + b_l + kt_m, -(b_m + b_l)], -1.0);
        TeleopTransfer {
            z: [
                [
                    Delayed::now(local_m),
                    Delayed::after(pd(g.k_m_npm, g.b_m_nspm, -1.0), d),
                    Delayed::after(gain(-g.c2), d),
                    Delayed::now(gain(g.c6)),
                ],
                [
                    Delayed::after(pd(g.k_s_npm, g.b_s_nspm, -1.0), d),
                    Delayed::now(pd(g.k_s_npm, g.b_s_nspm, 1.0)),
                    Delayed::now(gain(g.c5)),
                    Delayed::after(gain(-g.c3), d),
                ],
            ],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::FourChannelGains;

    #[test]
    fn each_gain_is_set_by_its_own_name() {
        let mut g = FourChannelGains::OFF;
        for (i, (name, _)) in FourChannelGains::OFF.named().into_iter().enumerate() {
            assert!(g.set(name, i as f32 + 1.0), "{name}");
        }
        let want = FourChannelGains {
            k_m_npm: 1.0,
            b_m_nspm: 2.0,
            b_local_nspm: 3.0,
            k_s_npm: 4.0,
            b_s_nspm: 5.0,
            c2: 6.0,
            c3: 7.0,
            c5: 8.0,
            c6: 9.0,
        };
        assert_eq!(g, want);
        assert!(!g.set("k_m", 1.0));
        assert_eq!(g, want);
    }
}
