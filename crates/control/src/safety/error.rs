//! A refusal that names the axis.

use crate::ParamError;
use core::fmt;

/// A limit or gain refused on one axis of a multi-axis layer or servo.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AxisError<E = ParamError> {
    /// The axis (0 is x).
    pub axis: usize,
    /// What is wrong with it.
    pub error: E,
}

impl<E> AxisError<E> {
    /// `error` on axis `axis`.
    pub const fn new(axis: usize, error: E) -> Self {
        AxisError { axis, error }
    }
}

impl<E: fmt::Display> fmt::Display for AxisError<E> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "axis {}: {}", self.axis, self.error)
    }
}

impl<E: fmt::Debug + fmt::Display> core::error::Error for AxisError<E> {}
