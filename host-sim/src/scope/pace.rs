//! Real time for a view: the wall time owed to a simulation, paid in
//! whole ticks.

/// Wall time owed to a run in real time (s). At most 0.2 s is owed: a
/// window that stalled (dragged, hidden) does not make the run leap.
#[derive(Clone, Copy, Debug, Default)]
pub struct Pacer {
    debt_s: f64,
}

impl Pacer {
    /// How many ticks of `period_s` (s) are due after `wall_s` (s) more
    /// wall time; they are counted as paid.
    pub fn due(&mut self, wall_s: f64, period_s: f64) -> usize {
        self.debt_s = (self.debt_s + wall_s).min(0.2);
        let n = (self.debt_s / period_s).floor().max(0.0);
        self.debt_s -= n * period_s;
        n as usize
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_are_paid_in_whole_and_the_rest_carried() {
        let mut p = Pacer::default();
        assert_eq!(p.due(2.5e-3, 1e-3), 2);
        assert_eq!(p.due(0.6e-3, 1e-3), 1);
        // A long stall owes 0.2 s at the most.
        assert_eq!(p.due(10.0, 1e-3), 200);
    }
}
