//! Checked construction parameters: every law refuses a gain that is not a
//! finite number in its range, and says which one.

use core::fmt;

/// A law parameter that was refused: which one, its value, and why.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParamError {
    /// The parameter's name with its unit, e.g. `"k_c (N/m)"`.
    pub name: &'static str,
    /// The refused value.
    pub value: f32,
    /// What is wrong, e.g. `"must be finite and > 0"`.
    pub problem: &'static str,
}

impl fmt::Display for ParamError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} = {} {}", self.name, self.value, self.problem)
    }
}

impl core::error::Error for ParamError {}

/// `value` if finite and > 0.
pub(crate) fn positive(name: &'static str, value: f32) -> Result<f32, ParamError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(ParamError {
            name,
            value,
            problem: "must be finite and > 0",
        })
    }
}

/// `value` if finite and >= 0.
pub(crate) fn non_negative(name: &'static str, value: f32) -> Result<f32, ParamError> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(ParamError {
            name,
            value,
            problem: "must be finite and >= 0",
        })
    }
}

/// `value`, if finite (either sign).
pub(crate) fn finite(name: &'static str, value: f32) -> Result<f32, ParamError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(ParamError {
            name,
            value,
            problem: "must be finite",
        })
    }
}
