use super::{Brake, EnergyObserver};
use crate::param::{non_negative, positive};
use crate::{ParamError, Position, Real};

/// The safeguards of a passivity controller, in SI units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PassivityLimits {
    /// Control period `T` (s).
    pub period_s: f32,
    /// The most damping the controller may add (N s/m). The controller is
    /// itself a sampled damper on a backward-difference velocity. On a free
    /// mass `m` that loop is unstable from `2m/T` on, and it rings (complex
    /// poles) from `(3 - 2√2) 2m/T ≈ 0.34 m/T` on. A ringing damper
    /// reverses the motion within a few ticks, so the velocity it was
    /// sized by no longer predicts the displacement, and it gives energy
    /// out where it meant to take it back. [`for_device`](Self::for_device)
    /// takes the ringing bound.
    pub max_damping_nspm: f32,
    /// Below this speed (m/s) the controller adds nothing: the damping it
    /// would need grows as `1/v²`, and at a few encoder counts per tick the
    /// velocity estimate is quantisation.
    pub min_velocity_mps: f32,
    /// The actuator's force limit (N): a corrected force is clipped to it.
    pub force_limit_n: f32,
    /// The most energy (J) the observer keeps in reserve. Dissipation
    /// banked beyond it is forgotten, so that a long passive stretch (a
    /// hand damping the handle for minutes) does not let a later burst of
    /// active behaviour run unchecked until the bank is spent. It must
    /// hold what the element may store and rightly give back (a VE body's
    /// kinetic energy, the coupling spring's stretch), or the controller
    /// would brake a VE that returns its own energy.
    pub max_reserve_j: f32,
    /// The device's own viscous damping at the port (N s/m), credited to
    /// the element ([`EnergyObserver::with_device_damping`]). A sampled
    /// coupling on a device without it is never passive at the tick's
    /// half-frequency (Colgate's `b > KT/2 + |B|` with `b = 0`), so with 0
    /// here the controller acts on any loop that rings there. Give a lower
    /// bound of the device's damping: more than it has would credit
    /// dissipation that does not happen.
    pub device_damping_nspm: f32,
}

/// The damping, as a fraction of `2m/T`, from which a sampled damper on a
/// free mass rings: the poles of `z² + (c - 1) z + c` (with `c = αT/2m`)
/// turn complex at `c = 3 - 2√2`.
const NON_RINGING: f32 = 0.171_572_88;

impl PassivityLimits {
    /// Limits for a device whose moving mass at the port is `mass_kg`
    /// (kg), run at `period_s` (s) with an actuator limit `force_limit_n`
    /// (N): the damping cap at `0.34 m/T`, where the sampled damper alone
    /// starts to ring; a
    /// velocity floor of 1 mm/s; a reserve of 0.5 J, what a 1 kg VE body
    /// holds at 1 m/s (the safety layer's default speed limit); no device
    /// damping credited.
    ///
    /// # Examples
    ///
    /// ```
    /// use twoport_control::passivity::PassivityLimits;
    ///
    /// // A 0.7 kg port at 1 kHz with a 200 N actuator.
    /// let l = PassivityLimits::for_device(0.7, 1e-3, 200.0).unwrap();
    /// assert!((l.max_damping_nspm - 240.2).abs() < 0.1);
    /// assert!(PassivityLimits::for_device(0.0, 1e-3, 200.0).is_err());
    /// ```
    pub fn for_device(mass_kg: f32, period_s: f32, force_limit_n: f32) -> Result<Self, ParamError> {
        let m = positive("mass (kg)", mass_kg)?;
        // `checked` names a bad period before the cap it spoils.
        Self {
            period_s,
            max_damping_nspm: NON_RINGING * 2.0 * m / period_s,
            min_velocity_mps: 1e-3,
            force_limit_n,
            max_reserve_j: 0.5,
            device_damping_nspm: 0.0,
        }
        .checked()
    }

    /// These limits if each is a finite number in its range; else which
    /// one is not.
    pub fn checked(self) -> Result<Self, ParamError> {
        positive("passivity.period (s)", self.period_s)?;
        non_negative("passivity.max_damping (N s/m)", self.max_damping_nspm)?;
        positive("passivity.min_velocity (m/s)", self.min_velocity_mps)?;
        positive("passivity.force_limit (N)", self.force_limit_n)?;
        non_negative("passivity.max_reserve (J)", self.max_reserve_j)?;
        non_negative("passivity.device_damping (N s/m)", self.device_damping_nspm)?;
        Ok(self)
    }
}

