use super::CompensatedSum;
use crate::param::{non_negative, positive};
use crate::{ParamError, Real};

/// The safeguards of a passivity controller in admittance causality, in SI
/// units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParallelLimits {
    /// Control period `T` (s).
    pub period_s: f32,
    /// The most conductance the controller may add (m/(N s)): the
    /// velocity it adds per newton of measured force. The added velocity
    /// is a direct feedthrough from the load cell to the position command,
    /// a sampled admittance of its own; [`for_display`](Self::for_display)
    /// caps it at `T / (2 m)`, half the direct feedthrough `T / m` of the
    /// lightest admittance coupling mass `m` the display is run with.
    pub max_conductance_mpns: f32,
    /// Below this force (N) the controller adds nothing: the conductance
    /// it would need grows as `1/f²`, and near zero the reading is
    /// load-cell noise.
    pub min_force_n: f32,
    /// The commanded velocity is clipped to this (m/s), the safety layer's
    /// speed limit, so that the correction cannot trip it.
    pub velocity_limit_mps: f32,
    /// The most energy (J) kept in reserve (see
    /// [`PassivityLimits::max_reserve_j`](super::PassivityLimits::max_reserve_j)).
    pub max_reserve_j: f32,
}

impl ParallelLimits {
    /// Limits for an admittance display at `period_s` (s) whose coupling
    /// mass is at least `coupling_mass_kg` (kg), with the safety layer's
    /// speed limit `velocity_limit_mps` (m/s): the cap at `T / (2 m)`, a
    /// force floor of 0.05 N, a reserve of 0.5 J.
    ///
    /// # Examples
    ///
    /// ```
    /// use twoport_control::passivity::ParallelLimits;
    ///
    /// let l = ParallelLimits::for_display(0.5, 1e-3, 1.0).unwrap();
    /// assert!((l.max_conductance_mpns - 1e-3).abs() < 1e-9);
    /// assert!(ParallelLimits::for_display(0.5, -1e-3, 1.0).is_err());
    /// ```
    pub fn for_display(
        coupling_mass_kg: f32,
        period_s: f32,
        velocity_limit_mps: f32,
    ) -> Result<Self, ParamError> {
        let m = positive("coupling mass (kg)", coupling_mass_kg)?;
        Self {
            period_s,
            max_conductance_mpns: period_s / (2.0 * m),
            min_force_n: 0.05,
            velocity_limit_mps,
            max_reserve_j: 0.5,
        }
        .checked()
    }

    /// These limits if each is a finite number in its range; else which
    /// one is not.
    pub fn checked(self) -> Result<Self, ParamError> {
        positive("passivity.period (s)", self.period_s)?;
        non_negative(
            "passivity.max_conductance (m/(N s))",
            self.max_conductance_mpns,
        )?;
        positive("passivity.min_force (N)", self.min_force_n)?;
        positive("passivity.velocity_limit (m/s)", self.velocity_limit_mps)?;
        non_negative("passivity.max_reserve (J)", self.max_reserve_j)?;
        Ok(self)
    }
}

/// A passivity controller in admittance causality: a variable damper in
/// parallel with the element (Hannaford & Ryu 2002). The element (an
/// admittance coupling with its VE) takes the measured force `f` and puts
/// out the velocity `v` the device is commanded to move at.
///
/// The element's input is sampled and its output is held: the position
/// command moves by `T v(k)` over tick `k`, driven by `f(k)`. So the
/// energy it has taken in is the discrete sum `E(k) = Σ_{j<=k} T f(j) v(j)`,
/// the same sum that makes a discrete admittance passive when its real
/// part is non-negative on the unit circle, the designer's criterion. When
/// `E` falls below zero, the controller adds the velocity `β f` with
/// `β = -E / (T f²)`, which takes the deficit back this tick, within
/// [`ParallelLimits`].
///
/// While the element is passive the output is the input, bit for bit.
///
/// # Examples
///
/// ```
/// use twoport_control::passivity::{ParallelDamper, ParallelLimits};
///
/// let mut pc = ParallelDamper::<f32>::new(ParallelLimits::for_display(0.5, 1e-3, 1.0).unwrap())?;
/// // An element that moves with the force it is given is passive.
/// assert_eq!(pc.step(2.0, 0.01), 0.01);
/// // One that moves against it gives energy out, here more than it took
/// // in: the controller adds velocity along the force.
/// let v = pc.step(2.0, -0.011);
/// assert!(v > -0.011 && pc.conductance_mpns() > 0.0);
/// // The deficit is taken back within the tick: the bank is empty again.
/// assert!(pc.energy_in_j().abs() < 1e-9);
/// # Ok::<(), twoport_control::ParamError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParallelDamper<R = f32> {
    /// Energy taken in (J).
    taken_in_j: CompensatedSum<R>,
    period_s: R,
    max_conductance_mpns: R,
    min_force_n: R,
    velocity_limit_mps: R,
    max_reserve_j: R,
    conductance_mpns: R,
}

