//! The VE on the host, the coupling on the board: a proof of the two-rate
//! loop for a host VE that moves with the handle.
//!
//! The board runs the impedance coupling at its servo period `T` against a
//! VE point held at the host's surface ([`Held`]). A host that simulates a
//! body ([`HostBody`]) reads the coupling's force every `N` ticks, steps
//! its body once per its own period `N T`, and sends the body's position;
//! the board takes the update's first step `d` ticks after the tick whose
//! force the host read, and ramps it over `N` ticks. The VE then closes a
//! loop through the host's rate and the link's delay: from the coupling's
//! force to the VE point's velocity it is linear but periodic in `N`
//! ticks, and no longer passive (a delayed mass gives energy back).
//!
//! The proof closes the host's loop around the proven one. With the
//! surface still, the board's loop is the single-rate one the designer
//! proved for every passive VE. The host then sees, from its body's
//! velocity to the force it reads, one system at its own rate: the body's
//! position held, delayed `d` ticks and ramped (the mean over `N` ticks of
//! the held positions, [`Held::ramp_response`]), pushing the coupling and
//! the device with the hand, and the force read every `N`th tick. Its
//! impedance at the host's frequency `θ_h = Nθ` sums the `N` servo
//! frequencies `θ_m = θ + 2πm/N` that fold onto it:
//!
//! ```text
//! Z_env(θ) = Σ_m c_m Z_in(θ_m),
//! c_m = T_h/(1 - e^{-jNθ}) · (1 - e^{-jθ_m})/T · e^{-jdθ_m} · R(θ_m)²,
//! ```
//!
//! where `Z_in` is the impedance the VE point meets: the coupling in series
//! with the device and the hand, `1/Z_in = 1/Z_cI + z^-d Y_h*`. For every
//! passive hand, `Re(1/Z_in) >= e(θ_m) = Re(1/Z_cI) - S(θ_m)` (`S` the
//! designer's sound bound, `e > 0` where the coupling is proven), so
//! `Z_in(θ_m)` lies in the disk through 0 of diameter `1/e`, and
//! `c_m Z_in` in that disk turned and scaled by `c_m`: centre `a_m`, radius
//! `|a_m|`, with `a_m = c_m / (2 e)`. Their sum, where `Z_env` lies, is the
//! disk of centre `Σ a_m` and radius `Σ |a_m|`, through 0 too. The host's
//! body (its impedance `Z_b`, [`HostBody::tf`]) closes the loop
//! `1 + Z_env/Z_b`. Scale the body's admittance from 0 (a still surface:
//! the proven single-rate loop) to its own, `λ/Z_b` with `λ` in `(0, 1]`:
//! a pole crosses the unit circle only where `Z_env = -Z_b/λ`. The disk is
//! convex and holds 0, so when `-Z_b` lies outside it, so does all of
//! `-Z_b/λ`, and the two-rate loop is stable for every passive hand when
//!
//! ```text
//! |Z_b(θ_h) + Σ a_m| > Σ |a_m|   for all θ in (0, π/N].
//! ```
//!
//! (Computed as `(Σ|a_m|)² - |Σ a_m|²` summed pair by pair, which does not
//! cancel where the disks are large.) The disk reaches into the left
//! half-plane by `W = Σ (|a_m| - Re a_m)`, and `Re Z_b > W` is enough, but
//! the test asks less: near DC `W → (k τ)² / (4 b)` with
//! `τ = (d + N - 1) T` (the coupling's spring delayed by the host's period
//! and the link), yet there the disk reaches left only far below the real
//! axis, and a body's reactance keeps `-Z_b` clear of it.
//!
//! The frequencies evaluated: 256 uniform in `(0, π/N]` and every point of
//! the designer's grid folded into it, so every frequency the designer
//! checks is among some `θ_m`. `verify::host` is the independent check:
//! the exact periodic loop's growth over one host period against a search
//! of hands.

