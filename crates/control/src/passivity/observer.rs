use super::CompensatedSum;
use crate::{Position, Real};

/// The energy (J) an element has taken in at one port, booked with the
/// force it held over each tick and the displacement during that tick.
///
/// The element holds the force `f(j)` on the port from tick `j` to tick
/// `j + 1`, in the servo's sign (the paper's `f_a`): positive resists
/// positive motion, that is pushes along `-x`. The port moves by
/// `x(j+1) - x(j)` meanwhile. The energy the element has taken in by tick
/// `k` is `E(k) = Σ_{j<k} f(j) (x(j+1) - x(j))`. An element that starts
/// at rest is passive when `E(k) >= 0` at every `k`: it has never given
/// out more than it took in.
///
/// # Examples
///
/// ```
/// use twoport_control::passivity::EnergyObserver;
/// use twoport_control::Position;
///
/// // A damper of 10 N s/m resisting a port moving at 1 mm/s (1 µm per
/// // 1 ms tick) takes in energy.
/// let mut obs = EnergyObserver::<f32>::new();
/// for k in 0..1000 {
///     let x = Position::from_nm(1000 * k);
///     obs.update(x, 10.0 * 1e-3);
/// }
/// // 999 ticks of 0.01 N over 1 µm.
/// assert!((obs.energy_in_j() - 999.0 * 1e-8).abs() < 1e-11);
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EnergyObserver<R = f32> {
    /// Energy taken in (nJ: newtons times nanometres).
    taken_in_nj: CompensatedSum<R>,
    /// The port's position at the start of the tick now being held (the
    /// origin, or where [`restart`](Self::restart) put it, before the
    /// first: nothing is held then, so nothing is booked).
    start: Position,
    /// The force held over that tick (N).
    held_n: R,
    /// The device's own damping `b` over `T`, in N per nm (see
    /// [`with_device_damping`](Self::with_device_damping)).
    credit_n_per_nm: R,
}

impl<R: Real> EnergyObserver<R> {
    /// An observer that has booked nothing.
    pub const fn new() -> Self {
        EnergyObserver {
            taken_in_nj: CompensatedSum::new(),
            start: Position::ZERO,
            held_n: R::ZERO,
            credit_n_per_nm: R::ZERO,
        }
    }

    /// An observer whose port lies outside the device's own viscous
    /// damping `b_nspm` (N s/m) at period `period_s` (s): the element it
    /// watches is the sampled law with that damper beside it, which is
    /// passive when Colgate's `b > KT/2 + |B|` holds for a wall of
    /// stiffness `K` and damping `B`. The damper's dissipation over a tick
    /// is credited as `b Δx² / T`, a lower bound on `∫ b v² dt` over the
    /// tick (Cauchy-Schwarz), so the credit never exceeds what the damper
    /// took.
    pub fn with_device_damping(b_nspm: f32, period_s: f32) -> Self {
        let mut o = Self::new();
        o.credit_n_per_nm = R::of(b_nspm / period_s) * R::M_PER_NM;
        o
    }

    /// Book the tick that ends now and start the next one: `x` is the
    /// port's position measured now, `force_n` the force (N) the element
    /// will hold from now until the next tick. Returns
    /// [`energy_in_j`](Self::energy_in_j).
    #[inline]
    pub fn update(&mut self, x: Position, force_n: R) -> R {
        self.book(x, force_n);
        self.energy_in_j()
    }

    /// [`update`](Self::update) without the conversion to joules.
    #[inline(always)]
    pub(crate) fn book(&mut self, x: Position, force_n: R) {
        let moved_nm: R = x.nm_from(self.start);
        self.taken_in_nj
            .add(moved_nm * (self.credit_n_per_nm * moved_nm + self.held_n));
        self.start = x;
        self.held_n = force_n;
    }

    /// The energy taken in so far, in nJ (N nm).
    #[inline(always)]
    pub(crate) fn energy_in_nj(&self) -> R {
        self.taken_in_nj.value()
    }

    /// Change the force held over the tick that starts now (N), after an
    /// [`update`](Self::update) in the same tick: a passivity controller
    /// books the force it finally applied.
    #[inline]
    pub fn hold(&mut self, force_n: R) {
        self.held_n = force_n;
    }

    /// The energy (J) the element has taken in so far.
    #[inline]
    pub fn energy_in_j(&self) -> R {
        self.taken_in_nj.value() * R::M_PER_NM
    }

    /// Forget everything booked (the damping credit stays): the element
    /// starts again at rest, the port at `x`.
    pub fn restart(&mut self, x: Position) {
        self.taken_in_nj = CompensatedSum::new();
        self.start = x;
        self.held_n = R::ZERO;
    }

