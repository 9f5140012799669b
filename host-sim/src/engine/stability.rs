//! Is a run stable? The paper's test: "no detectable undamped or divergent
//! oscillations". Here, on the commanded actuator force:
//!
//! 1. **Divergence**: a non-finite state or a device 10 m from where it
//!    started is unstable at once. (A frictionless free mass drifting is not
//!    an instability; a real one trips the velocity limit long before.)
//! 2. **Safety trip**: the board's safety layer latching a fault (a velocity
//!    limit, most often) is unstable.
//! 3. **Undamped oscillation**: the oscillatory part of the force (the
//!    force minus its 50 ms trailing mean) is measured as an RMS over ten
//!    windows of the final quiet second, after the script's last event,
//!    and its envelope's decay is the least-squares line through the
//!    windows' log RMS. If the last half-second is above 0.5 N and the
//!    envelope has not fallen by 30% a second (an exponential decay rate
//!    `ζω` of 0.36 rad/s), the oscillation is sustained (a limit cycle) or
//!    growing: unstable. The line, not a ratio of two halves, because a
//!    limit cycle's amplitude wanders by several percent from one tenth of
//!    a second to the next: the fitted rate of a sustained one scatters by
//!    about 0.1 /s, a third of the threshold, so the verdict does not
//!    flip with the last digit of a gain. A passive mode whose ringing
//!    stays above 0.5 N for a second and decays slower than that is, to a
//!    hand, undamped.
//!
//! Scenes end with at least a second of constant human input so that a
//! forced motion is never mistaken for a self-sustained one.

/// Running statistics for the criterion, fed one force per tick.
#[derive(Clone, Debug)]
pub struct Detector {
    window: Vec<f64>,
    sum: f64,
    next: usize,
    filled: usize,
    quiet_from_tick: u64,
    judged_ticks: u64,
    ticks_per_s: u64,
    total_ticks: u64,
    tick: u64,
    sq: [f64; WINDOWS],
    count: [u64; WINDOWS],
}

/// The verdict.
#[derive(Clone, Debug, PartialEq)]
pub struct StabilityVerdict {
    /// Stable by the criterion.
    pub stable: bool,
    /// Why not, when not.
    pub reason: Option<String>,
    /// RMS of the oscillatory force over the two halves of the final
    /// quiet second (N).
    pub late_rms_n: [f64; 2],
    /// The fitted envelope's ratio over one second (below 1: decaying).
    pub envelope_per_s: f64,
}

/// Oscillation below this RMS is noise, not instability (N).
pub const FLOOR_N: f64 = 0.5;
/// An envelope that keeps more than this fraction a second has not
/// decayed.
pub const DECAY_PER_S: f64 = 0.7;
/// Windows of the judged interval the envelope is fitted through.
pub const WINDOWS: usize = 10;

impl Detector {
    /// For a run of `total_ticks` whose script is quiet from `quiet_tick`;
    /// the judged interval is the last second (or the last half of the
    /// quiet part, if shorter), `ticks_per_s` ticks a second.
    pub fn new(total_ticks: u64, quiet_tick: u64, ticks_per_s: u64) -> Self {
        let quiet = total_ticks.saturating_sub(quiet_tick);
        let judged = quiet.min(ticks_per_s).max(2);
        let mean_len = (ticks_per_s / 20).max(1) as usize;
        Detector {
            window: vec![0.0; mean_len],
            sum: 0.0,
            next: 0,
            filled: 0,
            quiet_from_tick: total_ticks.saturating_sub(judged),
            judged_ticks: judged,
            ticks_per_s: ticks_per_s.max(1),
            total_ticks,
            tick: 0,
            sq: [0.0; WINDOWS],
            count: [0; WINDOWS],
        }
    }

    /// Feed this tick's commanded force (N).
    pub fn push(&mut self, force_n: f64) {
        let n = self.window.len();
        self.sum += force_n - self.window[self.next];
        self.window[self.next] = force_n;
        self.next += 1;
        if self.next == n {
            self.next = 0;
        }
        self.filled = (self.filled + 1).min(n);
        let osc = force_n - self.sum / self.filled as f64;
        if self.tick >= self.quiet_from_tick && self.tick < self.total_ticks {
            let at = self.tick - self.quiet_from_tick;
            let w = (at * WINDOWS as u64 / self.judged_ticks) as usize;
            self.sq[w] += osc * osc;
            self.count[w] += 1;
        }
        self.tick += 1;
    }