/// A passivity controller in impedance causality: a variable damper in
/// series with the element (Hannaford & Ryu 2002). The element (a VE with
/// its coupling) takes the port's motion and puts out a force; when the
/// [`EnergyObserver`] shows that it has given out more energy than it took
/// in, the controller adds the damping `α = -E / (T v²)` that takes that
/// energy back over the coming tick, within [`PassivityLimits`].
///
/// While the element is passive the controller does no arithmetic on its
/// force: the output is the input, bit for bit.
///
/// Forces are in the servo's sign (the paper's `f_a`): positive resists
/// positive motion.
///
/// # Examples
///
/// ```
/// use twoport_control::passivity::{PassivityLimits, SeriesDamper};
/// use twoport_control::Position;
///
/// let limits = PassivityLimits::for_device(0.7, 1e-3, 200.0).unwrap();
/// let mut pc = SeriesDamper::<f32>::new(limits).unwrap();
/// // A damper-like element is passive: nothing is added.
/// let f = pc.step(Position::from_nm(0), 0.0, 0.0);
/// assert_eq!(f, 0.0);
/// let f = pc.step(Position::from_nm(10_000), 0.01, 0.5);
/// assert_eq!((f, pc.damping_nspm()), (0.5, 0.0));
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SeriesDamper<R = f32> {
    observer: EnergyObserver<R>,
    brake: Brake<R>,
    force_limit_n: R,
    max_reserve_nj: R,
    damping_nspm: R,
}

impl<R: Real> SeriesDamper<R> {
    /// A controller with these limits, refused (and named) when one is out
    /// of range.
    pub fn new(limits: PassivityLimits) -> Result<Self, ParamError> {
        let l = limits.checked()?;
        Ok(SeriesDamper {
            observer: EnergyObserver::with_device_damping(l.device_damping_nspm, l.period_s),
            brake: Brake::new(&l),
            force_limit_n: R::of(l.force_limit_n),
            max_reserve_nj: R::of(l.max_reserve_j) * R::NM_PER_M,
            damping_nspm: R::ZERO,
        })
    }

    /// One tick: `x` the port's position now, `v` its velocity estimate
    /// (m/s), `force_n` the element's force for the coming tick (N).
    /// Returns the force to hold, within the force limit.
    #[inline]
    pub fn step(&mut self, x: Position, v: R, force_n: R) -> R {
        let f = self.correct(x, v, force_n);
        if f == force_n {
            return f;
        }
        // (On the servo's path the safety layer limits the force and
        // books what it let through.)
        let f = f.within(self.force_limit_n);
        self.observer.hold(f);
        f
    }

    /// [`step`](Self::step) without the force limit, for a caller whose
    /// safety layer clips the force and books what it let through with
    /// [`hold`](Self::hold) (the servo's tick).
    #[inline(always)]
    pub(crate) fn correct(&mut self, x: Position, v: R, force_n: R) -> R {
        self.observer.book(x, force_n);
        let e = self.observer.energy_in_nj();
        if e > self.max_reserve_nj {
            self.observer.set_energy_nj(self.max_reserve_nj);
        }
        // Passive (or a NaN energy, which leaves the force alone: the
        // safety layer downstream refuses a non-finite force on its own).
        let in_deficit = e < R::ZERO;
        if !in_deficit {
            self.damping_nspm = R::ZERO;
            return force_n;
        }
        let alpha = self.brake.damping(e, v);
        self.damping_nspm = alpha;
        force_n + alpha * v
    }

    /// Book `force_n` (N, the servo's sign) as the force held over
    /// the tick that [`step`](Self::step) started, in place of what it
    /// returned: what a safety layer downstream finally let through.
    #[inline]
    pub fn hold(&mut self, force_n: R) {
        self.observer.hold(force_n);
    }

    /// Forget everything booked: the element starts again at rest, the
    /// port at `x`.
    pub fn reset(&mut self, x: Position) {
        self.observer.restart(x);
        self.damping_nspm = R::ZERO;
    }

    /// The damping added in the last tick (N s/m); 0 while passive.
    pub fn damping_nspm(&self) -> R {
        self.damping_nspm
    }

