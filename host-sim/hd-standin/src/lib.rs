#![doc = include_str!("../README.md")]
// The C ABI's pointers are read and written here, each with its SAFETY
// line; nothing else is unsafe.
#![warn(missing_docs)]

mod scenario;
mod scheduler;

use core::ffi::{c_char, c_ulong, c_void};
use host_sim::emulate::{EmulatedDevice, Fault};
use scenario::Scenario;
use std::ffi::CStr;
use std::sync::{Mutex, MutexGuard};
use twoport_board::linkage::touch::TOUCH;
use twoport_design::linkage::LinkageFile;
use twoport_hd::*;

/// The one device this library opens.
const HANDLE: Hhd = 1;

/// An open device: the simulated arm and what the frames set.
struct Open {
    device: EmulatedDevice<3>,
    scenario: Scenario,
    force_on: bool,
    angles_rad: [f64; 3],
    torque_mnm: [f64; 3],
}

/// The library's state: the device, once open, and the errors not yet
/// read.
#[derive(Default)]
struct State {
    open: Option<Open>,
    errors: Vec<HdErrorInfo>,
}

static STATE: Mutex<State> = Mutex::new(State {
    open: None,
    errors: Vec::new(),
});

fn state() -> MutexGuard<'static, State> {
    STATE.lock().unwrap_or_else(|p| p.into_inner())
}

impl State {
    fn fail(&mut self, code: HdErrorCode, internal: i32) {
        self.errors.push(HdErrorInfo {
            error_code: code,
            internal_error_code: internal,
            hhd: HANDLE,
        });
    }
}

fn touch_file() -> Result<LinkageFile, String> {
    LinkageFile::from_toml(
        include_str!("../../../models/linkages/touch.toml"),
        "touch.toml",
    )
    .map_err(|e| e.to_string())
}

/// `hdInitDevice`: open the simulated Touch, `name` its scenario.
///
/// # Safety
/// `name` is null or a NUL-terminated string.
#[no_mangle]
pub unsafe extern "C" fn hdInitDevice(name: *const c_char) -> Hhd {
    let text = if name.is_null() {
        String::new()
    } else {
        // SAFETY: the caller passes a NUL-terminated string (hd.h).
        unsafe { CStr::from_ptr(name) }
            .to_string_lossy()
            .into_owned()
    };
    let mut s = state();
    let scenario = match Scenario::parse(&text) {
        Ok(sc) => sc,
        Err(_) => {
            s.fail(HD_INVALID_VALUE, 0);
            return HD_INVALID_HANDLE;
        }
    };
    if let Some(code) = scenario.refuse_open {
        s.fail(code, 0);
        return HD_INVALID_HANDLE;
    }
    if s.open.is_some() {
        s.fail(HD_DEVICE_ALREADY_INITIATED, 0);
        return HD_INVALID_HANDLE;
    }
    let device = touch_file()
        .map_err(host_sim::Error::Sim)
        .and_then(|f| EmulatedDevice::new(&f, TOUCH, true, scenario.hand, None));
    match device {
        Ok(device) => {
            device.note("open");
            s.open = Some(Open {
                device,
                scenario,
                force_on: false,
                angles_rad: TOUCH.rest_rad.map(f64::from),
                torque_mnm: [0.0; 3],
            });
            HANDLE
        }
        Err(_) => {
            s.fail(HD_DEVICE_FAULT, 0);
            HD_INVALID_HANDLE
        }
    }
}

/// `hdDisableDevice`: the motors off, the trace written where the
/// scenario says, the device closed.
#[no_mangle]
pub extern "C" fn hdDisableDevice(handle: Hhd) {
    let mut s = state();
    if handle != HANDLE {
        return s.fail(HD_BAD_HANDLE, 0);
    }
    if let Some(open) = s.open.take() {
        open.device.note("disabled");
        if let Some(path) = &open.scenario.trace {
            let _ = std::fs::write(path, open.device.trace().to_json());
        }
    }
    scheduler::silence(false);
}

/// `hdMakeCurrentDevice`: there is one.
#[no_mangle]
pub extern "C" fn hdMakeCurrentDevice(handle: Hhd) {
    if handle != HANDLE {
        state().fail(HD_BAD_HANDLE, 0);
    }
}

/// `hdBeginFrame`: nothing to do before the frame's reads.
#[no_mangle]
pub extern "C" fn hdBeginFrame(handle: Hhd) {
    let mut s = state();
    if handle != HANDLE || s.open.is_none() {
        s.fail(HD_BAD_HANDLE, 0);
    }
}