use crate::analysis::{grid, impedance_coupling_tf, Analysis, GridSpec};
use crate::network::HumanBound;
use crate::{Error, Plant};
use num_complex::Complex64;
use serde::Serialize;
use std::f64::consts::PI;
use twoport_control::ve::{HostBody, VeTransfer};
use twoport_control::world::Held;
use twoport_control::Position;

/// A host VE and the link to it, in servo ticks.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HostLoop {
    /// The host's period in servo ticks, `N` (>= 1): it reads every `N`th
    /// tick's force and the board ramps each update over `N` ticks.
    pub ve_period_ticks: u32,
    /// Ticks from the tick whose force the host read to the tick that
    /// takes the update's first step, `d` (>= 1): the host's read, its
    /// step and the link both ways.
    pub delay_ticks: u32,
    /// The host's body, at the host's period.
    pub body: HostBody,
}

impl HostLoop {
    /// A host running at `ve_rate_hz` and answering `delay_s` after the
    /// force it read, in ticks of a servo at `servo_period_s`: its period
    /// `N` (the servo's rate over the host's, which must be whole to a
    /// part in 10⁹) and its delay `d` (the delay rounded up to whole ticks,
    /// at least one).
    pub fn ticks_at(
        servo_period_s: f64,
        ve_rate_hz: f64,
        delay_s: f64,
    ) -> Result<(u32, u32), crate::Error> {
        let n = 1.0 / (servo_period_s * ve_rate_hz);
        if !(n.is_finite() && n >= 0.5 && (n - n.round()).abs() <= 1e-9 * n) {
            return Err(crate::Error::HostRate {
                ve_rate_hz,
                servo_period_s,
            });
        }
        if !(delay_s.is_finite() && delay_s > 0.0) {
            return Err(crate::Error::HostDelay(delay_s));
        }
        let d = (delay_s / servo_period_s - 1e-9).ceil().max(1.0);
        Ok((n.round() as u32, d as u32))
    }

    /// A host at `ve_period_ticks` servo ticks of `servo_period_s`, with
    /// `delay_ticks` of delay, stepping a body of `mass_kg`,
    /// `damping_nspm` and `stiffness_npm`. Refuses a zero period or delay
    /// and a body parameter out of its range, naming it.
    pub fn new(
        servo_period_s: f64,
        ve_period_ticks: u32,
        delay_ticks: u32,
        (mass_kg, damping_nspm, stiffness_npm): (f64, f64, f64),
    ) -> Result<Self, Error> {
        if ve_period_ticks == 0 {
            return Err(Error::HostLoop(
                "the VE period must be at least one servo tick".into(),
            ));
        }
        if delay_ticks == 0 {
            return Err(Error::HostLoop(
                "the delay must be at least one servo tick: a host answers a force it has read"
                    .into(),
            ));
        }
        let t_h = servo_period_s * f64::from(ve_period_ticks);
        let body = HostBody::new(
            mass_kg as f32,
            damping_nspm as f32,
            stiffness_npm as f32,
            t_h as f32,
            0.0,
        )?;
        Ok(HostLoop {
            ve_period_ticks,
            delay_ticks,
            body,
        })
    }

    /// `c_m` at base frequency `theta` (rad per tick), `m = 0..N`.
    fn weights(&self, theta: f64, period_s: f64) -> Vec<Complex64> {
        let n = self.ve_period_ticks;
        let ramp = Held::<1>::new([Position::ZERO], period_s as f32, n);
        let t_h = period_s * f64::from(n);
        let hold = t_h / (1.0 - Complex64::from_polar(1.0, -f64::from(n) * theta));
        (0..n)
            .map(|m| {
                let th = theta + 2.0 * PI * f64::from(m) / f64::from(n);
                let z = Complex64::from_polar(1.0, th);
                let r = ramp.ramp_response(z);
                hold * (1.0 - z.inv()) / period_s
                    * Complex64::from_polar(1.0, -f64::from(self.delay_ticks) * th)
                    * r
                    * r
            })
            .collect()
    }

