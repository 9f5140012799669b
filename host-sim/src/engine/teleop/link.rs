//! A network between the two sides: each packet late by the channel's
//! delay and a jitter, some lost, the receiver keeping the newest sent.

use crate::engine::effects::Rng;
use std::collections::VecDeque;

/// One direction of the channel. With no jitter and no drops it is the
/// control crate's constant-delay channel, value for value.
#[derive(Clone, Debug)]
pub struct Link<T> {
    delay: u64,
    jitter: u64,
    drop_fraction: f64,
    rng: Rng,
    /// Packets on their way: the tick each arrives, the tick it left.
    in_flight: VecDeque<(u64, u64, T)>,
    /// The newest packet received: the tick it left (none before the
    /// first) and its value.
    held: (Option<u64>, T),
}

impl<T: Copy> Link<T> {
    /// A link `delay_ticks` long, each packet later by up to
    /// `jitter_ticks` more, a fraction `drop_fraction` lost, drawn from
    /// `seed` (nonzero); it holds `initial` until a packet arrives.
    pub fn new(
        delay_ticks: usize,
        jitter_ticks: usize,
        drop_fraction: f64,
        seed: u64,
        initial: T,
    ) -> Self {
        Link {
            delay: delay_ticks as u64,
            jitter: jitter_ticks as u64,
            drop_fraction,
            rng: Rng(seed.max(1)),
            in_flight: VecDeque::new(),
            held: (None, initial),
        }
    }

    /// Send `value` at `tick`; what the receiver has at `tick`: the
    /// newest-sent packet to have arrived (a later one overtaken by it is
    /// thrown away), or what it held before.
    pub fn pass(&mut self, tick: u64, value: T) -> T {
        let lost = self.drop_fraction > 0.0 && self.rng.uniform() < self.drop_fraction;
        if !lost {
            let extra = if self.jitter > 0 {
                ((self.rng.uniform() * (self.jitter + 1) as f64) as u64).min(self.jitter)
            } else {
                0
            };
            self.in_flight
                .push_back((tick + self.delay + extra, tick, value));
        }
        let mut kept = VecDeque::with_capacity(self.in_flight.len());
        for (arrives, sent, v) in self.in_flight.drain(..) {
            if arrives > tick {
                kept.push_back((arrives, sent, v));
            } else if self.held.0.is_none_or(|s| sent > s) {
                self.held = (Some(sent), v);
            }
        }
        self.in_flight = kept;
        self.held.1
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use twoport_control::teleop::Channel;

    #[test]
    fn without_jitter_it_is_the_constant_channel() {
        for delay in [0, 1, 3] {
            let mut link = Link::new(delay, 0, 0.0, 1, -1i64);
            let mut channel = Channel::<i64, 8>::new(delay, -1).unwrap();
            for k in 0..50u64 {
                let v = (k * k) as i64;
                assert_eq!(link.pass(k, v), channel.pass(v), "delay {delay}, tick {k}");
            }
        }
    }

    #[test]
    fn jitter_never_delivers_early_late_or_out_of_order() {
        let (delay, jitter) = (2u64, 5u64);
        let mut link = Link::new(delay as usize, jitter as usize, 0.2, 7, None);
        let mut last_sent = None;
        let mut lost_or_late = 0;
        for k in 0..2_000u64 {
            let got = link.pass(k, Some(k));
            if let Some(sent) = got {
                assert!(sent + delay <= k, "tick {k}: {sent} arrived early");
                assert!(
                    last_sent.is_none_or(|l| sent >= l),
                    "tick {k}: older than held"
                );
                last_sent = Some(sent);
                lost_or_late += u64::from(sent + delay < k);
            }
            // A packet never waits past its jitter unless lost: what is
            // held is at most the jitter old, or one that outlived its
            // successors' loss.
            assert!(got.is_some() || k < delay + jitter + 20);
        }
        assert!(
            lost_or_late > 200,
            "jitter and drops showed: {lost_or_late}"
        );
    }
}
