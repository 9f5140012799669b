//! An identification experiment: a periodic multisine force on one axis,
//! the device held near where it started by a weak spring-damper on every
//! axis, for a whole number of periods.
//!
//! The hold is an [`ImpedanceCoupling`] to a fixed point, the same law
//! and the same z-domain form ([`ImpedanceCoupling::tf`]) as the display's
//! coupling with its VE held still: a board runs it only where its gains
//! lie inside the axis's proven region, so the loop is proven stable for
//! any passive hand while the experiment runs.
//!
//! The force is the paper's `f_a` (positive resists positive motion), so
//! the excitation, which pushes the device toward `+x`, enters with a
//! minus sign: `f_a = k (x - x_0) + b v - e[n]`.

use crate::multisine::Multisine;
use crate::{ImpedanceCoupling, ParamError, Position};

/// One experiment of a device of `N` axes.
#[derive(Clone, Copy, Debug)]
pub struct Experiment<const N: usize> {
    axis: usize,
    excitation: Multisine,
    hold: ImpedanceCoupling,
    centre: [Position; N],
    tick: u32,
    ticks: u32,
}

impl<const N: usize> Experiment<N> {
    /// Play `excitation` on `axis` for `periods` whole periods, holding
    /// every axis near `centre` with `hold`. Refused: an axis the device
    /// does not have, no period, or a length past `u32::MAX` ticks.
    pub fn new(
        axis: usize,
        excitation: Multisine,
        hold: ImpedanceCoupling,
        periods: u32,
        centre: [Position; N],
    ) -> Result<Self, ParamError> {
        if axis >= N {
            return Err(ParamError {
                name: "experiment axis",
                value: axis as f32,
                problem: "must be one of the device's axes",
            });
        }
        let ticks = excitation
            .period_ticks()
            .checked_mul(periods)
            .filter(|t| *t > 0)
            .ok_or(ParamError {
                name: "experiment periods",
                value: periods as f32,
                problem: "must be at least 1, and the run at most 2^32 ticks",
            })?;
        Ok(Experiment {
            axis,
            excitation,
            hold,
            centre,
            tick: 0,
            ticks,
        })
    }

    /// The axis excited.
    pub fn axis(&self) -> usize {
        self.axis
    }

    /// The excitation.
    pub fn excitation(&self) -> &Multisine {
        &self.excitation
    }

    /// The hold: its gains and its z-domain form.
    pub fn hold(&self) -> &ImpedanceCoupling {
        &self.hold
    }

    /// Ticks played so far.
    pub fn tick(&self) -> u32 {
        self.tick
    }

    /// Ticks the whole experiment takes.
    pub fn ticks(&self) -> u32 {
        self.ticks
    }

    /// Whether every period has been played.
    pub fn done(&self) -> bool {
        self.tick >= self.ticks
    }

    /// This tick's push on the excited axis (N, toward `+x`); zero once
    /// done.
    pub fn excitation_n(&self) -> f32 {
        if self.done() {
            0.0
        } else {
            self.excitation.at(self.tick)
        }
    }

    /// This tick's force on `axis` at position `x` and velocity `v_mps`
    /// (N, `f_a`): the hold, and on the excited axis the excitation.
    pub fn force(&self, axis: usize, x: Position, v_mps: f32) -> f32 {
        let Some(c) = self.centre.get(axis) else {
            return 0.0;
        };
        let hold = self.hold.port(x.minus_m(*c), v_mps).f0_n;
        if axis == self.axis {
            hold - self.excitation_n()
        } else {
            hold
        }
    }

    /// On to the next tick.
    pub fn advance(&mut self) {
        self.tick = self.tick.saturating_add(1);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn experiment() -> Experiment<2> {
        let e = Multisine::new(100, 1, 20, 3.0).unwrap();
        let hold = ImpedanceCoupling::new(500.0, 5.0, 1e-3).unwrap();
        let centre = [Position::from_nm(1000), Position::from_nm(-2000)];
        Experiment::new(0, e, hold, 3, centre).unwrap()
    }

    /// The excited axis gets the hold minus the excitation, the other the
    /// hold alone, each about its own centre; after the last period, the
    /// hold alone.
    #[test]
    fn the_force_is_the_hold_and_the_excitation() {
        let mut x = experiment();
        assert_eq!(x.ticks(), 300);
        let at = Position::from_nm(3000);
        for n in 0..300 {
            let e = x.excitation().at(n);
            let f0 = x.force(0, at, 0.01);
            // 500 N/m over 2 um, 5 N s/m at 10 mm/s.
            assert!((f0 - (500.0 * 2e-6 + 0.05 - e)).abs() < 1e-5, "{n}: {f0}");
            let f1 = x.force(1, at, 0.0);
            assert!((f1 - 500.0 * 5e-6).abs() < 1e-6, "{f1}");
            assert!(!x.done());
            x.advance();
        }
        assert!(x.done());
        assert_eq!(x.excitation_n(), 0.0);
        assert!((x.force(0, at, 0.0) - 500.0 * 2e-6).abs() < 1e-6);
        assert_eq!(x.force(7, at, 0.0), 0.0);
    }

    #[test]
    fn an_axis_the_device_lacks_or_no_period_is_refused() {
        let e = Multisine::new(100, 1, 20, 3.0).unwrap();
        let hold = ImpedanceCoupling::new(500.0, 5.0, 1e-3).unwrap();
        let c = [Position::ZERO; 2];
        assert!(Experiment::new(2, e, hold, 3, c).is_err());
        assert!(Experiment::new(0, e, hold, 0, c).is_err());
        assert!(Experiment::new(0, e, hold, u32::MAX, c).is_err());
    }
}
