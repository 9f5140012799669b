//! Why a record could not be identified.

/// Why a record could not be identified.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum IdentifyError {
    /// The signals' lengths differ.
    #[error("{what}: {len} samples, but the force has {force}")]
    Length {
        /// The signal.
        what: &'static str,
        /// Its length.
        len: usize,
        /// The force's.
        force: usize,
    },
    /// Fewer whole periods than an estimate with a variance needs.
    #[error("{periods} whole periods after the {skipped} skipped: at least 2 are needed (a period is {period} samples)")]
    TooShort {
        /// Whole periods left.
        periods: usize,
        /// Periods skipped for the transient.
        skipped: usize,
        /// Samples a period.
        period: usize,
    },
    /// A sample that is not a number.
    #[error("{what}[{at}] = {value}: not a finite number")]
    NotFinite {
        /// The signal.
        what: &'static str,
        /// The sample's index.
        at: usize,
        /// Its value.
        value: f64,
    },
    /// An excited harmonic with no force in it.
    #[error("harmonic {harmonic} ({hz:.3} Hz): the force has no component there (|F| = {force:.3e} N); the excitation does not reach it")]
    NoExcitation {
        /// The harmonic.
        harmonic: usize,
        /// Its frequency (Hz).
        hz: f64,
        /// The force's amplitude there (N).
        force: f64,
    },
    /// A record file that cannot be read: where, and why.
    #[error("{place}: {why}")]
    Log {
        /// The file, and the line where there is one.
        place: String,
        /// What is wrong there.
        why: String,
    },
    /// A harmonic at or past Nyquist, or a period too short.
    #[error("harmonic {harmonic} of a {period}-sample period: must be between 1 and {max}")]
    Harmonic {
        /// The harmonic.
        harmonic: usize,
        /// Samples a period.
        period: usize,
        /// The largest allowed.
        max: usize,
    },
    /// The force was held at its largest value for consecutive samples:
    /// the amplifier or the board's limit cut the excitation, and the
    /// response is not the device's alone.
    #[error("the force is clipped: {samples} samples sit at its largest value, {force_n:.4} N, the first run at t = {at_s:.4} s; lower the excitation's peak")]
    Clipped {
        /// Samples at the extreme.
        samples: usize,
        /// The extreme (N, signed).
        force_n: f64,
        /// Where the first run of them starts (s).
        at_s: f64,
    },
    /// The record's response gives out power: no passive device does, so
    /// the force's sign or the encoder's is reversed.
    #[error("the response gives out power where a passive device absorbs it: the actuator's mobility v/F has a negative real part at {negative} of {harmonics} harmonics below a fifth of Nyquist (their weighted mean -{share:.3} of its size, {sigmas:.0} standard deviations): the force's sign or the encoder's is reversed. The force must push the actuator toward +x, the way its encoder counts up: turn the sign of one of them (the amplifier's, the motor's leads, or the encoder's direction) and record again")]
    ReversedSign {
        /// Harmonics with a negative real part.
        negative: usize,
        /// Harmonics weighed.
        harmonics: usize,
        /// The weighted mean of `-Re Y/|Y|`.
        share: f64,
        /// How many standard deviations below zero its evidence is.
        sigmas: f64,
    },
    /// The pose's records are not what a linear body gives: its fit
    /// leaves residuals far past their noise.
    #[error("the records are not what a linear body at one pose gives: the fit leaves {misfit:.1} times their noise (at most {most} is taken); friction that sticks, or a push that moves the handle far enough to change the pose, does this: push harder against friction, softer against the pose, or hold the handle stiffer")]
    NotLinear {
        /// `χ²/ν` of the fit.
        misfit: f64,
        /// The most taken.
        most: f64,
    },
    /// An axis's best fit leaves a misfit far past the record's noise: the
    /// device is not one the fit's class holds, or the record is too poor
    /// to tell.
    #[error("the best fit ({modes} modes) leaves {misfit:.1} times the record's noise (at most {most} is taken): no model of the fit's class explains this device, so none is written. A delay the record does not show elsewhere, friction that sticks under the excitation, more than one spring to the frame, a structure with branches the load cell does not sit on, or a sensor's scale wrong does this; so does too little excitation where the coherence is low. Check the device against docs/identification.md, record again with a larger excitation or more periods, or with the load cell")]
    Misfit {
        /// Modes of the best fit.
        modes: usize,
        /// Its `χ²/ν`.
        misfit: f64,
        /// The most taken.
        most: f64,
    },
    /// The record gives no more values than the chosen fit has
    /// parameters.
    #[error("the record gives {values} values (two a harmonic, and the load cell's) for a fit of {parameters} parameters: nothing is left to tell the model from the noise; excite more harmonics (a multisine over the band the design needs, up to a fifth of the sampling rate)")]
    TooFewHarmonics {
        /// Values the record gives.
        values: usize,
        /// Parameters of the fit.
        parameters: usize,
    },
    /// The played band stops short of what a design needs to see.
    #[error("the excitation stops at {top_hz:.1} Hz: a fit sees only the band played, and a design needs the device's response to at least a fifth of the sampling rate ({needed_hz:.1} Hz), where a coupling's proof often binds and where the modes that limit it sit. Play the multisine up to {needed_hz:.1} Hz or higher")]
    NarrowBand {
        /// The highest harmonic played (Hz).
        top_hz: f64,
        /// The least top a record must reach (Hz).
        needed_hz: f64,
    },
    /// No fit of any order converged.
    #[error("no model of 0 to {most} modes fits the record")]
    NoFit {
        /// The most modes tried.
        most: usize,
    },
    /// No body with a positive definite mass fits the records.
    #[error("no body with a positive mass in every direction fits the records")]
    NoBody,
}