    /// Set the energy booked so far to `energy_j` (J): a reserve cap or a
    /// reset. The tick being held is still booked when it ends.
    pub fn set_energy_j(&mut self, energy_j: R) {
        self.set_energy_nj(energy_j * R::NM_PER_M);
    }

    /// [`set_energy_j`](Self::set_energy_j) in nJ.
    pub(crate) fn set_energy_nj(&mut self, energy_nj: R) {
        self.taken_in_nj = CompensatedSum::new();
        self.taken_in_nj.add(energy_nj);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::vec::Vec;

    /// A unit mass on a sampled spring `f = K x` (resisting) held over each 1 ms tick,
    /// integrated exactly between ticks. The ZOH spring pumps energy in:
    /// the oscillation grows. The observer sees the spring give out energy
    /// (its taken-in energy falls below minus its initial store), and what
    /// it books equals the mass's energy change by the work-energy theorem,
    /// an independent check. The naive pairing, `f(k)` with the backward
    /// difference of tick `k`, stays above the spring's initial store
    /// throughout: it cannot see the divergence.
    #[test]
    fn sees_a_zoh_spring_pump_energy_that_the_naive_pairing_misses() {
        // K T^2 / 2m = 1.6e-4: the sampled loop's poles sit at
        // |z|^2 = 1.00016, so the swing grows about fivefold in 20 s.
        let (m, k, t) = (1.0f64, 320.0f64, 1e-3f64);
        let (mut x, mut v) = (1e-3f64, 0.0f64);
        let stored0 = 0.5 * k * x * x;
        let mut obs = EnergyObserver::<f64>::new();
        let (mut naive, mut naive_min, mut seen_min) = (0.0f64, 0.0f64, 0.0f64);
        let mut last_nm: Option<i32> = None;
        // The observer sees positions rounded to 1 nm; the mass moves
        // exactly. The work-energy check allows what that rounding can
        // move: half a nanometre at each end of each tick.
        let mut rounding_j = 0.0f64;
        let mut amplitude = Vec::new();
        for _ in 0..20_000 {
            let p = Position::from_m_f64(x).expect("in range");
            let xq = p.nm() as f64 * 1e-9;
            let f = -k * xq;
            let e = obs.update(p, -f);
            if let Some(l) = last_nm {
                naive -= f * (p.nm() - l) as f64 * 1e-9;
            }
            last_nm = Some(p.nm());
            naive_min = naive_min.min(naive);
            seen_min = seen_min.min(e);
            // The mass's kinetic energy is the work the spring did on it:
            // minus what the spring took in.
            let kinetic = 0.5 * m * v * v;
            assert!(
                (kinetic + e).abs() <= rounding_j + 1e-12,
                "{kinetic} J vs {e} J (rounding {rounding_j} J)"
            );
            rounding_j += f.abs() * 1e-9;
            amplitude.push(xq.abs());
            // Exact motion of the mass under the held force.
            x += v * t + 0.5 * f / m * t * t;
            v += f / m * t;
        }
        let early = amplitude[..1000].iter().cloned().fold(0.0, f64::max);
        let late = amplitude[19_000..].iter().cloned().fold(0.0, f64::max);
        assert!(late > 3.0 * early, "the loop diverges: {early} -> {late} m");
        assert!(
            seen_min < -10.0 * stored0,
            "observer: at most {} J given out, {stored0} J stored at the start",
            -seen_min
        );
        assert!(naive_min >= -stored0 * (1.0 + 1e-9), "naive {naive_min} J");
    }

    /// A passive element (a sampled damper) never shows negative energy,
    /// and the f32 observer with compensation tracks an f64 reference over
    /// 10^6 ticks.
    #[test]
    fn a_damper_takes_energy_in_and_f32_keeps_up_with_f64() {
        let mut o32 = EnergyObserver::<f32>::new();
        let mut o64 = EnergyObserver::<f64>::new();
        let mut last = Position::ZERO;
        for i in 0..1_000_000i32 {
            // A slow sine of 2 mm at 0.5 Hz.
            let ph = i as f64 * 1e-3 * core::f64::consts::PI;
            let p = Position::from_m_f64(2e-3 * ph.sin()).unwrap();
            let v = (p.nm() - last.nm()) as f64 * 1e-9 / 1e-3;
            last = p;
            let f = 50.0 * v;
            let e32 = o32.update(p, f as f32);
            let e64 = o64.update(p, f);
            assert!(e64 >= -1e-12, "tick {i}: {e64}");
            if i % 100_000 == 99_999 {
                assert!(
                    ((e32 as f64) - e64).abs() <= 1e-5 * e64.abs(),
                    "{e32} vs {e64}"
                );
            }
        }
    }
}
