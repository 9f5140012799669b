//! The HD API's constants this crate uses, as OpenHaptics' `hdDefines.h`
//! and `hdScheduler.h` publish them.

/// A device handle (`HHD`).
pub type Hhd = u32;
/// An error code (`HDerror`).
pub type HdErrorCode = u32;

/// `HD_INVALID_HANDLE`: no device.
pub const HD_INVALID_HANDLE: Hhd = 0xFFFF_FFFF;

/// `HD_SUCCESS`.
pub const HD_SUCCESS: HdErrorCode = 0x0000;
/// `HD_INVALID_ENUM`.
pub const HD_INVALID_ENUM: HdErrorCode = 0x0100;
/// `HD_INVALID_VALUE`.
pub const HD_INVALID_VALUE: HdErrorCode = 0x0101;
/// `HD_INVALID_OPERATION`.
pub const HD_INVALID_OPERATION: HdErrorCode = 0x0102;
/// `HD_BAD_HANDLE`.
pub const HD_BAD_HANDLE: HdErrorCode = 0x0104;
/// `HD_WARM_MOTORS`: the motors are too hot.
pub const HD_WARM_MOTORS: HdErrorCode = 0x0200;
/// `HD_EXCEEDED_MAX_FORCE`.
pub const HD_EXCEEDED_MAX_FORCE: HdErrorCode = 0x0201;
/// `HD_EXCEEDED_MAX_FORCE_IMPULSE`.
pub const HD_EXCEEDED_MAX_FORCE_IMPULSE: HdErrorCode = 0x0202;
/// `HD_EXCEEDED_MAX_VELOCITY`.
pub const HD_EXCEEDED_MAX_VELOCITY: HdErrorCode = 0x0203;
/// `HD_FORCE_ERROR`.
pub const HD_FORCE_ERROR: HdErrorCode = 0x0204;
/// `HD_DEVICE_FAULT`.
pub const HD_DEVICE_FAULT: HdErrorCode = 0x0300;
/// `HD_DEVICE_ALREADY_INITIATED`: the device is open already.
pub const HD_DEVICE_ALREADY_INITIATED: HdErrorCode = 0x0301;
/// `HD_COMM_ERROR`: the device stopped talking.
pub const HD_COMM_ERROR: HdErrorCode = 0x0302;
/// `HD_COMM_CONFIG_ERROR`: the device could not be reached as configured.
pub const HD_COMM_CONFIG_ERROR: HdErrorCode = 0x0303;
/// `HD_TIMER_ERROR`: the servo loop missed its time.
pub const HD_TIMER_ERROR: HdErrorCode = 0x0304;
/// `HD_ILLEGAL_BEGIN`.
pub const HD_ILLEGAL_BEGIN: HdErrorCode = 0x0400;
/// `HD_ILLEGAL_END`.
pub const HD_ILLEGAL_END: HdErrorCode = 0x0401;
/// `HD_FRAME_ERROR`.
pub const HD_FRAME_ERROR: HdErrorCode = 0x0402;
/// `HD_SCHEDULER_FULL`.
pub const HD_SCHEDULER_FULL: HdErrorCode = 0x0501;
/// `HD_INVALID_LICENSE`.
pub const HD_INVALID_LICENSE: HdErrorCode = 0x0600;

/// `HD_CURRENT_BUTTONS`: one integer, a bit per button.
pub const HD_CURRENT_BUTTONS: u32 = 0x2000;
/// `HD_CURRENT_JOINT_ANGLES`: three doubles (rad).
pub const HD_CURRENT_JOINT_ANGLES: u32 = 0x2100;
/// `HD_CURRENT_JOINT_TORQUE`: three doubles (mN m), set.
pub const HD_CURRENT_JOINT_TORQUE: u32 = 0x2703;
/// `HD_FORCE_OUTPUT`: the motors' output, enabled or disabled.
pub const HD_FORCE_OUTPUT: u32 = 0x4000;
/// `HD_DEVICE_BUTTON_1`: the stylus's first button.
pub const HD_DEVICE_BUTTON_1: i32 = 1;

/// `HD_CALLBACK_DONE`: the scheduler drops the callback.
pub const HD_CALLBACK_DONE: u32 = 0;
/// `HD_CALLBACK_CONTINUE`: the scheduler calls it again next tick.
pub const HD_CALLBACK_CONTINUE: u32 = 1;
/// `HD_MAX_SCHEDULER_PRIORITY` (`USHRT_MAX`).
pub const HD_MAX_SCHEDULER_PRIORITY: u16 = u16::MAX;

/// `HDErrorInfo`: what `hdGetError` returns.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct HdErrorInfo {
    /// The `HD_` error code.
    pub error_code: HdErrorCode,
    /// The device's own code behind it.
    pub internal_error_code: i32,
    /// The device it concerns.
    pub hhd: Hhd,
}

/// A callback the scheduler runs (`HDSchedulerCallback`).
pub type HdCallback = extern "C" fn(user: *mut core::ffi::c_void) -> u32;

/// The name OpenHaptics gives an error code, where it is one this crate
/// knows.
pub fn code_name(code: HdErrorCode) -> Option<&'static str> {
    Some(match code {
        HD_SUCCESS => "HD_SUCCESS",
        HD_INVALID_ENUM => "HD_INVALID_ENUM",
        HD_INVALID_VALUE => "HD_INVALID_VALUE",
        HD_INVALID_OPERATION => "HD_INVALID_OPERATION",
        HD_BAD_HANDLE => "HD_BAD_HANDLE",
        HD_WARM_MOTORS => "HD_WARM_MOTORS",
        HD_EXCEEDED_MAX_FORCE => "HD_EXCEEDED_MAX_FORCE",
        HD_EXCEEDED_MAX_FORCE_IMPULSE => "HD_EXCEEDED_MAX_FORCE_IMPULSE",
        HD_EXCEEDED_MAX_VELOCITY => "HD_EXCEEDED_MAX_VELOCITY",
        HD_FORCE_ERROR => "HD_FORCE_ERROR",
        HD_DEVICE_FAULT => "HD_DEVICE_FAULT",
        HD_DEVICE_ALREADY_INITIATED => "HD_DEVICE_ALREADY_INITIATED",
        HD_COMM_ERROR => "HD_COMM_ERROR",
        HD_COMM_CONFIG_ERROR => "HD_COMM_CONFIG_ERROR",
        HD_TIMER_ERROR => "HD_TIMER_ERROR",
        HD_ILLEGAL_BEGIN => "HD_ILLEGAL_BEGIN",
        HD_ILLEGAL_END => "HD_ILLEGAL_END",
        HD_FRAME_ERROR => "HD_FRAME_ERROR",
        HD_SCHEDULER_FULL => "HD_SCHEDULER_FULL",
        HD_INVALID_LICENSE => "HD_INVALID_LICENSE",
        _ => return None,
    })
}