    /// The energy (J) the controlled element has taken in, counting what
    /// the controller dissipated.
    pub fn energy_in_j(&self) -> R {
        self.observer.energy_in_j()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The cap is where the sampled damper alone on a free mass stops
    /// settling monotonically: at the cap the mass comes to rest without
    /// a tick's displacement changing sign; a little above, it rings
    /// through zero; past `2m/T` the mass runs away.
    #[test]
    fn the_damping_cap_is_where_the_sampled_damper_starts_to_ring() {
        let (m, t) = (0.7f64, 1e-3f64);
        let cap = PassivityLimits::for_device(m as f32, t as f32, 200.0)
            .unwrap()
            .max_damping_nspm as f64;
        // Returns the final speed and whether the velocity changed sign.
        let run = |b: f64| {
            let (mut x, mut v, mut last) = (0.0f64, 0.01f64, -0.01 * t);
            let mut reversed = false;
            for _ in 0..5000 {
                let f = -b * (x - last) / t;
                last = x;
                x += v * t + 0.5 * f / m * t * t;
                v += f / m * t;
                // What the controller sees: the tick's displacement.
                reversed |= x < last;
            }
            (v.abs(), reversed)
        };
        let (rest, reversed) = run(cap);
        assert!(
            rest < 1e-12 && !reversed,
            "at the cap: {rest} m/s, {reversed}"
        );
        let (rest, reversed) = run(1.1 * cap);
        assert!(
            rest < 1e-12 && reversed,
            "above the cap: {rest}, {reversed}"
        );
        let (away, _) = run(2.1 * m / t);
        assert!(away > 1.0, "past the bound: {away}");
    }

    /// Steps a mass `m` under a sampled spring `K` (which alone pumps
    /// energy in, as the observer's tests show) with the controller
    /// between them; returns the swing early and late, the lowest energy
    /// the controlled element showed, and its largest single-tick exchange.
    fn spring_on_mass(m: f64, k: f64, v0: f64, ticks: usize, on: bool) -> (f64, f64, f64, f64) {
        let t = 1e-3f64;
        let limits = PassivityLimits::for_device(m as f32, t as f32, 200.0).unwrap();
        let mut pc = SeriesDamper::<f64>::new(limits).unwrap();
        let mut obs = EnergyObserver::<f64>::new();
        // The spring starts relaxed, so it holds no energy of its own; the
        // mass brings it in.
        let (mut x, mut v) = (0.0f64, v0);
        let mut last = Position::ZERO;
        let (mut early, mut late, mut lowest, mut largest) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        let mut held = 0.0f64;
        for i in 0..ticks {
            let Some(p) = Position::from_m_f64(x).filter(|_| x.abs() < 1.0) else {
                // Run away: a metre past the start.
                return (early, f64::INFINITY, lowest, largest);
            };
            let v_est = (p.nm() - last.nm()) as f64 * 1e-9 / t;
            largest = largest.max((held * (p.nm() - last.nm()) as f64 * 1e-9).abs());
            last = p;
            // The spring resists its stretch; the mass feels minus that.
            let f_ve = k * p.nm() as f64 * 1e-9;
            let f = if on { pc.step(p, v_est, f_ve) } else { f_ve };
            lowest = lowest.min(obs.update(p, f));
            held = f;
            let f = -f;
            if i < ticks / 10 {
                early = early.max(x.abs());
            } else if i >= ticks - ticks / 10 {
                late = late.max(x.abs());
            }
            x += v * t + 0.5 * f / m * t * t;
            v += f / m * t;
        }
        (early, late, lowest, largest)
    }

    /// Over random masses, springs and starting stretches, the loop the
    /// spring alone drives unstable stays bounded with the controller, and
    /// the controlled element never shows more net energy given out than
    /// its largest single-tick exchange (the controller acts on the tick
    /// after the observer sees a deficit; over these runs the dip is at
    /// most 0.7 of it). The swing stays as it started: the controller
    /// takes back what the hold injects, and the spring feels lossless.
    /// Without it the same runs diverge: the test can fail.
    #[test]
    fn a_zoh_spring_stays_passive_and_bounded_under_the_controller() {
        let mut seed = 0x1234_5678_9abc_def1u64;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for case in 0..40 {
            let m = 0.2 + 2.0 * next();
            // K T^2 / 2m from 1e-4 to 1e-2: the spring alone grows 3x to
            // 10^40x in 20 s.
            let k = 2.0 * m / 1e-6 * 10f64.powf(-4.0 + 2.0 * next());
            let v0 = 1e-3 + 0.1 * next();
            let (early, late, lowest, largest) = spring_on_mass(m, k, v0, 20_000, true);
            assert!(
                late <= early * 1.01,
                "case {case}: m {m}, K {k}: {early} -> {late} m"
            );
            assert!(
                lowest >= -largest,
                "case {case}: {lowest} J given out, one tick moves {largest} J"
            );
            let (early, late, ..) = spring_on_mass(m, k, v0, 20_000, false);
            assert!(
                late > 2.0 * early,
                "case {case}: the spring alone should diverge"
            );
        }
    }

    /// While the element is passive, the controller's output is its input,
    /// bit for bit: a damper element over a random walk.
    #[test]
    fn a_passive_element_passes_through_bit_for_bit() {
        let limits = PassivityLimits::for_device(0.7, 1e-3, 200.0).unwrap();
        let mut pc = SeriesDamper::<f32>::new(limits).unwrap();
        let mut seed = 0x0bad_5eed_u64;
        let (mut nm, mut last) = (0i32, 0i32);
        for _ in 0..100_000 {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            nm += (seed % 2001) as i32 - 1000;
            let v = (nm - last) as f32 * 1e-9 / 1e-3;
            last = nm;
            let f = 30.0 * v;
            let out = pc.step(Position::from_nm(nm), v, f);
            assert_eq!(out.to_bits(), f.to_bits());
            assert_eq!(pc.damping_nspm(), 0.0);
        }
    }

    /// Bad limits are refused by name.
    #[test]
    fn bad_limits_are_named() {
        let mut l = PassivityLimits::for_device(0.7, 1e-3, 200.0).unwrap();
        l.min_velocity_mps = f32::NAN;
        let e = SeriesDamper::<f32>::new(l).unwrap_err();
        assert_eq!(e.name, "passivity.min_velocity (m/s)");
    }
}
