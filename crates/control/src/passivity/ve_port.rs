use super::{CompensatedSum, ParallelLimits};
use crate::ve::{Causality, Port, VeOutput, VeTransfer, VirtualEnvironment};
use crate::{Integrator, ParamError, Position, Real};

/// A passivity controller at the VE's port: a variable damper in parallel
/// with a VE that takes the coupling's force and answers with a velocity
/// (admittance causality, Hannaford & Ryu 2002).
///
/// An explicitly integrated VE can be unstable with its coupling on its
/// own, whatever the device does: a controller at the device's port sees
/// the energy only once it reaches the device, and damps the wrong motion.
/// This one books what the VE took in, `E(k) = Σ T f(j) v(j)` (the sum
/// whose sign the designer's criterion keeps for a passive VE), and while
/// `E` is negative adds the velocity `β f` with `β = -E / (T f²)`, sized by
/// last tick's force and within [`ParallelLimits`] (the cap applies to
/// `β`; the velocity limit to what it adds).
///
/// The damper sits inside the coupling's algebraic loop: with the port's
/// line `f = f0 - z v` and `v = v_VE + β f`, the VE meets the port
/// `f0 / (1 + zβ)`, `z / (1 + zβ)`, so the tick stays solved exactly. The
/// VE point the coupling holds moves with the whole velocity.
///
/// While the VE is passive the wrapper does no arithmetic on the VE's
/// answer: the output is the VE's, bit for bit.
///
/// # Examples
///
/// ```
/// use twoport_control::passivity::{ParallelLimits, PassiveVe};
/// use twoport_control::ve::{ExplicitCursor, Port, VirtualEnvironment};
/// use twoport_control::Position;
///
/// let cursor = ExplicitCursor::<f32>::new_in(0.05, 1e-3, Position::ZERO)?;
/// let limits = ParallelLimits::for_display(0.05, 1e-3, 1.0)?;
/// let mut ve = PassiveVe::new(cursor, limits)?;
/// let out = ve.step(Port { f0_n: 1.0, z_nspm: 100.0 });
/// assert_eq!(out.force_n, 1.0);
/// assert_eq!(ve.conductance_mpns(), 0.0);
/// # Ok::<(), twoport_control::ParamError>(())
/// ```
#[derive(Clone, Copy, Debug)]
pub struct PassiveVe<V, R = f32> {
    ve: V,
    taken_in_j: CompensatedSum<R>,
    /// What the damper moved the VE point, beyond the VE's own motion.
    added: Integrator<R>,
    dissipated_j: CompensatedSum<R>,
    period_s: R,
    max_conductance_mpns: R,
    min_force_n: R,
    velocity_limit_mps: R,
    max_reserve_j: R,
    last_force_n: R,
    conductance_mpns: R,
}

impl<V: VirtualEnvironment<R>, R: Real> PassiveVe<V, R> {
    /// `ve` with the controller, refused (and named) when a limit is out
    /// of range.
    pub fn new(ve: V, limits: ParallelLimits) -> Result<Self, ParamError> {
        let l = limits.checked()?;
        Ok(PassiveVe {
            ve,
            taken_in_j: CompensatedSum::new(),
            added: Integrator::new_in(l.period_s, Position::ZERO),
            dissipated_j: CompensatedSum::new(),
            period_s: R::of(l.period_s),
            max_conductance_mpns: R::of(l.max_conductance_mpns),
            min_force_n: R::of(l.min_force_n),
            velocity_limit_mps: R::of(l.velocity_limit_mps),
            max_reserve_j: R::of(l.max_reserve_j),
            last_force_n: R::ZERO,
            conductance_mpns: R::ZERO,
        })
    }

    /// The VE inside.
    pub fn inner(&self) -> &V {
        &self.ve
    }

    /// The VE inside, to change it between ticks.
    pub fn inner_mut(&mut self) -> &mut V {
        &mut self.ve
    }

    /// The conductance added this tick (m/(N s)); 0 while passive.
    pub fn conductance_mpns(&self) -> R {
        self.conductance_mpns
    }

    /// The energy (J) the controlled VE has taken in, counting what the
    /// controller dissipated.
    pub fn energy_in_j(&self) -> R {
        self.taken_in_j.value()
    }

    /// The energy (J) the controller has dissipated.
    pub fn dissipated_j(&self) -> R {
        self.dissipated_j.value()
    }

    /// The conductance for this tick, from what was booked up to the last.
    #[inline(always)]
    fn conductance(&self) -> R {
        let e = self.taken_in_j.value();
        let f = self.last_force_n;
        let f2 = f * f;
        let in_deficit = e < R::ZERO;
        let strong_enough = f2 >= self.min_force_n * self.min_force_n;
        if !(in_deficit && strong_enough) {
            return R::ZERO;
        }
        let wanted = -e / (self.period_s * f2);
        if wanted < self.max_conductance_mpns {
            wanted
        } else {
            self.max_conductance_mpns
        }
    }
}

