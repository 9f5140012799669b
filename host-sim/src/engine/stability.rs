//! Is a run stable? The paper's test: "no detectable undamped or divergent
//! oscillations". Here, on the commanded actuator force:
//!
//! 1. **Divergence**: a non-finite state or a device 10 m from where it
//!    started is unstable at once. (A frictionless free mass drifting is not
//!    an instability; a real one trips the velocity limit long before.)
//! 2. **Safety trip**: the board's safety layer latching a fault (a velocity
//!    limit, most often) is unstable.
//! 3. **Undamped oscillation**: the oscillatory part of the force (the
//!    force minus its 50 ms trailing mean) is measured as an RMS over the
//!    two halves of the final quiet second, after the script's last event.
//!    If the second half is above 0.5 N and has not decayed below 98% of
//!    the first half, the oscillation is sustained (a limit cycle) or
//!    growing: unstable. Any mode with ζω above 0.04 rad/s decays faster
//!    than that over half a second, so lightly damped passive terminations
//!    (a stiff arm, a high-Q spring VE) are not mistaken for instability.
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
    half_ticks: u64,
    total_ticks: u64,
    tick: u64,
    sq: [f64; 2],
    count: [u64; 2],
}

/// The verdict.
#[derive(Clone, Debug, PartialEq)]
pub struct Verdict {
    /// Stable by the criterion.
    pub stable: bool,
    /// Why not, when not.
    pub reason: Option<String>,
    /// RMS of the oscillatory force over the two halves of the final
    /// quiet second (N).
    pub late_rms_n: [f64; 2],
}

/// Oscillation below this RMS is noise, not instability (N).
pub const FLOOR_N: f64 = 0.5;
/// A late half above this fraction of the early half has not decayed.
pub const DECAY: f64 = 0.98;

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
            half_ticks: judged / 2,
            total_ticks,
            tick: 0,
            sq: [0.0; 2],
            count: [0; 2],
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
            let half = usize::from(self.tick >= self.quiet_from_tick + self.half_ticks);
            self.sq[half] += osc * osc;
            self.count[half] += 1;
        }
        self.tick += 1;
    }

    /// The verdict on what was fed.
    pub fn verdict(&self) -> Verdict {
        let rms = |h: usize| {
            if self.count[h] == 0 {
                0.0
            } else {
                (self.sq[h] / self.count[h] as f64).sqrt()
            }
        };
        let late = [rms(0), rms(1)];
        let undamped = late[1] > FLOOR_N && late[1] >= DECAY * late[0];
        Verdict {
            stable: !undamped,
            reason: undamped.then(|| {
                format!(
                    "undamped oscillation: force RMS {:.2} N then {:.2} N over the final quiet second",
                    late[0], late[1]
                )
            }),
            late_rms_n: late,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(f: impl Fn(f64) -> f64) -> Verdict {
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
}