    /// The body's impedance `F/V` at the host's frequency `theta_h` (rad
    /// per host period), from its own law.
    fn body_impedance(&self, theta_h: f64) -> Complex64 {
        let z = Complex64::from_polar(1.0, theta_h);
        match self.body.tf() {
            VeTransfer::Admittance(y) => y.eval(z).inv(),
            VeTransfer::Impedance(zb) => zb.eval(z),
        }
    }
}

/// Where `Z_env` can lie at one host frequency for every passive hand:
/// the sum of the disks `c_m Z_in(θ_m)` ranges over, itself a disk
/// through 0 (each is), of centre `Σ a_m` and radius `Σ |a_m|` with
/// `a_m = c_m / (2 e_m)`.
struct Disk {
    /// `Σ a_m`.
    centre: Complex64,
    /// `Σ |a_m|`.
    radius: f64,
    /// `radius² - |centre|² >= 0`, summed pair by pair so that disks of
    /// nearly one direction do not cancel.
    slack: f64,
}

impl Disk {
    /// The disk of the terms `(c_m, e_m)`; `None` where a weighted term's
    /// `e_m <= 0` (the coupling is not proven for every passive VE there).
    fn of(terms: &[(Complex64, f64)]) -> Option<Disk> {
        let mut a = Vec::with_capacity(terms.len());
        for &(c, e) in terms {
            if e > 0.0 {
                a.push(c / (2.0 * e));
            } else if c.norm() != 0.0 {
                return None;
            }
        }
        // |p||q| - Re(p q*) without the cancellation of nearly parallel
        // terms.
        let apart = |p: Complex64, q: Complex64| {
            let w = p * q.conj();
            if w.re > 0.0 {
                w.im * w.im / (w.norm() + w.re)
            } else {
                w.norm() - w.re
            }
        };
        let slack = a
            .iter()
            .flat_map(|p| a.iter().map(move |q| apart(*p, *q)))
            .sum();
        Some(Disk {
            centre: a.iter().sum(),
            radius: a.iter().map(|p| p.norm()).sum(),
            slack,
        })
    }

    /// `radius² - |z + centre|²`: positive where `-z` is inside.
    fn inside(&self, z: Complex64) -> f64 {
        self.slack - z.norm_sqr() - 2.0 * (z * self.centre.conj()).re
    }

    /// How far `-z_b` lies outside the disk (N s/m; negative inside).
    fn margin(&self, z_b: Complex64) -> f64 {
        let n = self.inside(z_b);
        if n.is_nan() {
            return f64::NEG_INFINITY;
        }
        -n / ((z_b + self.centre).norm() + self.radius)
    }

    /// The least damping `B` (N s/m) from which on `-(z_0 + B)` lies
    /// outside the disk: the upper end of the dampings that put it
    /// inside, 0 where none does. (`B` only moves `-z_b` along the real
    /// axis.)
    fn least_damping(&self, z_0: Complex64) -> f64 {
        let s = z_0 + self.centre;
        let disc = self.radius * self.radius - s.im * s.im;
        if disc.is_nan() {
            return f64::INFINITY;
        }
        if disc <= 0.0 {
            return 0.0;
        }
        // Inside for B in -Re s ± √disc; the upper end, by the product of
        // the roots where Re s > 0 (where both are large and nearly equal).
        let upper = if s.re > 0.0 {
            self.inside(z_0) / (s.re + disc.sqrt())
        } else {
            -s.re + disc.sqrt()
        };
        upper.max(0.0)
    }
}

/// What [`check_host_ve`] found.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct HostCheck {
    /// Whether `-Z_b` lies outside the disk `Z_env` can reach at every
    /// frequency evaluated (and the coupling is proven for every passive
    /// VE there).
    pub proven: bool,
    /// The least distance of `-Z_b` outside that disk over them (N s/m;
    /// negative inside).
    pub min_margin_nspm: f64,
    /// The base frequency where it is least (Hz, in `(0, 1/(2 N T)]`).
    pub worst_frequency_hz: f64,
    /// The least body damping from which on the loop is proven with this
    /// body's mass and spring (N s/m): at each frequency, the upper end of
    /// the dampings that put `-Z_b` inside the disk (damping moves it
    /// along the real axis). Infinite where the coupling is not proven for
    /// every passive VE at some frequency.
    pub least_damping_nspm: f64,
    /// How many base frequencies were evaluated.
    pub frequencies: usize,
}

