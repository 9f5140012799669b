//! Wave variables: a channel that stays passive whatever its constant
//! delay (Niemeyer and Slotine).

use super::{Channel, Delayed, Sparse, TeleopStep, TeleopTransfer};
use crate::{param, ParamError, Real};

/// Each side sends the wave `s = (b v + f)/√(2b)` and reads the wave `r`
/// the other sent `d` ticks ago, `r = (b v - f)/√(2b)`: its force is
/// `f = b v - √(2b) r` for its velocity `v` (m/s), and it sends
/// `s = √(2b) v - r`. Each tick a side takes in `f v = (s² - r²)/2`: the
/// channel holds what is in transit and gives back no more, so the two
/// sides' channel is passive for any delay of at least one tick (at most
/// `D`). `b` (N s/m) is the wave impedance. Forces are positive resisting
/// each device's positive motion; the slave follows the master.
///
/// Its form: `Z_mm = Z_ss = b (1 + g²)/(1 - g²)`, `Z_ms = Z_sm = -2b g/(1 -
/// g²)` with `g = H z^-d`. Unfiltered (`H = 1`) it is a lossless line,
/// its poles on the unit circle at the round trip's harmonics, where a
/// sampled device on a stiff termination resonates. Each side may filter
/// the wave it reads, `r_f = a r_f' + (1 - a) r` (`H = (1 - a)/(1 - a
/// z^-1)`, [`with_wave_filter`](Self::with_wave_filter)): a convex mix,
/// so `Σ r_f² <= Σ r²` over any span and the channel stays passive, and
/// `|H| < 1` away from DC moves every pole but `z = 1` inside the circle.
#[derive(Clone, Copy, Debug)]
pub struct WaveVariables<R = f32, const D: usize = 64> {
    b: R,
    sqrt_2b: R,
    /// The wave filter's pole `a` (0: none).
    pole: R,
    /// Each side's filtered wave, `r_f'` (master's, slave's).
    filtered: [R; 2],
    to_slave: Channel<R, D>,
    to_master: Channel<R, D>,
}

impl<R: Real, const D: usize> WaveVariables<R, D> {
    /// Wave impedance `b_nspm` (N s/m, > 0), the channel `delay_ticks`
    /// long each way (1 to `D`), empty.
    ///
    /// # Examples
    ///
    /// ```
    /// use twoport_control::teleop::WaveVariables;
    /// let mut w = WaveVariables::<f32, 8>::new(10.0, 2)?;
    /// // The master pushed at 0.1 m/s, the slave held: the slave is pulled
    /// // along two ticks on, with twice the master's first force.
    /// let f: Vec<(f32, f32)> = (0..3)
    ///     .map(|_| { let s = w.step(0.1, 0.0); (s.master_n, s.slave_n) })
    ///     .collect();
    /// assert_eq!(f[0], (1.0, 0.0));
    /// assert!((f[2].1 + 2.0).abs() < 1e-6);
    /// assert!(WaveVariables::<f32, 8>::new(10.0, 0).is_err());
    /// # Ok::<(), twoport_control::ParamError>(())
    /// ```
    pub fn new(b_nspm: f32, delay_ticks: usize) -> Result<Self, ParamError> {
        let b = param::positive("b (N s/m)", b_nspm)?;
        let bad = ParamError {
            name: "delay (ticks)",
            value: delay_ticks as f32,
            problem: "must be at least 1 (with none the two sides' waves are one loop) and at most the channel's length",
        };
        let channel = || Channel::new(delay_ticks, R::ZERO).filter(|_| delay_ticks >= 1);
        Ok(WaveVariables {
            b: R::of(b),
            sqrt_2b: R::of((2.0 * b).sqrt()),
            pole: R::ZERO,
            filtered: [R::ZERO; 2],
            to_slave: channel().ok_or(bad)?,
            to_master: channel().ok_or(bad)?,
        })
    }