impl<V: VirtualEnvironment<R>, R: Real> VirtualEnvironment<R> for PassiveVe<V, R> {
    fn causality(&self) -> Causality {
        self.ve.causality()
    }

    // Always inlined: once per tick, inside the coupling's step, where a
    // call would spill the tick's registers (the M4F count).
    #[inline(always)]
    fn step(&mut self, port: Port<R>) -> VeOutput<R> {
        let beta = self.conductance();
        self.conductance_mpns = beta;
        let out = if beta == R::ZERO {
            self.ve.step(port)
        } else {
            let scale = R::ONE / (R::ONE + port.z_nspm * beta);
            let inner = self.ve.step(Port {
                f0_n: port.f0_n * scale,
                z_nspm: port.z_nspm * scale,
            });
            let lim = self.velocity_limit_mps;
            let extra = beta * inner.force_n;
            let extra = if extra > lim {
                lim
            } else if extra < -lim {
                -lim
            } else {
                extra
            };
            if extra.is_finite() {
                self.added.step(extra);
                self.dissipated_j.add(self.period_s * inner.force_n * extra);
            }
            port.at(inner.velocity_mps + extra)
        };
        if out.force_n.is_finite() && out.velocity_mps.is_finite() {
            self.taken_in_j
                .add(self.period_s * out.force_n * out.velocity_mps);
            if self.taken_in_j.value() > self.max_reserve_j {
                self.taken_in_j = CompensatedSum::new();
                self.taken_in_j.add(self.max_reserve_j);
            }
            self.last_force_n = out.force_n;
        }
        out
    }

    fn reset(&mut self, x: Position) {
        self.ve.reset(x);
        self.taken_in_j = CompensatedSum::new();
        self.added.reset(Position::ZERO);
        self.last_force_n = R::ZERO;
        self.conductance_mpns = R::ZERO;
    }

    fn position(&self) -> Position {
        self.ve.position() + self.added.position().nm()
    }

    fn offset_m(&self, from: Position) -> R {
        self.ve.offset_m(from) + self.added.offset_m(Position::ZERO)
    }

    /// The VE's own form: the controller is off while the VE is passive.
    fn tf(&self) -> VeTransfer {
        self.ve.tf()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::coupling::ImpedanceCoupling;
    use crate::ve::{CursorMass, ExplicitCursor};

    const T: f32 = 1e-3;

    /// A coupling holding a device still at 1 mm against a light explicit
    /// cursor: alone the pair rings up (the explicit cursor is not
    /// passive); with the controller it settles. The first swing leaves a
    /// deficit the capped damper cannot take back from so small a force,
    /// but once the controller is on the deficit stops growing.
    #[test]
    fn an_explicit_cursor_on_a_stiff_coupling_settles_under_the_controller() {
        let run = |on: bool| {
            let mut c = ImpedanceCoupling::<f32>::new_in(51_000.0, 90.0, T).unwrap();
            let cursor = ExplicitCursor::<f32>::new_in(0.03, T, Position::ZERO).unwrap();
            let limits = ParallelLimits::for_display(0.03, T, 10.0).unwrap();
            let mut ve = PassiveVe::new(cursor, limits).unwrap();
            let x = Position::from_nm(1_000_000);
            let (mut late, mut engaged) = (0.0f32, 0.0f32);
            for k in 0..5000 {
                let f = if on {
                    c.step(x, 0.0, &mut ve).force_n
                } else {
                    c.step(x, 0.0, ve.inner_mut()).force_n
                };
                if !f.is_finite() || f.abs() > 1e4 {
                    return (f32::INFINITY, 0.0);
                }
                if k >= 4000 {
                    late = late.max((f - 0.0).abs());
                }
                if k == 500 {
                    engaged = ve.energy_in_j();
                }
            }
            (late, ve.energy_in_j() - engaged)
        };
        let (late_off, _) = run(false);
        let (late_on, fell) = run(true);
        assert!(late_off > 100.0, "alone: {late_off} N");
        assert!(late_on < 1.0, "with the controller: {late_on} N");
        assert!(fell > -5e-3, "the deficit kept growing: {fell} J");
    }

    /// While the VE is passive the wrapper changes no bit.
    #[test]
    fn a_passive_ve_passes_through_bit_for_bit() {
        let inner = CursorMass::<f32>::new_in(0.25, T, Position::ZERO).unwrap();
        let limits = ParallelLimits::for_display(0.25, T, 1.0).unwrap();
        let mut a = inner;
        let mut b = PassiveVe::new(inner, limits).unwrap();
        for k in 0..20_000 {
            let port = Port {
                f0_n: ((k as f32) * 0.01).sin() * 5.0,
                z_nspm: 141.0,
            };
            let (oa, ob) = (a.step(port), b.step(port));
            assert_eq!(oa.velocity_mps.to_bits(), ob.velocity_mps.to_bits());
            assert_eq!(oa.force_n.to_bits(), ob.force_n.to_bits());
            assert_eq!(a.position(), b.position());
            assert_eq!(b.conductance_mpns(), 0.0);
        }
    }
}
