//! The passivity layer on a teleoperator's channel: a time-domain guard
//! for a delay that varies, or packets that drop.

use crate::passivity::{Brake, CompensatedSum, PassivityLimits};
use crate::{ParamError, Position, Real};

/// One side's guard on a channel (Ryu and Artigas's time-domain
/// passivity for a two-port network). It books the energy its device's
/// port has put into the teleoperator and taken out of it, each tick with
/// the force held over it and the displacement during it, as
/// [`EnergyObserver`](crate::passivity::EnergyObserver) does. Energy can
/// leave at one side only after it entered at the other: each side sends
/// what it has put in with its packets, and where what it has taken out
/// passes what the other side had put in when its last packet left, it
/// adds the damping that takes the excess back, within its limits. What
/// arrives late, or not at all, only makes it stricter: the other side's
/// input it knows is older, so smaller.
///
/// While the channel is passive the guard does no arithmetic on the
/// force: the output is the input, bit for bit. Forces are in the servo's
/// sign: positive resists positive motion.
///
/// # Examples
///
/// ```
/// use twoport_control::passivity::PassivityLimits;
/// use twoport_control::teleop::ChannelGuard;
/// use twoport_control::Position;
///
/// let limits = PassivityLimits::for_device(0.1, 1e-3, 10.0)?;
/// let mut g = ChannelGuard::<f32>::new(limits)?;
/// // The teleoperator pushes the device along +x (its force -1 N) while
/// // the other side has put nothing in: the second tick's output is
/// // damped.
/// assert_eq!(g.step(Position::ZERO, 0.0, -1.0, 0.0), -1.0);
/// let f = g.step(Position::from_nm(10_000), 0.01, -1.0, 0.0);
/// assert!(f > -1.0 && g.damping_nspm() > 0.0);
/// assert!((g.energy_out_j() - 1e-5).abs() < 1e-9);
/// # Ok::<(), twoport_control::ParamError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChannelGuard<R = f32> {
    /// Energy the port has put in (nJ: newtons times nanometres).
    in_nj: CompensatedSum<R>,
    /// Energy it has taken out (nJ).
    out_nj: CompensatedSum<R>,
    start: Position,
    held_n: R,
    brake: Brake<R>,
    force_limit_n: R,
    damping_nspm: R,
}

impl<R: Real> ChannelGuard<R> {
    /// A guard with these limits (the device's damping credit is not used:
    /// the channel's energy is booked at the port as it is), refused and
    /// named when one is out of range.
    pub fn new(limits: PassivityLimits) -> Result<Self, ParamError> {
        let l = limits.checked()?;
        Ok(ChannelGuard {
            in_nj: CompensatedSum::new(),
            out_nj: CompensatedSum::new(),
            start: Position::ZERO,
            held_n: R::ZERO,
            brake: Brake::new(&l),
            force_limit_n: R::of(l.force_limit_n),
            damping_nspm: R::ZERO,
        })
    }

    /// One tick: `x` the port's position now, `v` its velocity estimate
    /// (m/s), `force_n` the teleoperator's force on it for the coming tick
    /// (N), and `other_in_j` the energy the other side had put in when
    /// its last packet to arrive left (J). Returns the force to hold,
    /// within the force limit.
    #[inline]
    pub fn step(&mut self, x: Position, v: R, force_n: R, other_in_j: R) -> R {
        let moved_nm: R = x.nm_from(self.start);
        let e = moved_nm * self.held_n;
        if e > R::ZERO {
            self.in_nj.add(e);
        } else {
            self.out_nj.add(-e);
        }
        self.start = x;
        // What the port holds against what it may give out: below zero,
        // it has given out more than the other side had put in.
        let margin_nj = other_in_j * R::NM_PER_M - self.out_nj.value();
        let in_deficit = margin_nj < R::ZERO;
        // Within what came in (or a NaN, which leaves the force to the
        // safety layer downstream).
        let alpha = if in_deficit {
            self.brake.damping(margin_nj, v)
        } else {
            R::ZERO
        };
        self.damping_nspm = alpha;
        if alpha == R::ZERO {
            self.held_n = force_n;
            return force_n;
        }
        let f = (force_n + alpha * v).within(self.force_limit_n);
        self.held_n = f;
        f
    }

    /// The energy the port has put into the teleoperator (J): what this
    /// side sends the other.
    pub fn energy_in_j(&self) -> R {
        self.in_nj.value() * R::M_PER_NM
    }

    /// The energy the port has taken out (J).
    pub fn energy_out_j(&self) -> R {
        self.out_nj.value() * R::M_PER_NM
    }

    /// The damping added in the last tick (N s/m); 0 while passive.
    pub fn damping_nspm(&self) -> R {
        self.damping_nspm
    }

    /// Forget everything booked: the port starts again at rest at `x`.
    pub fn reset(&mut self, x: Position) {
        self.in_nj = CompensatedSum::new();
        self.out_nj = CompensatedSum::new();
        self.start = x;
        self.held_n = R::ZERO;
        self.damping_nspm = R::ZERO;
    }
}
