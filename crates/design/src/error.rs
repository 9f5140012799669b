//! The designer's one error type.

use thiserror::Error;

/// Why the designer refused a question, naming the input that is wrong.
#[derive(Clone, Debug, PartialEq, Error)]
#[non_exhaustive]
pub enum Error {
    /// A model file could not be read or is not a device.
    #[error(transparent)]
    Model(#[from] crate::ModelError),
    /// A law's parameter is out of its range.
    #[error("{0}")]
    Param(#[from] twoport_control::ParamError),
    /// A host loop that cannot be: a zero VE period or delay.
    #[error("host VE: {0}")]
    HostLoop(String),
    /// No pose was given.
    #[error("no device model was given")]
    NoPose,
    /// Poses of one board with different periods.
    #[error("{} has period_s = {} but {} has {}: poses share one board, give one period", .other.0, .other.1, .first.0, .first.1)]
    PeriodsDiffer {
        /// The first pose's model name and period (s).
        first: (String, f64),
        /// The first that differs.
        other: (String, f64),
    },
    /// A period that is not a positive time.
    #[error("period {0}: must be a positive number of seconds")]
    Period(f64),
    /// A model whose dynamics do not discretise.
    #[error("{model}: {why}")]
    Dynamics {
        /// The model's name.
        model: String,
        /// What its dynamics refused.
        why: String,
    },
    /// An admittance display asked of a device without a force sensor.
    #[error("{0}: the model has no force sensor (no C_f), and an admittance display needs one to measure the hand's force; design an impedance display instead")]
    NoForceSensor(String),
    /// An admittance design with no impedance design to take `K_p` from.
    #[error("no impedance design exists to take K_p from (eq 30); give kp and bp")]
    NoRegulator,
    /// A gain that is negative or not finite.
    #[error("{name} {value}: must be a finite number >= 0")]
    Gain {
        /// The gain's name (as the designer's calls and the command line
        /// name it).
        name: &'static str,
        /// Its value.
        value: f64,
    },
    /// A design margin out of range.
    #[error("margin {0}: must be a fraction from 0 to 0.9")]
    Margin(f64),
    /// A region's damping range or point count out of range.
    #[error("a region needs 0 < b_from < b_to (N s/m) and 2..=1000 points")]
    RegionGrid,
    /// Gains that make no coupling.
    #[error("{0}")]
    Coupling(String),
    /// A matrix exponential that cannot be taken (a non-finite or huge
    /// argument: dynamics far faster than the sample period).
    #[error("{0}")]
    Exponential(String),
    /// A controller transfer function whose leading denominator term is 0.
    #[error("a controller transfer function is not causal")]
    NotCausal,
    /// A figure could not be computed from the design.
    #[error("{0}")]
    Figure(String),
    /// A figure could not be drawn or written.
    #[error("{0}")]
    Plot(String),
    /// A linkage whose workspace holds no pose the kinematics drive.
    #[error("{0}: no pose inside the joint limits (and the relative ones) is one the kinematics drive: check joints.limits_rad, joints.relative and the geometry")]
    NoReachablePose(String),
    /// A host whose rate does not divide the servo's.
    #[error("ve_rate {ve_rate_hz} Hz: the servo's rate (a period of {servo_period_s} s) is not a whole multiple of it")]
    HostRate {
        /// The host's VE rate (Hz).
        ve_rate_hz: f64,
        /// The servo's period (s).
        servo_period_s: f64,
    },
    /// A host delay that is not a time above zero.
    #[error("host_delay {0}: must be a time > 0 s")]
    HostDelay(f64),
    /// A teleoperator that cannot be proven as asked: a law reading a
    /// load cell a device lacks, a loop that cannot be built.
    #[error("teleoperator: {0}")]
    Teleop(String),
    /// The counterexample search could not run on a pose.
    #[error("{model}: {why}")]
    Verify {
        /// The pose's model name.
        model: String,
        /// Why.
        why: String,
    },
}
