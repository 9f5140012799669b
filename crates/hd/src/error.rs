//! What goes wrong with the HD library, each with what to do about it.

use crate::consts::*;
use thiserror::Error;

/// Why a call to the HD library failed.
#[derive(Clone, Debug, PartialEq, Eq, Error)]
#[non_exhaustive]
pub enum HdError {
    /// The library would not load.
    #[error(
        "OpenHaptics' HD library ({path}) would not load: {why}. Install OpenHaptics \
         (3D Systems' Touch device drivers and the OpenHaptics developer edition), or give \
         the library's path"
    )]
    NoLibrary {
        /// Where it was looked for.
        path: String,
        /// What the system's loader said.
        why: String,
    },
    /// The library lacks a documented call.
    #[error("the HD library at {path} has no {symbol}: it is not OpenHaptics' HD library")]
    MissingCall {
        /// The library's path.
        path: String,
        /// The call.
        symbol: &'static str,
    },
    /// A device name with a NUL byte in it.
    #[error("device name {0:?}: it has a NUL byte")]
    Name(String),
    /// A call reported an error.
    #[error("{call}: {} (internal code {internal}){}", name(*code), advice(*code))]
    Call {
        /// The call that reported it.
        call: &'static str,
        /// The `HD_` error code.
        code: HdErrorCode,
        /// The device's code behind it.
        internal: i32,
    },
    /// The library answered with a value no device gives.
    #[error("{0}")]
    Value(String),
}

impl HdError {
    /// The `HD_` error code, for an error a call reported.
    pub fn code(&self) -> Option<HdErrorCode> {
        match self {
            HdError::Call { code, .. } => Some(*code),
            _ => None,
        }
    }
}

fn name(code: HdErrorCode) -> String {
    code_name(code).map_or_else(|| format!("HD error {code:#06x}"), str::to_string)
}

/// What a lab does about an error code.
fn advice(code: HdErrorCode) -> &'static str {
    match code {
        HD_COMM_CONFIG_ERROR => {
            ": the library could not reach the device as configured. Is it plugged in and \
             set up in Touch Setup? May this user open its port (on Linux, the dialout group: \
             sudo usermod -aG dialout $USER, then log in again)?"
        }
        HD_DEVICE_ALREADY_INITIATED => {
            ": the device is open already, by another program or by this one: close the \
             other program"
        }
        HD_COMM_ERROR => {
            ": the device stopped answering (unplugged, or its USB cable or power lost); \
             plug it in again and reopen it"
        }
        HD_DEVICE_FAULT => {
            ": the device reported a fault: reopen it, and power it off and on if it persists"
        }
        HD_WARM_MOTORS => ": the motors are too hot: let them cool before reopening",
        HD_TIMER_ERROR => ": the library's servo loop missed its time (the machine is loaded)",
        HD_INVALID_LICENSE => ": OpenHaptics' licence is missing or expired",
        HD_EXCEEDED_MAX_FORCE
        | HD_EXCEEDED_MAX_FORCE_IMPULSE
        | HD_EXCEEDED_MAX_VELOCITY
        | HD_FORCE_ERROR => ": the library's own safety limit tripped",
        _ => "",
    }
}