    /// The verdict on what was fed.
    pub fn verdict(&self) -> StabilityVerdict {
        let rms = |w: std::ops::Range<usize>| {
            let n: u64 = self.count[w.clone()].iter().sum();
            if n == 0 {
                0.0
            } else {
                (self.sq[w].iter().sum::<f64>() / n as f64).sqrt()
            }
        };
        let half = WINDOWS / 2;
        let late = [rms(0..half), rms(half..WINDOWS)];
        let envelope = self.envelope_per_s();
        let undamped = late[1] > FLOOR_N && envelope > DECAY_PER_S;
        StabilityVerdict {
            stable: !undamped,
            reason: undamped.then(|| {
                format!(
                    "undamped oscillation: force RMS {:.2} N then {:.2} N over the final quiet \
                     second, its envelope keeping {:.0}% a second",
                    late[0],
                    late[1],
                    100.0 * envelope.min(9.99)
                )
            }),
            late_rms_n: late,
            envelope_per_s: envelope,
        }
    }

    /// The least-squares line through the windows' log RMS, as the ratio
    /// it gives over a second. Silent windows sit at a femtonewton, so a
    /// force that stops reads as a steep decay.
    fn envelope_per_s(&self) -> f64 {
        let points: Vec<(f64, f64)> = (0..WINDOWS)
            .filter(|&w| self.count[w] > 0)
            .map(|w| {
                let t = (w as f64 + 0.5) * self.judged_ticks as f64
                    / (WINDOWS as f64 * self.ticks_per_s as f64);
                let rms = (self.sq[w] / self.count[w] as f64).sqrt();
                (t, rms.max(1e-15).ln())
            })
            .collect();
        let n = points.len() as f64;
        if points.len() < 2 {
            return 1.0;
        }
        let (tm, ym) = points
            .iter()
            .fold((0.0, 0.0), |(a, b), (t, y)| (a + t / n, b + y / n));
        let (sxy, sxx) = points.iter().fold((0.0, 0.0), |(a, b), (t, y)| {
            (a + (t - tm) * (y - ym), b + (t - tm) * (t - tm))
        });
        (sxy / sxx).exp()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(f: impl Fn(f64) -> f64) -> StabilityVerdict {
        let mut d = Detector::new(3000, 1000, 1000);
        for k in 0..3000 {
            d.push(f(k as f64 * 1e-3));
        }
        d.verdict()
    }

    #[test]
    fn decaying_constant_and_growing_forces() {
        let w = 2.0 * std::f64::consts::PI * 40.0;
        assert!(run(|t| 50.0 + 20.0 * (-3.0 * t).exp() * (w * t).sin()).stable);
        assert!(run(|_| 80.0).stable);
        let grow = run(|t| 2.0 * (0.5 * t).exp() * (w * t).sin());
        assert!(!grow.stable, "{grow:?}");
        let limit_cycle = run(|t| (200.0 * (w * t).sin()).clamp(-150.0, 150.0));
        assert!(!limit_cycle.stable);
        // Tiny sustained noise below the floor is not instability.
        assert!(run(|t| 0.1 * (w * t).sin()).stable);
    }

    /// A limit cycle whose amplitude wanders (here by up to ±8% every
    /// 50 ms, and 5% lower over the last half-second) is sustained
    /// whatever the wander; a ringing that loses half its amplitude a
    /// second is decaying however large.
    #[test]
    fn a_wandering_limit_cycle_is_sustained_and_a_slow_decay_is_not() {
        let w = 2.0 * std::f64::consts::PI * 37.0;
        let mut seed = 0x2545_f491_u64;
        for _ in 0..200 {
            let steps: Vec<f64> = (0..60)
                .map(|_| {
                    seed = seed
                        .wrapping_mul(6364136223846793005)
                        .wrapping_add(1442695040888963407);
                    1.0 + 0.16 * ((seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5)
                })
                .collect();
            let v = run(|t| {
                let drop = if t >= 2.5 { 0.95 } else { 1.0 };
                drop * steps[(t / 0.05) as usize] * (w * t).sin()
            });
            assert!(!v.stable, "{v:?}");
        }
        let slow = run(|t| 3.0 * (-0.7 * t).exp() * (w * t).sin());
        assert!(slow.stable, "{slow:?}");
        assert!((slow.envelope_per_s - (-0.7f64).exp()).abs() < 0.01);
    }
}
