//! The scope's data side, apart from any drawing: bounded sample buffers,
//! per-pixel min/max decimation and an edge trigger.

use std::collections::VecDeque;

/// A bounded ring of `(t, value)` samples: memory is `capacity` samples
/// however long the scope runs.
#[derive(Clone, Debug)]
pub struct Ring {
    data: VecDeque<(f64, f64)>,
    capacity: usize,
}

impl Ring {
    /// A ring holding at most `capacity` samples (at least 2).
    pub fn new(capacity: usize) -> Self {
        let capacity = capacity.max(2);
        Ring {
            data: VecDeque::with_capacity(capacity),
            capacity,
        }
    }

    /// Append a sample, dropping the oldest when full.
    pub fn push(&mut self, t: f64, v: f64) {
        if self.data.len() == self.capacity {
            self.data.pop_front();
        }
        self.data.push_back((t, v));
    }

    /// Samples held.
    pub fn len(&self) -> usize {
        self.data.len()
    }

    /// Whether empty.
    pub fn is_empty(&self) -> bool {
        self.data.is_empty()
    }

    /// The bound on samples held.
    pub fn capacity(&self) -> usize {
        self.capacity
    }

    /// Samples in time order.
    pub fn iter(&self) -> impl Iterator<Item = &(f64, f64)> {
        self.data.iter()
    }
}

/// Per-pixel `(min, max)` of the samples in `[t0, t1)` over `pixels`
/// columns; a column with no sample is `None`. Drawing a vertical line from
/// min to max in each column shows every peak of a stream far faster than
/// the screen, with no aliasing: a 10 kHz stream on 1000 pixels over 1 s
/// puts 10 samples in each column and loses none of their extremes.
pub fn minmax<'a>(
    samples: impl IntoIterator<Item = &'a (f64, f64)>,
    t0: f64,
    t1: f64,
    pixels: usize,
) -> Vec<Option<(f64, f64)>> {
    let mut out = vec![None; pixels];
    let span_ok = t1 > t0;
    if pixels == 0 || !span_ok {
        return out;
    }
    let scale = pixels as f64 / (t1 - t0);
    for &(t, v) in samples {
        let inside = t >= t0 && t < t1 && v.is_finite();
        if !inside {
            continue;
        }
        let i = (((t - t0) * scale) as usize).min(pixels - 1);
        out[i] = Some(match out[i] {
            None => (v, v),
            Some((lo, hi)) => (lo.min(v), hi.max(v)),
        });
    }
    out
}

/// Which crossing triggers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Edge {
    /// From below the level to at or above it.
    Rising,
    /// From above the level to at or below it.
    Falling,
}

/// The time of the last crossing of `level` on `edge` in the samples, if
/// any: where a triggered sweep starts.
pub fn last_trigger<'a>(
    samples: impl IntoIterator<Item = &'a (f64, f64)>,
    level: f64,
    edge: Edge,
) -> Option<f64> {
    let mut prev: Option<f64> = None;
    let mut found = None;
    for &(t, v) in samples {
        if let Some(p) = prev {
            let hit = match edge {
                Edge::Rising => p < level && v >= level,
                Edge::Falling => p > level && v <= level,
            };
            if hit {
                found = Some(t);
            }
        }
        prev = Some(v);
    }
    found
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_ring_is_bounded_and_keeps_the_newest() {
        let mut r = Ring::new(1000);
        for k in 0..3_600_000u64 {
            r.push(k as f64 * 1e-3, k as f64);
        }
        assert_eq!(r.len(), 1000);
        assert_eq!(r.iter().next().unwrap().1, 3_599_000.0);
        assert_eq!(r.iter().last().unwrap().1, 3_599_999.0);
    }

    /// A 10 kHz stream with a single-sample spike: min/max on 100 pixels
    /// keeps the spike; picking every 100th sample would lose it.
    #[test]
    fn minmax_decimation_keeps_every_peak() {
        let mut r = Ring::new(20_000);
        for k in 0..10_000 {
            let v = if k == 4_321 {
                50.0
            } else {
                (k as f64 * 0.01).sin()
            };
            r.push(k as f64 * 1e-4, v);
        }
        let cols = minmax(r.iter(), 0.0, 1.0, 100);
        assert!(cols.iter().all(|c| c.is_some()));
        let top = cols.iter().map(|c| c.unwrap().1).fold(f64::MIN, f64::max);
        assert_eq!(top, 50.0);
        let naive = r.iter().step_by(100).map(|s| s.1).fold(f64::MIN, f64::max);
        assert!(naive < 2.0, "the naive decimation would have missed it");
    }

    #[test]
    fn trigger_finds_the_last_edge() {
        let s: Vec<(f64, f64)> = (0..1000)
            .map(|k| (k as f64, (k as f64 * 0.1).sin()))
            .collect();
        let t = last_trigger(s.iter(), 0.0, Edge::Rising).unwrap();
        assert!(
            (t * 0.1 / (2.0 * std::f64::consts::PI)).fract() < 0.02,
            "{t}"
        );
        let f = last_trigger(s.iter(), 0.5, Edge::Falling).unwrap();
        assert!(f > t - 63.0);
        assert_eq!(last_trigger(s.iter(), 5.0, Edge::Rising), None);
    }
}
