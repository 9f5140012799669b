//! A body a host simulates at its own rate and sends to the board as a
//! held surface: the host VE that closes a loop through the link.

use super::VeTransfer;
use crate::{param, ParamError, ZTransfer};

/// A mass `m` on a damper `b` and a spring `k` to an anchor at 0, pushed
/// by the force the board reports its coupling applied to the VE point,
/// integrated once per host period `T_h`:
///
/// ```text
/// v[n] = (v[n-1] + (T_h/m) (f[n] - k x[n-1])) / (1 + T_h b / m)
/// x[n] = x[n-1] + T_h v[n]
/// ```
///
/// (semi-implicit Euler, the damper implicit: passive at its own rate for
/// `k T_h² < 4 m + 2 b T_h`). A host sends `x[n]` as a
/// [`Contact::Held`](crate::world::Contact::Held) surface each period.
/// It runs on the host, in `f64`: the positions it sends are picometres.
///
/// The link's delay and the board's ramp make the loop through it
/// time-varying; `twoport-design`'s `host_ve` proves a coupling against it
/// at a given servo rate, host rate and delay, from [`HostBody::tf`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HostBody {
    mass_kg: f32,
    damping_nspm: f32,
    stiffness_npm: f32,
    period_s: f32,
    position_m: f64,
    velocity_mps: f64,
}

impl HostBody {
    /// A body of mass `mass_kg` (kg, positive), damping `damping_nspm`
    /// (N s/m, not negative) and stiffness `stiffness_npm` (N/m, not
    /// negative) to the anchor at 0, stepped every `period_s` (s,
    /// positive), at rest at `position_m` (m).
    pub fn new(
        mass_kg: f32,
        damping_nspm: f32,
        stiffness_npm: f32,
        period_s: f32,
        position_m: f64,
    ) -> Result<Self, ParamError> {
        Ok(HostBody {
            mass_kg: param::positive("host body mass (kg)", mass_kg)?,
            damping_nspm: param::non_negative("host body damping (N s/m)", damping_nspm)?,
            stiffness_npm: param::non_negative("host body stiffness (N/m)", stiffness_npm)?,
            period_s: param::positive("host period T_h (s)", period_s)?,
            position_m,
            velocity_mps: 0.0,
        })
    }

    /// One host period under `force_n` (N, along +x, applied to the body);
    /// the new position (m). A non-finite force leaves the body as it was.
    pub fn step(&mut self, force_n: f64) -> f64 {
        if force_n.is_finite() {
            let (m, b, k, t) = self.params();
            let a = t / m;
            self.velocity_mps =
                (self.velocity_mps + a * (force_n - k * self.position_m)) / (1.0 + a * b);
            self.position_m += t * self.velocity_mps;
        }
        self.position_m
    }

    /// Where the body is (m).
    pub fn position_m(&self) -> f64 {
        self.position_m
    }

    /// Its velocity (m/s).
    pub fn velocity_mps(&self) -> f64 {
        self.velocity_mps
    }

    /// Put it at rest at `position_m` (m).
    pub fn reset(&mut self, position_m: f64) {
        self.position_m = position_m;
        self.velocity_mps = 0.0;
    }

    /// `(m, b, k, T_h)` in f64.
    fn params(&self) -> (f64, f64, f64, f64) {
        (
            f64::from(self.mass_kg),
            f64::from(self.damping_nspm),
            f64::from(self.stiffness_npm),
            f64::from(self.period_s),
        )
    }

    /// Its mass (kg).
    pub fn mass_kg(&self) -> f32 {
        self.mass_kg
    }

    /// Its damping (N s/m).
    pub fn damping_nspm(&self) -> f32 {
        self.damping_nspm
    }

    /// Its spring to the anchor (N/m).
    pub fn stiffness_npm(&self) -> f32 {
        self.stiffness_npm
    }

    /// The host period `T_h` (s).
    pub fn period_s(&self) -> f32 {
        self.period_s
    }

    /// The law in `z_h = e^{s T_h}`: position over force, `X(z_h)/F(z_h)`
    /// (m/N). From the recursion, with `a = T_h/m`:
    /// `X/F = a T_h / ((1 + a b) + (a k T_h - a b - 2) z_h^-1 + z_h^-2)`.
    pub fn position_tf(&self) -> ZTransfer {
        let (m, b, k, t) = self.params();
        let a = t / m;
        let d0 = 1.0 + a * b;
        ZTransfer {
            num: [a * t / d0, 0.0, 0.0],
            den: [1.0, (a * k * t - a * b - 2.0) / d0, 1.0 / d0],
        }
    }

    /// The law as a VE's transfer at the host rate: the velocity
    /// `(x[n] - x[n-1]) / T_h` over the force (m/(N s)).
    pub fn tf(&self) -> VeTransfer {
        let x = self.position_tf();
        let t = f64::from(self.period_s);
        // (1 - z^-1)/T_h times b0 / (1 + a1 z^-1 + a2 z^-2).
        VeTransfer::Admittance(ZTransfer {
            num: [x.num[0] / t, -x.num[0] / t, 0.0],
            den: x.den,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use num_complex::Complex64;

    /// The law the designer analyses is the law a host runs: the body
    /// stepped with a sinusoidal force settles to the amplitude and phase
    /// `position_tf` gives at that frequency.
    #[test]
    fn a_sinusoid_matches_the_analysed_response() {
        let th = 0.3;
        for (m, b, k) in [(0.5, 10.0, 0.0), (0.2, 20.0, 300.0), (1.0, 20.0, 100.0)] {
            let mut body = HostBody::new(m, b, k, 1e-3, 0.0).unwrap();
            let mut xs = [0.0f64; 4000];
            for (n, x) in xs.iter_mut().enumerate() {
                *x = body.step((th * n as f64).cos());
            }
            // The forced response from the transfer function, and the
            // free part (its modes) gone by the end... except a free mass's
            // drift, so compare increments over the last period.
            let h = body.position_tf().eval(Complex64::from_polar(1.0, th));
            let n0 = 3000;
            let forced = |n: usize| (h * Complex64::from_polar(1.0, th * n as f64)).re;
            let drift = (xs[n0] - forced(n0)) - (xs[n0 - 1] - forced(n0 - 1));
            for n in n0..4000 {
                let want = forced(n) - forced(n0) + xs[n0] + drift * (n - n0) as f64;
                assert!(
                    (xs[n] - want).abs() < 1e-7 * h.norm(),
                    "m {m} b {b} k {k}: tick {n}: {} against {want}",
                    xs[n]
                );
            }
        }
    }

    #[test]
    fn bad_parameters_are_named_and_bad_forces_ignored() {
        let e = HostBody::new(0.0, 1.0, 0.0, 1e-3, 0.0).unwrap_err();
        assert_eq!(e.name, "host body mass (kg)");
        let e = HostBody::new(1.0, -1.0, 0.0, 1e-3, 0.0).unwrap_err();
        assert_eq!(e.name, "host body damping (N s/m)");
        let e = HostBody::new(1.0, 1.0, f32::NAN, 1e-3, 0.0).unwrap_err();
        assert_eq!(e.name, "host body stiffness (N/m)");
        let mut b = HostBody::new(1.0, 1.0, 0.0, 1e-3, 0.25).unwrap();
        b.step(f64::NAN);
        assert_eq!((b.position_m(), b.velocity_mps()), (0.25, 0.0));
    }
}