/// Base frequencies in `(0, π/N]` (rad per tick): 256 uniform, and the
/// designer's grid folded in.
fn base_grid(plant: &Plant, n: u32) -> Vec<f64> {
    let t = plant.period_s();
    let top = PI / f64::from(n);
    let period = 2.0 * top;
    let mut th: Vec<f64> = (1..=256).map(|i| top * f64::from(i) / 256.0).collect();
    for w in grid(plant, GridSpec::DEFAULT) {
        let f = (w * t).rem_euclid(period);
        let f = if f > top { period - f } else { f };
        if f > 1e-9 * top {
            th.push(f);
        }
    }
    th.sort_by(f64::total_cmp);
    th.dedup_by(|a, b| (*a - *b).abs() <= 1e-12 * top);
    th
}

/// The device's side of the host's loop, evaluated once for any coupling:
/// at each base frequency, the designer's sound bound at the `N`
/// frequencies that fold onto it, the host's weights `c_m` there, and the
/// body's real impedance. A coupling's check then costs its own
/// response at those frequencies, so the searches for the stiffest
/// coupling and the best pair evaluate the device once.
pub struct HostAnalysis<'a> {
    plant: &'a Plant,
    human: Option<HumanBound>,
    host: HostLoop,
    bases: Vec<f64>,
    /// `z` at each folded frequency, base by base, `N` a base.
    z: Vec<Complex64>,
    /// The sound bound there.
    bound: Vec<f64>,
    /// `c_m`, laid out as `z`.
    weights: Vec<Complex64>,
    /// `Z_b` at each base frequency's host frequency.
    zb: Vec<Complex64>,
    /// The single-rate analysis and its bound, for the searches.
    single: std::cell::OnceCell<(Analysis, Vec<f64>)>,
}

impl<'a> HostAnalysis<'a> {
    /// Evaluate `plant` (with the hand within `human` where given) and
    /// `host` on the base frequencies.
    pub fn new(plant: &'a Plant, human: Option<HumanBound>, host: &HostLoop) -> Self {
        let t = plant.period_s();
        let n = host.ve_period_ticks as usize;
        let bases = base_grid(plant, host.ve_period_ticks);
        // Every folded frequency in [0, π] (the real parts are even in θ).
        let fold = |th: f64| ((th + PI).rem_euclid(2.0 * PI) - PI).abs();
        let omegas: Vec<f64> = bases
            .iter()
            .flat_map(|&th| (0..n).map(move |m| th + 2.0 * PI * m as f64 / n as f64))
            .map(|th| fold(th).max(1e-12) / t)
            .collect();
        let a = Analysis::on(plant, &omegas);
        let bound = a.impedance_bound(human);
        let weights = bases.iter().flat_map(|&th| host.weights(th, t)).collect();
        let zb = bases
            .iter()
            .map(|&th| host.body_impedance(f64::from(host.ve_period_ticks) * th))
            .collect();
        HostAnalysis {
            plant,
            human,
            host: *host,
            bases,
            z: a.points.iter().map(|p| p.z).collect(),
            bound,
            weights,
            zb,
            single: std::cell::OnceCell::new(),
        }
    }