impl<R: Real> ParallelDamper<R> {
    /// A controller with these limits, refused (and named) when one is out
    /// of range.
    pub fn new(limits: ParallelLimits) -> Result<Self, ParamError> {
        let l = limits.checked()?;
        Ok(ParallelDamper {
            taken_in_j: CompensatedSum::new(),
            period_s: R::of(l.period_s),
            max_conductance_mpns: R::of(l.max_conductance_mpns),
            min_force_n: R::of(l.min_force_n),
            velocity_limit_mps: R::of(l.velocity_limit_mps),
            max_reserve_j: R::of(l.max_reserve_j),
            conductance_mpns: R::ZERO,
        })
    }

    /// One tick: `force_n` the measured force on the port along `+x` (N),
    /// `velocity_mps` the element's velocity for it (m/s). Returns the
    /// velocity to command.
    #[inline]
    pub fn step(&mut self, force_n: R, velocity_mps: R) -> R {
        let t = self.period_s;
        // What the element alone would take in this tick, on top of what
        // it has banked.
        let e = self.taken_in_j.value() + t * force_n * velocity_mps;
        let active = e < R::ZERO && force_n.abs() >= self.min_force_n;
        let v = if active {
            let beta = (-e / (t * force_n * force_n)).at_most(self.max_conductance_mpns);
            self.conductance_mpns = beta;
            (velocity_mps + beta * force_n).within(self.velocity_limit_mps)
        } else {
            self.conductance_mpns = R::ZERO;
            velocity_mps
        };
        self.taken_in_j.add(t * force_n * v);
        if self.taken_in_j.value() > self.max_reserve_j {
            self.taken_in_j = CompensatedSum::new();
            self.taken_in_j.add(self.max_reserve_j);
        }
        v
    }

    /// Forget everything booked: the element starts again at rest.
    pub fn reset(&mut self) {
        self.taken_in_j = CompensatedSum::new();
        self.conductance_mpns = R::ZERO;
    }

    /// The conductance added in the last tick (m/(N s)); 0 while passive.
    pub fn conductance_mpns(&self) -> R {
        self.conductance_mpns
    }

    /// The energy (J) the controlled element has taken in, counting what
    /// the controller dissipated.
    pub fn energy_in_j(&self) -> R {
        self.taken_in_j.value()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn limits() -> ParallelLimits {
        ParallelLimits::for_display(0.5, 1e-3, 1.0).unwrap()
    }

    /// A negative damper (an active admittance `v = -f / b`) under random
    /// forces: alone it gives energy out every tick; with the controller
    /// the controlled element never shows more than the energy of one
    /// tick's largest exchange given out, when the cap allows the whole
    /// correction. The test can fail: without the controller the energy
    /// falls without bound.
    #[test]
    fn an_active_admittance_is_held_passive() {
        let mut seed = 0x5eed_cafe_u64;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let mut l = limits();
        l.max_conductance_mpns = 1.0;
        let mut pc = ParallelDamper::<f64>::new(l).unwrap();
        let (mut alone, mut lowest) = (0.0f64, 0.0f64);
        for _ in 0..100_000 {
            let f = 20.0 * next();
            let v = -f / 200.0;
            alone += 1e-3 * f * v;
            let out = pc.step(f, v);
            assert!(out.abs() <= 1.0);
            lowest = lowest.min(pc.energy_in_j());
        }
        assert!(alone < -0.5, "alone: {alone} J");
        // The floor lets forces below 0.05 N through uncorrected.
        assert!(lowest >= -1e-3 * 0.05 * 0.05 / 200.0 * 2.0, "{lowest} J");
    }

    /// While the element is passive the output is its input, bit for bit.
    #[test]
    fn a_passive_admittance_passes_through_bit_for_bit() {
        let mut pc = ParallelDamper::<f32>::new(limits()).unwrap();
        for i in 0..10_000 {
            let f = ((i as f32) * 0.37).sin() * 10.0;
            let v = f / 30.0;
            assert_eq!(pc.step(f, v).to_bits(), v.to_bits());
            assert_eq!(pc.conductance_mpns(), 0.0);
        }
    }

    /// Bad limits are refused by name.
    #[test]
    fn bad_limits_are_named() {
        let mut l = limits();
        l.min_force_n = 0.0;
        assert_eq!(
            ParallelDamper::<f32>::new(l).unwrap_err().name,
            "passivity.min_force (N)"
        );
    }
}
