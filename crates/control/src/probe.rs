//! Measuring a stepped law's frequency response, without trigonometry or
//! allocation, so that the same check runs on the host and on the target.

use num_complex::Complex64;

/// A single-bin DFT of a law's input and output under the excitation
/// `cos(θk)`: drive the law with [`SineProbe::excitation`], pass what it
/// really took and gave to [`SineProbe::record`] (or [`SineProbe::skip`]
/// while it settles), and read [`SineProbe::response`]. Over a whole number
/// of periods, constants (a law's DC offset) drop out of the bin exactly.
#[derive(Clone, Copy, Debug)]
pub struct SineProbe {
    rotation: Complex64,
    phase: Complex64,
    input: Complex64,
    output: Complex64,
}

impl SineProbe {
    /// A probe at the normalised frequency `θ = ωT` (rad/sample) given by
    /// its cosine and sine.
    pub fn new(cos_theta: f64, sin_theta: f64) -> Self {
        SineProbe {
            rotation: Complex64::new(cos_theta, sin_theta),
            phase: Complex64::new(1.0, 0.0),
            input: Complex64::new(0.0, 0.0),
            output: Complex64::new(0.0, 0.0),
        }
    }

    /// This tick's excitation `cos(θk)`.
    pub fn excitation(&self) -> f64 {
        self.phase.re
    }

    /// Accumulate this tick's real input and output, then advance.
    pub fn record(&mut self, input: f64, output: f64) {
        let w = self.phase.conj();
        self.input += w * input;
        self.output += w * output;
        self.skip();
    }

    /// Advance one tick without accumulating.
    pub fn skip(&mut self) {
        self.phase *= self.rotation;
    }

    /// Output over input at this bin.
    pub fn response(&self) -> Complex64 {
        self.output / self.input
    }

    /// The whole measurement: drive `tick` with `cos(θk)` for `settle`
    /// ticks unrecorded, then `window` ticks recorded (make it a whole number
    /// of periods); `tick` returns the (input, output) it really had.
    pub fn measure(
        cos_theta: f64,
        sin_theta: f64,
        settle: u32,
        window: u32,
        mut tick: impl FnMut(f64) -> (f64, f64),
    ) -> Complex64 {
        let mut probe = SineProbe::new(cos_theta, sin_theta);
        for k in 0..settle + window {
            let (i, o) = tick(probe.excitation());
            if k >= settle {
                probe.record(i, o);
            } else {
                probe.skip();
            }
        }
        probe.response()
    }
}
