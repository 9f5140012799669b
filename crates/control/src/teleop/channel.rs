//! A channel with a constant delay of whole ticks.

/// What one side sends the other, `delay` ticks late: a ring of at most
/// `D` values (`no_std`, no allocation). Before `delay` ticks have passed
/// it gives the value it was made with.
#[derive(Clone, Copy, Debug)]
pub struct Channel<T, const D: usize> {
    ring: [T; D],
    delay: usize,
    next: usize,
}

impl<T: Copy, const D: usize> Channel<T, D> {
    /// A channel `delay_ticks` long (0: no delay), at most `D`; `None`
    /// past it. It holds `initial` until the first value sent arrives.
    pub fn new(delay_ticks: usize, initial: T) -> Option<Self> {
        (delay_ticks <= D).then_some(Channel {
            ring: [initial; D],
            delay: delay_ticks,
            next: 0,
        })
    }

    /// Its delay (ticks).
    pub fn delay_ticks(&self) -> usize {
        self.delay
    }

    /// Send `value` this tick; what arrives this tick, sent `delay` ticks
    /// ago.
    #[inline]
    pub fn pass(&mut self, value: T) -> T {
        if self.delay == 0 {
            return value;
        }
        let out = self.arriving();
        self.send(value);
        out
    }

    /// What arrives this tick, sent `delay` ticks ago (a channel of at
    /// least one tick: what is sent this tick is not yet there).
    #[inline]
    pub fn arriving(&self) -> T {
        self.ring[self.next]
    }

    /// Send `value` this tick, after reading what arrives (a channel of
    /// at least one tick).
    #[inline]
    pub fn send(&mut self, value: T) {
        if self.delay > 0 {
            self.ring[self.next] = value;
            self.next = (self.next + 1) % self.delay;
        }
    }

    /// Empty it: it holds `value` again until what is sent next arrives.
    pub fn reset(&mut self, value: T) {
        self.ring = [value; D];
        self.next = 0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_value_arrives_delay_ticks_later() {
        let mut c = Channel::<i32, 8>::new(3, -1).unwrap();
        let got: [i32; 6] = core::array::from_fn(|k| c.pass(k as i32));
        assert_eq!(got, [-1, -1, -1, 0, 1, 2]);
        let mut none = Channel::<i32, 8>::new(0, -1).unwrap();
        assert_eq!(none.pass(7), 7);
        assert!(Channel::<i32, 8>::new(9, 0).is_none());
        c.reset(5);
        assert_eq!([c.pass(9), c.pass(9), c.pass(9), c.pass(9)], [5, 5, 5, 9]);
    }
}