    /// Prove the impedance coupling `(k, b)` (N/m, N s/m) against the
    /// host's loop, for every passive hand (within `human` where given).
    pub fn check(&self, k: f64, b: f64) -> Result<HostCheck, Error> {
        let t = self.plant.period_s();
        let n = self.host.ve_period_ticks as usize;
        let zc = impedance_coupling_tf(k, b, t)?;
        let damping = f64::from(self.host.body.damping_nspm());
        let (mut worst, mut least_damping) = ((f64::INFINITY, 0.0), f64::NEG_INFINITY);
        for (i, &th) in self.bases.iter().enumerate() {
            let terms: Vec<(Complex64, f64)> = (i * n..(i + 1) * n)
                .map(|m| (self.weights[m], zc.eval(self.z[m]).inv().re - self.bound[m]))
                .collect();
            let zb = self.zb[i];
            let (margin, least) = match Disk::of(&terms) {
                Some(disk) => (disk.margin(zb), disk.least_damping(zb - damping)),
                None => (f64::NEG_INFINITY, f64::INFINITY),
            };
            if margin < worst.0 {
                worst = (margin, th / (2.0 * PI * t));
            }
            least_damping = least_damping.max(least);
        }
        Ok(HostCheck {
            proven: worst.0 > 0.0,
            min_margin_nspm: worst.0,
            worst_frequency_hz: worst.1,
            least_damping_nspm: least_damping.max(0.0),
            frequencies: self.bases.len(),
        })
    }

