#![doc = include_str!("../README.md")]
#![warn(missing_docs)]
// The C boundary: raw pointers in and out are its whole job. Each unsafe
// block says what the caller's contract (in `include/twoport.h`) makes
// sound.

mod types;

use std::cell::RefCell;
use std::ffi::{c_char, CStr, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::time::Duration;
use twoport_host::{
    BoardPort, Contact, Gains, HostBoard, LinkError, Pace, PcBoard, SerialBoard, SimulatedBoard,
};
pub use types::{
    TpAxisSpec, TpDisplay, TpLoopTiming, TpMode, TpPercentiles, TpResult, TpSpec, TpState,
    TP_CONTACT_ABOVE, TP_CONTACT_BELOW, TP_CONTACT_FREE, TP_CONTACT_HELD, TP_MAX_AXES,
    TP_VE_DAMPING, TP_VE_STIFFNESS, TP_VE_SURFACE,
};

/// A board, opened by `tp_board_open_serial`, `tp_board_open_simulated`
/// or `tp_board_open_pc_simulated` and freed by `tp_board_close`. Use it
/// from one thread at a time (any thread).
pub struct TpBoard(HostBoard<Box<dyn BoardPort + Send>>);

thread_local! {
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

/// Keep `e` as this thread's last error and say which kind it was.
fn fail(e: &LinkError) -> TpResult {
    let msg = CString::new(e.to_string().replace('\0', " ")).unwrap_or_default();
    LAST_ERROR.with(|l| *l.borrow_mut() = msg);
    match e {
        LinkError::Refused { .. } | LinkError::GainsRefused(_) => TpResult::Refused,
        LinkError::Axes { .. } | LinkError::OutOfRange { .. } | LinkError::BadValue { .. } => {
            TpResult::Argument
        }
        LinkError::Timeout { .. } => TpResult::Timeout,
        LinkError::Reset(_) | LinkError::Foreign { .. } => TpResult::Reset,
        LinkError::Faulted(_) => TpResult::Faulted,
        _ => TpResult::Link,
    }
}

/// An argument error, kept as this thread's last error.
fn bad(what: &str) -> TpResult {
    LAST_ERROR.with(|l| *l.borrow_mut() = CString::new(what).unwrap_or_default());
    TpResult::Argument
}

/// Run `f`, turning a panic into `TpResult::Panic`: no unwind crosses into
/// C.
fn guard(f: impl FnOnce() -> TpResult) -> TpResult {
    catch_unwind(AssertUnwindSafe(f)).unwrap_or_else(|_| {
        LAST_ERROR.with(|l| {
            *l.borrow_mut() =
                CString::new("twoport: internal error (a panic), caught").unwrap_or_default()
        });
        TpResult::Panic
    })
}

/// `f` on the board behind `b`, or `Argument` for a null board.
fn with_board(b: *mut TpBoard, f: impl FnOnce(&mut TpBoard) -> TpResult) -> TpResult {
    guard(|| {
        // SAFETY: a non-null `b` came from `tp_board_open_*` and has not
        // been closed, and the caller uses it from one thread at a time
        // (the header's contract), so this is the only reference.
        match unsafe { b.as_mut() } {
            Some(b) => f(b),
            None => bad("the board is NULL"),
        }
    })
}

/// The `n` values at `p`, or `None` for a null pointer with `n > 0`.
///
/// # Safety
/// A non-null `p` points to `n` readable values.
unsafe fn slice<'a, T>(p: *const T, n: usize) -> Option<&'a [T]> {
    match (p.is_null(), n) {
        (_, 0) => Some(&[]),
        (true, _) => None,
        // SAFETY: the caller's contract above.
        (false, n) => Some(unsafe { std::slice::from_raw_parts(p, n) }),
    }
}

/// Open `result` into `out`.
fn opened(
    result: Result<HostBoard<Box<dyn BoardPort + Send>>, LinkError>,
    out: *mut *mut TpBoard,
) -> TpResult {
    if out.is_null() {
        return bad("out is NULL");
    }
    match result {
        Ok(b) => {
            // SAFETY: `out` is non-null and, by the header's contract,
            // points to a writable `TpBoard *`.
            unsafe { *out = Box::into_raw(Box::new(TpBoard(b))) };
            TpResult::Ok
        }
        Err(e) => fail(&e),
    }
}

/// The message of this thread's last error: valid until this thread's
/// next call into twoport; never NULL (empty when there was none).
#[no_mangle]
pub extern "C" fn tp_last_error() -> *const c_char {
    LAST_ERROR.with(|l| l.borrow().as_ptr())
}

/// Open the board of `axes` axes at the serial port `path` (a real board,
/// or the firmware in QEMU through its pty): handshake and specification.
/// On success `*out` is the board, which `tp_board_close` frees.
///
/// # Safety
/// `path` is a NUL-terminated string; `out` points to a writable pointer.
#[no_mangle]
pub unsafe extern "C" fn tp_board_open_serial(
    path: *const c_char,
    axes: u8,
    out: *mut *mut TpBoard,
) -> TpResult {
    guard(|| {
        if path.is_null() {
            return bad("path is NULL");
        }
        // SAFETY: `path` is non-null and NUL-terminated (the contract).
        let Ok(path) = unsafe { CStr::from_ptr(path) }.to_str() else {
            return bad("path is not UTF-8");
        };
        let port = SerialBoard::open(path).map(|p| Box::new(p) as Box<dyn BoardPort + Send>);
        opened(port.and_then(|p| HostBoard::open(p, axes)), out)
    })
}

/// Open the shipped Excalibur image on a simulated device in this
/// process, ticking with the wall clock, the hand pushing `hand_n` (N)
/// along +x while the board's outputs are on: an application tried with
/// no hardware.
///
/// # Safety
/// `out` points to a writable pointer.
#[no_mangle]
pub unsafe extern "C" fn tp_board_open_simulated(hand_n: f32, out: *mut *mut TpBoard) -> TpResult {
    guard(|| {
        let port = SimulatedBoard::excalibur(hand_n, Pace::RealTime)
            .map(|p| Box::new(p) as Box<dyn BoardPort + Send>);
        opened(port.and_then(|p| HostBoard::open(p, 1)), out)
    })
}

/// Open the Excalibur's PC image (its region proven for up to 5 ms from
/// sample to force) on the PC's loop, in a thread of its own, against a simulated device exchanged with as a USB device is (the
/// path a Falcon or a Haply board takes), the hand pushing `hand_n` (N)
/// along +x while the outputs are on.
///
/// # Safety
/// `out` points to a writable pointer.
#[no_mangle]
pub unsafe extern "C" fn tp_board_open_pc_simulated(
    hand_n: f32,
    out: *mut *mut TpBoard,
) -> TpResult {
    guard(|| {
        let port =
            PcBoard::excalibur_simulated(hand_n).map(|p| Box::new(p) as Box<dyn BoardPort + Send>);
        opened(port.and_then(|p| HostBoard::open(p, 1)), out)
    })
}

/// Open the device `name` (`"haply-2diy"`, `"falcon"` or `"touch"`, as
/// `twoport devices` lists them) at `path` (a serial port; a Touch's name
/// in Touch Setup, "" for the default one), its image running in this
/// computer's servo loop; `firmware` is the Falcon's firmware file
/// (Novint's, not shipped), or a Touch's HD library where it is not the
/// system's (NULL otherwise). Each failure says what to do
/// (`tp_last_error`).
///
/// # Safety
/// `name` and `path` are NUL-terminated strings, `firmware` one or NULL;
/// `out` points to a writable pointer.
#[no_mangle]
pub unsafe extern "C" fn tp_board_open_device(
    name: *const c_char,
    path: *const c_char,
    firmware: *const c_char,
    out: *mut *mut TpBoard,
) -> TpResult {
    // SAFETY: the same contract, with no reason given.
    unsafe { tp_board_open_device_unproven(name, path, firmware, core::ptr::null(), out) }
}

/// `tp_board_open_device`, its image accepting gains outside its proven
/// region where `unproven_gains` (NULL: refused) says why: the user's
/// explicit choice, which the loop logs.
///
/// # Safety
/// As `tp_board_open_device`'s; `unproven_gains` is a NUL-terminated
/// string or NULL.
#[no_mangle]
pub unsafe extern "C" fn tp_board_open_device_unproven(
    name: *const c_char,
    path: *const c_char,
    firmware: *const c_char,
    unproven_gains: *const c_char,
    out: *mut *mut TpBoard,
) -> TpResult {
    guard(|| {
        let text = |p: *const c_char| {
            // SAFETY: `p` is non-null and NUL-terminated (the contract).
            (!p.is_null()).then(|| unsafe { CStr::from_ptr(p) })
        };
        let (Some(name), Some(path)) = (text(name), text(path)) else {
            return bad("name and path must not be NULL");
        };
        let (Ok(name), Ok(path)) = (name.to_str(), path.to_str()) else {
            return bad("name and path must be UTF-8");
        };
        let firmware = text(firmware).map(|f| std::path::PathBuf::from(&*f.to_string_lossy()));
        let why = text(unproven_gains).map(|w| w.to_string_lossy().into_owned());
        let port =
            twoport_host::attached::open_with(name, path, firmware.as_deref(), why.as_deref())
                .map(|(p, n)| (Box::new(p) as Box<dyn BoardPort + Send>, n));
        opened(port.and_then(|(p, n)| HostBoard::open(p, n)), out)
    })
}

/// Where the device `name`'s image calibrates (rad, a joint each): write
/// it to `rest_rad`, which has room for `n` (at least the device's axes),
/// and its axes to `axes`. Hold the handle there and calibrate there
/// (`tp_board_calibrate`) after `tp_board_open_device`.
///
/// # Safety
/// `name` is a NUL-terminated string; `rest_rad` points to `n` writable
/// doubles and `axes` to a writable `size_t`.
#[no_mangle]
pub unsafe extern "C" fn tp_device_rest_pose(
    name: *const c_char,
    rest_rad: *mut f64,
    n: usize,
    axes: *mut usize,
) -> TpResult {
    guard(|| {
        if name.is_null() || rest_rad.is_null() || axes.is_null() {
            return bad("name, rest_rad and axes must not be NULL");
        }
        // SAFETY: `name` is non-null and NUL-terminated (the contract).
        let Ok(name) = unsafe { CStr::from_ptr(name) }.to_str() else {
            return bad("name must be UTF-8");
        };
        let rest = match twoport_host::attached::rest_pose(name) {
            Ok(r) => r,
            Err(e) => return fail(&e),
        };
        if rest.len() > n {
            return bad(&format!(
                "{name} has {} axes: rest_rad holds {n}",
                rest.len()
            ));
        }
        // SAFETY: `rest_rad` has room for `n` doubles and `axes` for one
        // `size_t` (the contract); `rest.len() <= n`.
        unsafe {
            for (i, q) in rest.iter().enumerate() {
                rest_rad.add(i).write(*q);
            }
            axes.write(rest.len());
        }
        TpResult::Ok
    })
}

/// Disarm the board and free it. NULL is ignored. The board must not be
/// used after.
///
/// # Safety
/// `b` is NULL or a board from `tp_board_open_*` not closed before.
#[no_mangle]
pub unsafe extern "C" fn tp_board_close(b: *mut TpBoard) -> TpResult {
    guard(|| {
        if b.is_null() {
            return TpResult::Ok;
        }
        // SAFETY: `b` came from `Box::into_raw` in `opened` and is closed
        // once (the contract).
        let board = unsafe { Box::from_raw(b) };
        match board.0.close() {
            Ok(()) => TpResult::Ok,
            Err(e) => fail(&e),
        }
    })
}

/// The board's specification, as it said when opened.
///
/// # Safety
/// `b` is an open board; `out` points to a writable `TpSpec`.
#[no_mangle]
pub unsafe extern "C" fn tp_board_spec(b: *mut TpBoard, out: *mut TpSpec) -> TpResult {
    with_board(b, |b| {
        // SAFETY: `out`, if non-null, points to a writable TpSpec.
        match unsafe { out.as_mut() } {
            Some(out) => {
                *out = TpSpec::from(b.0.spec());
                TpResult::Ok
            }
            None => bad("out is NULL"),
        }
    })
}

/// The servo loop's timing, where it runs on this computer (a board
/// opened with `tp_board_open_pc_simulated`, or a device's driver); a
/// board that runs its own loop reports its timing in its state instead,
/// and this answers `TP_ARGUMENT`.
///
/// # Safety
/// `b` is an open board; `out` points to a writable `TpLoopTiming`.
#[no_mangle]
pub unsafe extern "C" fn tp_board_loop_timing(b: *mut TpBoard, out: *mut TpLoopTiming) -> TpResult {
    with_board(b, |b| {
        // SAFETY: `out`, if non-null, points to a writable TpLoopTiming.
        let Some(out) = (unsafe { out.as_mut() }) else {
            return bad("out is NULL");
        };
        match b.0.port().loop_timing() {
            Some(t) => {
                *out = TpLoopTiming::from(&t);
                TpResult::Ok
            }
            None => bad("the board runs its own loop: its state has its timing"),
        }
    })
}

/// Tell a disarmed board where each of its `n` axes stands (m).
///
/// # Safety
/// `b` is an open board; `position_m` points to `n` doubles.
#[no_mangle]
pub unsafe extern "C" fn tp_board_calibrate(
    b: *mut TpBoard,
    position_m: *const f64,
    n: usize,
) -> TpResult {
    with_board(b, |b| {
        // SAFETY: the contract: `n` doubles at `position_m`.
        let Some(x) = (unsafe { slice(position_m, n) }) else {
            return bad("position_m is NULL");
        };
        b.0.calibrate(x).map_or_else(|e| fail(&e), |_| TpResult::Ok)
    })
}

/// Home a disarmed board onto its stops; wait up to `timeout_s` (s).
///
/// # Safety
/// `b` is an open board.
#[no_mangle]
pub unsafe extern "C" fn tp_board_home(b: *mut TpBoard, timeout_s: f64) -> TpResult {
    with_board(b, |b| {
        if !(timeout_s.is_finite() && timeout_s >= 0.0) {
            return bad("timeout_s is not a time");
        }
        let t = Duration::from_secs_f64(timeout_s.min(3600.0));
        b.0.home(t).map_or_else(|e| fail(&e), |_| TpResult::Ok)
    })
}

/// Arm: the coupling runs and the force comes on.
///
/// # Safety
/// `b` is an open board.
#[no_mangle]
pub unsafe extern "C" fn tp_board_arm(b: *mut TpBoard) -> TpResult {
    with_board(b, |b| b.0.arm().map_or_else(|e| fail(&e), |_| TpResult::Ok))
}

/// Disarm: zero force at once.
///
/// # Safety
/// `b` is an open board.
#[no_mangle]
pub unsafe extern "C" fn tp_board_disarm(b: *mut TpBoard) -> TpResult {
    with_board(b, |b| {
        b.0.disarm().map_or_else(|e| fail(&e), |_| TpResult::Ok)
    })
}

/// Clear latched faults (the board stays disarmed).
///
/// # Safety
/// `b` is an open board.
#[no_mangle]
pub unsafe extern "C" fn tp_board_clear_faults(b: *mut TpBoard) -> TpResult {
    with_board(b, |b| {
        b.0.clear_faults()
            .map_or_else(|e| fail(&e), |_| TpResult::Ok)
    })
}

/// Set every axis's impedance coupling: stiffness `k_npm[i]` (N/m) and
/// damping `b_nspm[i]` (N s/m) for `n` axes. All or none: a coupling past
/// the proven region is refused (`TP_RESULT_REFUSED`, the limit in
/// `tp_last_error`).
///
/// # Safety
/// `b` is an open board; `k_npm` and `b_nspm` point to `n` doubles.
#[no_mangle]
pub unsafe extern "C" fn tp_board_set_impedance(
    b: *mut TpBoard,
    k_npm: *const f64,
    b_nspm: *const f64,
    n: usize,
) -> TpResult {
    with_board(b, |b| {
        // SAFETY: the contract: `n` doubles at each.
        let (Some(k), Some(d)) = (unsafe { slice(k_npm, n) }, unsafe { slice(b_nspm, n) }) else {
            return bad("k_npm or b_nspm is NULL");
        };
        let g: Vec<Gains> = k
            .iter()
            .zip(d)
            .map(|(k, d)| Gains::impedance(*k as f32, *d as f32))
            .collect();
        b.0.set_gains(&g)
            .map_or_else(|e| fail(&e), |_| TpResult::Ok)
    })
}

/// Stream the state every `every_ticks` ticks (0: none).
///
/// # Safety
/// `b` is an open board.
#[no_mangle]
pub unsafe extern "C" fn tp_board_stream(b: *mut TpBoard, every_ticks: u32) -> TpResult {
    with_board(b, |b| {
        b.0.stream(every_ticks)
            .map_or_else(|e| fail(&e), |_| TpResult::Ok)
    })
}

/// Read what the board has sent without waiting long, and feed its
/// watchdog: call it at least every 20 ms while armed. `*n_new` (if not
/// NULL) is the states read.
///
/// # Safety
/// `b` is an open board; `n_new` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn tp_board_poll(b: *mut TpBoard, n_new: *mut usize) -> TpResult {
    with_board(b, |b| match b.0.poll() {
        Ok(n) => {
            // SAFETY: `n_new`, if non-null, is writable (the contract).
            if let Some(out) = unsafe { n_new.as_mut() } {
                *out = n;
            }
            TpResult::Ok
        }
        Err(e) => fail(&e),
    })
}

/// The newest streamed state; `TP_RESULT_ARGUMENT` if none has come.
///
/// # Safety
/// `b` is an open board; `out` points to a writable `TpState`.
#[no_mangle]
pub unsafe extern "C" fn tp_board_latest(b: *mut TpBoard, out: *mut TpState) -> TpResult {
    with_board(b, |b| {
        // SAFETY: `out`, if non-null, points to a writable TpState.
        let Some(out) = (unsafe { out.as_mut() }) else {
            return bad("out is NULL");
        };
        match b.0.latest() {
            Some(s) => {
                *out = TpState::from(s);
                TpResult::Ok
            }
            None => bad("no state has been streamed yet"),
        }
    })
}

/// Move up to `cap` of the oldest buffered states into `buf`, oldest
/// first; `*n` is how many. The rest stay for the next call.
///
/// # Safety
/// `b` is an open board; `buf` points to `cap` writable `TpState`s; `n`
/// is writable.
#[no_mangle]
pub unsafe extern "C" fn tp_board_take_states(
    b: *mut TpBoard,
    buf: *mut TpState,
    cap: usize,
    n: *mut usize,
) -> TpResult {
    with_board(b, |b| {
        if n.is_null() || (buf.is_null() && cap > 0) {
            return bad("buf or n is NULL");
        }
        let states = b.0.take_states_up_to(cap);
        for (i, s) in states.iter().enumerate() {
            // SAFETY: `i < cap`, and `buf` holds `cap` writable states.
            unsafe { buf.add(i).write(TpState::from(s)) };
        }
        // SAFETY: `n` is non-null and writable (the contract).
        unsafe { n.write(states.len()) };
        TpResult::Ok
    })
}

/// Run the VE on the host (disarmed only): each `tp_board_send_ve` moves
/// each axis's surface over `ramp_ticks` ticks; an armed board that runs
/// more than `deadline_ticks` ticks on one update faults to zero force.
///
/// # Safety
/// `b` is an open board.
#[no_mangle]
pub unsafe extern "C" fn tp_board_host_ve(
    b: *mut TpBoard,
    ramp_ticks: u32,
    deadline_ticks: u32,
) -> TpResult {
    with_board(b, |b| {
        b.0.host_ve(ramp_ticks, deadline_ticks)
            .map_or_else(|e| fail(&e), |_| TpResult::Ok)
    })
}

/// Give the VE back to the board's image (disarmed only).
///
/// # Safety
/// `b` is an open board.
#[no_mangle]
pub unsafe extern "C" fn tp_board_board_ve(b: *mut TpBoard) -> TpResult {
    with_board(b, |b| {
        b.0.board_ve().map_or_else(|e| fail(&e), |_| TpResult::Ok)
    })
}

/// Set one parameter of the board's own VE on `axis` (disarmed only):
/// `TP_VE_SURFACE` (m), `TP_VE_STIFFNESS` (N/m) or `TP_VE_DAMPING` (N s/m)
/// to `value`. A value out of range, an axis the board has not or a
/// parameter its VE has not is refused (`tp_last_error` says which).
///
/// # Safety
/// `b` is an open board.
#[no_mangle]
pub unsafe extern "C" fn tp_board_set_ve_param(
    b: *mut TpBoard,
    axis: usize,
    param: u8,
    value: f64,
) -> TpResult {
    use twoport_host::VeParam;
    with_board(b, |b| {
        let setting = match param {
            TP_VE_SURFACE => VeParam::surface_m(value),
            TP_VE_STIFFNESS => VeParam::stiffness_npm(value),
            TP_VE_DAMPING => VeParam::damping_nspm(value),
            _ => return bad("param is not TP_VE_SURFACE, TP_VE_STIFFNESS or TP_VE_DAMPING"),
        };
        match setting {
            Ok(p) => {
                b.0.set_ve_param(axis, p)
                    .map_or_else(|e| fail(&e), |_| TpResult::Ok)
            }
            Err(e) => bad(&e.to_string()),
        }
    })
}

/// Send the host VE's surface for each of `n` axes (m) and what each is
/// (`TP_CONTACT_HELD`, `TP_CONTACT_ABOVE`, `TP_CONTACT_BELOW`,
/// `TP_CONTACT_FREE`);
/// `*seq` (if not NULL) is the update's number, which the states'
/// `ve_seq` echo once the board holds it.
///
/// # Safety
/// `b` is an open board; `position_m` and `contact` point to `n` values
/// each; `seq` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn tp_board_send_ve(
    b: *mut TpBoard,
    position_m: *const f64,
    contact: *const u8,
    n: usize,
    seq: *mut u32,
) -> TpResult {
    with_board(b, |b| {
        // SAFETY: the contract: `n` values at each.
        let (Some(x), Some(c)) = (unsafe { slice(position_m, n) }, unsafe {
            slice(contact, n)
        }) else {
            return bad("position_m or contact is NULL");
        };
        let Some(c) = c
            .iter()
            .map(|c| types::contact(*c))
            .collect::<Option<Vec<Contact>>>()
        else {
            return bad("a contact is not one of TP_CONTACT_HELD, _ABOVE, _BELOW, _FREE");
        };
        match b.0.send_ve(x, &c) {
            Ok(s) => {
                // SAFETY: `seq`, if non-null, is writable (the contract).
                if let Some(out) = unsafe { seq.as_mut() } {
                    *out = s;
                }
                TpResult::Ok
            }
            Err(e) => fail(&e),
        }
    })
}
