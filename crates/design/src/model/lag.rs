//! A model's measurement-to-actuation delay at one sample period.

/// The measurement-to-actuation delay of a model at one sample period:
/// `ticks` whole ticks and a `fraction` of one more, `0 <= fraction < 1`.
/// The force a tick computes is applied from `(ticks + fraction) T` after
/// its sample, and held one period.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lag {
    /// Whole ticks.
    pub ticks: u32,
    /// The part of a tick on top, `α` in `[0, 1)`.
    pub fraction: f64,
}

impl Lag {
    /// No delay at all.
    pub const NONE: Lag = Lag {
        ticks: 0,
        fraction: 0.0,
    };

    /// A latency of `latency_s` (s) at sample period `period_s` (s), split
    /// into whole ticks and a fraction. A latency within a part in 1e9 of a
    /// whole number of ticks is that number (a period's rounding must not
    /// make a tick of `0.999...`).
    pub fn of(latency_s: f64, period_s: f64) -> Lag {
        let ticks = latency_s / period_s;
        let mut whole = ticks.floor();
        let mut fraction = ticks - whole;
        if fraction > 1.0 - 1e-9 {
            (whole, fraction) = (whole + 1.0, 0.0);
        } else if fraction < 1e-9 {
            fraction = 0.0;
        }
        Lag {
            ticks: whole as u32,
            fraction,
        }
    }
}