    /// The stiffest coupling at damping `b` (N s/m) proven both for every
    /// passive VE and against the host (N/m, to 1e-3 of it): the
    /// single-rate limit, lowered by bisection until the host's loop is
    /// proven; `None` where no stiffness above 1e-6 of the limit is.
    pub fn max_stiffness(&self, b: f64) -> Result<Option<f64>, Error> {
        let (a, bound) = self.single.get_or_init(|| {
            let a = Analysis::new(self.plant, GridSpec::DEFAULT);
            let bound = a.impedance_bound(self.human);
            (a, bound)
        });
        let Some(limit) = crate::analysis::max_stiffness(a, bound, b) else {
            return Ok(None);
        };
        let proven = |k: f64| self.check(k, b).map(|c| c.proven);
        // Just inside the single-rate boundary, where the excess is positive.
        let top = limit * (1.0 - 1e-6);
        if proven(top)? {
            return Ok(Some(top));
        }
        let (mut lo, mut hi) = (top * 1e-6, top);
        if !proven(lo)? {
            return Ok(None);
        }
        while (hi - lo) > 1e-3 * lo {
            let mid = (lo * hi).sqrt();
            if proven(mid)? {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        Ok(Some(lo))
    }

    /// The best pair against the host: the damping in `(0, b_max]` (N s/m)
    /// whose stiffest coupling proven against it is stiffest, and that
    /// stiffness, `(k N/m, b N s/m)`. A damping helps the single-rate
    /// proof and, delayed by the host, works against the host's loop, so
    /// the pair lies below the single-rate one: searched over seven
    /// dampings spaced by ratios of 2.6 down to `b_max / 300`, then by
    /// golden sections around the best.
    pub fn best_pair(&self, b_max: f64) -> Result<Option<(f64, f64)>, Error> {
        let k_at = |b: f64| self.max_stiffness(b.min(b_max)).map(|k| k.unwrap_or(0.0));
        let ln = |i: f64| b_max.ln() - i * (300f64.ln() / 6.0);
        let mut best = (0.0, b_max, 0.0);
        for i in 0..7 {
            let b = ln(f64::from(i)).exp().min(b_max);
            let k = k_at(b)?;
            if k > best.0 {
                best = (k, b, f64::from(i));
            }
        }
        if best.0 == 0.0 {
            return Ok(None);
        }
        // Golden sections in log b over the best's neighbours.
        let (mut lo, mut hi) = (ln((best.2 + 1.0).min(6.0)), ln((best.2 - 1.0).max(0.0)));
        let g = 0.618_033_988_749_895;
        for _ in 0..6 {
            let (x1, x2) = (hi - g * (hi - lo), lo + g * (hi - lo));
            let (k1, k2) = (k_at(x1.exp())?, k_at(x2.exp())?);
            for (k, x) in [(k1, x1), (k2, x2)] {
                if k > best.0 {
                    best = (k, x.exp().min(b_max), best.2);
                }
            }
            if k1 > k2 {
                hi = x2;
            } else {
                lo = x1;
            }
        }
        Ok(Some((best.0, best.1)))
    }
}

/// [`HostAnalysis::check`] for one coupling.
pub fn check_host_ve(
    plant: &Plant,
    k: f64,
    b: f64,
    human: Option<HumanBound>,
    host: &HostLoop,
) -> Result<HostCheck, Error> {
    HostAnalysis::new(plant, human, host).check(k, b)
}

/// [`HostAnalysis::max_stiffness`] for one damping.
pub fn host_max_stiffness(
    plant: &Plant,
    b: f64,
    human: Option<HumanBound>,
    host: &HostLoop,
) -> Result<Option<f64>, Error> {
    HostAnalysis::new(plant, human, host).max_stiffness(b)
}

/// [`HostAnalysis::best_pair`].
pub fn host_best_pair(
    plant: &Plant,
    human: Option<HumanBound>,
    host: &HostLoop,
    b_max: f64,
) -> Result<Option<(f64, f64)>, Error> {
    HostAnalysis::new(plant, human, host).best_pair(b_max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::max_stiffness;
    use crate::DeviceModel;

    fn excalibur(t: f64) -> (DeviceModel, Plant) {
        let m = DeviceModel::excalibur().unwrap();
        let p = Plant::new(&m, t).unwrap();
        (m, p)
    }

    /// A host's rate and delay in servo ticks: a whole multiple within a
    /// part in 10⁹ (a 1 kHz host on 4 kHz: 4; on 1.5 kHz: refused), the
    /// delay rounded up to whole ticks and at least one.
    #[test]
    fn a_host_rate_and_delay_become_ticks() {
        assert_eq!(HostLoop::ticks_at(2.5e-4, 1000.0, 0.002), Ok((4, 8)));
        assert_eq!(HostLoop::ticks_at(1e-3, 1000.0, 0.0021), Ok((1, 3)));
        assert_eq!(HostLoop::ticks_at(1e-3, 1000.0, 1e-6), Ok((1, 1)));
        for (t, rate) in [(1.0 / 1500.0, 1000.0), (1e-3, 2000.0)] {
            assert!(matches!(
                HostLoop::ticks_at(t, rate, 0.002),
                Err(crate::Error::HostRate { .. })
            ));
        }
        for bad in [0.0, -1.0, f64::NAN] {
            assert!(matches!(
                HostLoop::ticks_at(1e-3, 1000.0, bad),
                Err(crate::Error::HostDelay(_))
            ));
        }
    }

    /// A host that never moves its body (all damping) adds nothing: the
    /// loop is proven exactly where the coupling is proven for every
    /// passive VE, and not past it.
    #[test]
    fn a_still_body_leaves_the_single_rate_proof() {
        let (_, p) = excalibur(1e-3);
        let a = Analysis::new(&p, GridSpec::DEFAULT);
        let limit = max_stiffness(&a, &a.impedance_bound(Some(HumanBound::PAPER)), 90.0).unwrap();
        let still = HostLoop::new(1e-3, 1, 1, (1.0, 1e12, 0.0)).unwrap();
        let at = |k: f64| check_host_ve(&p, k, 90.0, Some(HumanBound::PAPER), &still).unwrap();
        assert!(at(0.99 * limit).proven);
        assert!(!at(1.01 * limit).proven);
        assert!(at(1.01 * limit).least_damping_nspm.is_infinite());
    }

    #[test]
    fn a_host_loop_that_cannot_be_is_named() {
        let e = HostLoop::new(1e-3, 0, 1, (1.0, 1.0, 0.0)).unwrap_err();
        assert!(e.to_string().contains("VE period"), "{e}");
        let e = HostLoop::new(1e-3, 1, 0, (1.0, 1.0, 0.0)).unwrap_err();
        assert!(e.to_string().contains("delay"), "{e}");
        let e = HostLoop::new(1e-3, 1, 1, (0.0, 1.0, 0.0)).unwrap_err();
        assert!(e.to_string().contains("host body mass"), "{e}");
    }
}