/// `hdEndFrame`: the frame's torques held for one period of the arm.
#[no_mangle]
pub extern "C" fn hdEndFrame(handle: Hhd) {
    let mut s = state();
    let Some(open) = s.open.as_mut().filter(|_| handle == HANDLE) else {
        return s.fail(HD_BAD_HANDLE, 0);
    };
    let fault = open.scenario.fault.and_then(|(after, f)| {
        let (ticks, pressed_at) = open.device.ticks();
        pressed_at.filter(|p| ticks >= p + after).map(|_| f)
    });
    let code = match fault {
        Some(Fault::Unplug) => Some(HD_COMM_ERROR),
        Some(Fault::ShortReply) => Some(HD_DEVICE_FAULT),
        Some(Fault::Silent) => {
            scheduler::silence(true);
            None
        }
        _ => None,
    };
    if let Some(code) = code {
        return s.fail(code, 0);
    }
    let torque_nm = if open.force_on {
        open.torque_mnm.map(|t| (t * 1e-3) as f32)
    } else {
        [0.0; 3]
    };
    match open.device.tick(torque_nm) {
        Ok(p) => {
            let per_count = core::f64::consts::TAU / f64::from(TOUCH.hardware.counts_per_rev);
            open.angles_rad = core::array::from_fn(|i| {
                f64::from(TOUCH.rest_rad[i]) + f64::from(p.counts[i]) * per_count
            });
            if fault == Some(Fault::Garbled) {
                open.angles_rad[1] = f64::NAN;
            }
        }
        Err(e) => {
            open.device.note(e);
            s.fail(HD_DEVICE_FAULT, 0);
        }
    }
}

/// `hdGetDoublev`: the joints' angles (rad).
///
/// # Safety
/// `out` has room for the parameter's values (three here).
#[no_mangle]
pub unsafe extern "C" fn hdGetDoublev(param: u32, out: *mut f64) {
    let mut s = state();
    let values = match (&s.open, param) {
        (Some(open), HD_CURRENT_JOINT_ANGLES) => open.angles_rad,
        (None, _) => return s.fail(HD_INVALID_OPERATION, 0),
        _ => return s.fail(HD_INVALID_ENUM, 0),
    };
    for (i, v) in values.iter().enumerate() {
        // SAFETY: the caller gives room for the parameter's three values.
        unsafe { out.add(i).write(*v) };
    }
}

/// `hdGetIntegerv`: the buttons (the first held while a hand grips).
///
/// # Safety
/// `out` has room for the parameter's value.
#[no_mangle]
pub unsafe extern "C" fn hdGetIntegerv(param: u32, out: *mut i32) {
    let mut s = state();
    let value = match (&s.open, param) {
        (Some(open), HD_CURRENT_BUTTONS) => {
            i32::from(open.scenario.hand.is_some()) * HD_DEVICE_BUTTON_1
        }
        (None, _) => return s.fail(HD_INVALID_OPERATION, 0),
        _ => return s.fail(HD_INVALID_ENUM, 0),
    };
    // SAFETY: the caller gives room for the parameter's value.
    unsafe { out.write(value) };
}

/// `hdSetDoublev`: the joints' torques (mN m) for the frame's end.
///
/// # Safety
/// `values` holds the parameter's values (three here).
#[no_mangle]
pub unsafe extern "C" fn hdSetDoublev(param: u32, values: *const f64) {
    let mut s = state();
    let Some(open) = s.open.as_mut() else {
        return s.fail(HD_INVALID_OPERATION, 0);
    };
    if param != HD_CURRENT_JOINT_TORQUE {
        return s.fail(HD_INVALID_ENUM, 0);
    }
    for (i, t) in open.torque_mnm.iter_mut().enumerate() {
        // SAFETY: the caller passes the parameter's three values.
        *t = unsafe { values.add(i).read() };
    }
}

fn force_output(param: u32, on: bool) {
    let mut s = state();
    let Some(open) = s.open.as_mut() else {
        return s.fail(HD_INVALID_OPERATION, 0);
    };
    if param != HD_FORCE_OUTPUT {
        return s.fail(HD_INVALID_ENUM, 0);
    }
    if open.force_on != on {
        open.force_on = on;
        open.device.note(if on { "force on" } else { "force off" });
        if on {
            // The hand was holding the handle where the driver
            // calibrated; now that the board is armed, it presses.
            open.device.press();
        }
    }
}

/// `hdEnable(HD_FORCE_OUTPUT)`: the motors on.
#[no_mangle]
pub extern "C" fn hdEnable(param: u32) {
    force_output(param, true);
}

/// `hdDisable(HD_FORCE_OUTPUT)`: the motors off.
#[no_mangle]
pub extern "C" fn hdDisable(param: u32) {
    force_output(param, false);
}

/// `hdGetError`: the oldest error not yet read, or `HD_SUCCESS`.
#[no_mangle]
pub extern "C" fn hdGetError() -> HdErrorInfo {
    let mut s = state();
    if s.errors.is_empty() {
        HdErrorInfo::default()
    } else {
        s.errors.remove(0)
    }
}

/// `hdStartScheduler`.
#[no_mangle]
pub extern "C" fn hdStartScheduler() {
    scheduler::start();
}

/// `hdStopScheduler`: returns once no callback runs.
#[no_mangle]
pub extern "C" fn hdStopScheduler() {
    scheduler::stop();
}

/// `hdSetSchedulerRate`: 1 kHz is the one rate this library runs.
#[no_mangle]
pub extern "C" fn hdSetSchedulerRate(rate_hz: c_ulong) {
    if rate_hz != 1000 {
        state().fail(HD_INVALID_VALUE, 0);
    }
}

/// `hdScheduleAsynchronous`: `callback` with `data`, once a period from
/// the scheduler's start.
#[no_mangle]
pub extern "C" fn hdScheduleAsynchronous(
    callback: HdCallback,
    data: *mut c_void,
    _priority: u16,
) -> c_ulong {
    scheduler::add(callback, data as usize)
}

/// `hdUnschedule`.
#[no_mangle]
pub extern "C" fn hdUnschedule(handle: c_ulong) {
    scheduler::remove(handle);
}