    /// Each side's incoming wave low-passed, `r_f = a r_f' + (1 - a) r`,
    /// with the pole `a` in `[0, 1)` (`e^{-2π f_c T}` for a cutoff `f_c`).
    pub fn with_wave_filter(mut self, pole: f32) -> Result<Self, ParamError> {
        if !(0.0..1.0).contains(&pole) {
            return Err(ParamError {
                name: "wave filter pole",
                value: pole,
                problem: "must be at least 0 and below 1",
            });
        }
        self.pole = R::of(pole);
        Ok(self)
    }

    /// One tick: each device's velocity estimate (m/s) in, each its force
    /// out, the waves sent on.
    #[inline]
    pub fn step(&mut self, v_m_mps: R, v_s_mps: R) -> TeleopStep<R> {
        let (a, one) = (self.pole, R::ONE);
        let mix = |prev: R, r: R| a * prev + (one - a) * r;
        let r_m = mix(self.filtered[0], self.to_master.arriving());
        let r_s = mix(self.filtered[1], self.to_slave.arriving());
        self.filtered = [r_m, r_s];
        self.to_slave.send(self.sqrt_2b * v_m_mps - r_m);
        self.to_master.send(self.sqrt_2b * v_s_mps - r_s);
        TeleopStep {
            master_n: self.b * v_m_mps - self.sqrt_2b * r_m,
            slave_n: self.b * v_s_mps - self.sqrt_2b * r_s,
        }
    }

    /// The channel emptied.
    pub fn reset(&mut self) {
        self.to_slave.reset(R::ZERO);
        self.to_master.reset(R::ZERO);
        self.filtered = [R::ZERO; 2];
    }

    /// `Z_mm = Z_ss = b (1 + g²)/(1 - g²)`, `Z_ms = Z_sm = -2b g/(1 - g²)`,
    /// `g = (1 - a) z^-d/(1 - a z^-1)`: over the common denominator
    /// `(1 - a z^-1)² - (1 - a)² z^-2d`.
    pub fn tf(&self) -> TeleopTransfer {
        let (b, a) = (self.b.to_f64(), self.pole.to_f64());
        let d = self.to_slave.delay_ticks() as u32;
        let c = (1.0 - a) * (1.0 - a);
        let den = Sparse {
            coef: [1.0, -2.0 * a, a * a, -c],
            power: [0, 1, 2, 2 * d],
        };
        let local = Delayed {
            num: Sparse {
                coef: [b, -2.0 * a * b, a * a * b, c * b],
                power: [0, 1, 2, 2 * d],
            },
            den,
        };
        let remote = Delayed {
            num: Sparse {
                coef: [-2.0 * b * (1.0 - a), 2.0 * a * b * (1.0 - a), 0.0, 0.0],
                power: [d, d + 1, 0, 0],
            },
            den,
        };
        TeleopTransfer {
            z: [
                [local, remote, Delayed::ZERO, Delayed::ZERO],
                [remote, local, Delayed::ZERO, Delayed::ZERO],
            ],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Whatever the two sides do, the energy the channel has taken in
    /// never falls below zero: it gives back at most what it was given
    /// (an independent check of passivity, from the waves' bookkeeping
    /// alone), for delays of one to seven ticks, its waves filtered or
    /// not.
    #[test]
    fn the_channel_gives_back_no_more_than_it_took() {
        let mut seed = 0x9e37_79b9_7f4a_7c15_u64;
        let mut rng = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        for (d, pole) in (1..=7).flat_map(|d| [(d, 0.0), (d, 0.8)]) {
            let mut w = WaveVariables::<f64, 8>::new(25.0, d)
                .unwrap()
                .with_wave_filter(pole)
                .unwrap();
            let mut taken = 0.0;
            for k in 0..20_000 {
                let (v_m, v_s) = (rng(), if k % 3 == 0 { 0.0 } else { rng() });
                let f = w.step(v_m, v_s);
                taken += f.master_n * v_m + f.slave_n * v_s;
                assert!(taken >= -1e-9, "{d} ticks, pole {pole}, tick {k}: {taken}");
            }
        }
    }
}
