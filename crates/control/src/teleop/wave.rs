//! Wave variables: a channel that stays passive whatever its constant
//! delay (Niemeyer and Slotine).

use super::{Channel, Delayed, TeleopStep, TeleopTransfer};
use crate::{param, ParamError, Real, ZTransfer};

/// Each side sends the wave `s = (b v + f)/√(2b)` and reads the wave `r`
/// the other sent `d` ticks ago, `r = (b v - f)/√(2b)`: its force is
/// `f = b v - √(2b) r` for its velocity `v` (m/s), and it sends
/// `s = √(2b) v - r`. Each tick a side takes in `f v = (s² - r²)/2`: the
/// channel holds what is in transit and gives back no more, so the two
/// sides' channel is passive for any delay of at least one tick (at most
/// `D`). `b` (N s/m) is the wave impedance. Forces are positive resisting
/// each device's positive motion; the slave follows the master.
///
/// Its form: `Z_mm = Z_ss = b (1 + z^-2d)/(1 - z^-2d)`, `Z_ms = Z_sm =
/// -2b z^-d/(1 - z^-2d)`: a lossless line, its poles on the unit circle
/// at the round trip's harmonics.
#[derive(Clone, Copy, Debug)]
pub struct WaveVariables<R = f32, const D: usize = 64> {
    b: R,
    sqrt_2b: R,
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
            to_slave: channel().ok_or(bad)?,
            to_master: channel().ok_or(bad)?,
        })
    }

    /// One tick: each device's velocity estimate (m/s) in, each its force
    /// out, the waves sent on.
    #[inline]
    pub fn step(&mut self, v_m_mps: R, v_s_mps: R) -> TeleopStep<R> {
        let (r_m, r_s) = (self.to_master.arriving(), self.to_slave.arriving());
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
    }

    /// `Z_mm = Z_ss = b (1 + z^-2d)/(1 - z^-2d)`, `Z_ms = Z_sm = -2b
    /// z^-d/(1 - z^-2d)`, in steps of `d`.
    pub fn tf(&self) -> TeleopTransfer {
        let b = self.b.to_f64();
        let d = self.to_slave.delay_ticks() as u32;
        let line = |num: [f64; 3]| Delayed {
            tf: ZTransfer {
                num,
                den: [1.0, 0.0, -1.0],
            },
            stride_ticks: d,
            delay_ticks: 0,
        };
        let (local, remote) = (line([b, 0.0, b]), line([0.0, -2.0 * b, 0.0]));
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
    /// alone), for delays of one to seven ticks.
    #[test]
    fn the_channel_gives_back_no_more_than_it_took() {
        let mut seed = 0x9e37_79b9_7f4a_7c15_u64;
        let mut rng = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        for d in 1..=7 {
            let mut w = WaveVariables::<f64, 8>::new(25.0, d).unwrap();
            let mut taken = 0.0;
            for k in 0..20_000 {
                let (v_m, v_s) = (rng(), if k % 3 == 0 { 0.0 } else { rng() });
                let f = w.step(v_m, v_s);
                taken += f.master_n * v_m + f.slave_n * v_s;
                assert!(taken >= -1e-9, "{d} ticks, tick {k}: {taken}");
            }
        }
    }
}
