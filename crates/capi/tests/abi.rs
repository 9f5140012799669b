//! The C ABI called as C calls it, against the simulated board in this
//! process: the spec's protocol-9 fields and the board's own VE's
//! parameters, with bad arguments refused and named.

use std::ffi::CStr;
use std::ptr::null_mut;
use twoport::*;

fn last_error() -> String {
    // SAFETY: tp_last_error always returns a valid, NUL-terminated string
    // owned by this thread.
    unsafe { CStr::from_ptr(tp_last_error()) }
        .to_string_lossy()
        .into_owned()
}

#[test]
fn the_spec_and_the_boards_own_ve_through_the_c_abi() {
    let mut b: *mut TpBoard = null_mut();
    // SAFETY: `b` is a valid place for the board's pointer.
    assert_eq!(
        unsafe { tp_board_open_simulated(2.0, &mut b) },
        TpResult::Ok
    );
    let mut spec = std::mem::MaybeUninit::<TpSpec>::uninit();
    // SAFETY: `b` is open and `spec` is a writable TpSpec.
    assert_eq!(unsafe { tp_board_spec(b, spec.as_mut_ptr()) }, TpResult::Ok);
    // SAFETY: tp_board_spec wrote it.
    let spec = unsafe { spec.assume_init() };
    // The shipped image states neither its travel nor its link's rate.
    assert_eq!(
        (spec.link_bytes_per_s, spec.axis[0].has_workspace),
        (0, false)
    );
    // SAFETY (each call below): `b` is open.
    let set = |p, v| unsafe { tp_board_set_ve_param(b, 0, p, v) };
    assert_eq!(set(9, 1.0), TpResult::Argument);
    assert!(last_error().contains("TP_VE_SURFACE"), "{}", last_error());
    assert_eq!(set(TP_VE_STIFFNESS, -1.0), TpResult::Argument);
    assert!(
        last_error().contains("VE stiffness (N/m) = -1 must be finite and >= 0"),
        "{}",
        last_error()
    );
    assert_eq!(set(TP_VE_SURFACE, 0.005), TpResult::Ok);
    assert_eq!(set(TP_VE_DAMPING, 100.0), TpResult::Ok);
    // SAFETY: `b` is open.
    assert_eq!(
        unsafe { tp_board_set_ve_param(b, 1, TP_VE_DAMPING, 1.0) },
        TpResult::Argument
    );
    // SAFETY: `b` is open; closing frees it.
    assert_eq!(unsafe { tp_board_close(b) }, TpResult::Ok);
    // SAFETY: a NULL board is refused, not read.
    assert_eq!(
        unsafe { tp_board_set_ve_param(null_mut(), 0, TP_VE_DAMPING, 1.0) },
        TpResult::Argument
    );
}

/// The PC's loop opens through the C ABI as a board does, and says what
/// it is: the Excalibur image at 1 ms on one axis; its loop's timing is
/// read through the C ABI too, ordered, once it has ticked.
#[test]
fn the_pc_loop_opens_through_the_c_abi() {
    let mut b: *mut TpBoard = null_mut();
    // SAFETY: `b` is a valid place for the board's pointer.
    assert_eq!(
        unsafe { tp_board_open_pc_simulated(2.0, &mut b) },
        TpResult::Ok
    );
    let mut spec = std::mem::MaybeUninit::<TpSpec>::uninit();
    // SAFETY: `b` is open and `spec` is a writable TpSpec.
    assert_eq!(unsafe { tp_board_spec(b, spec.as_mut_ptr()) }, TpResult::Ok);
    // SAFETY: tp_board_spec wrote it.
    let spec = unsafe { spec.assume_init() };
    assert_eq!((spec.period_s, spec.axes), (1e-3, 1));
    let mut t = TpLoopTiming::default();
    while t.ticks < 3 {
        std::thread::sleep(std::time::Duration::from_millis(5));
        // SAFETY: `b` is open and `t` is a writable TpLoopTiming.
        assert_eq!(unsafe { tp_board_loop_timing(b, &mut t) }, TpResult::Ok);
    }
    for p in [t.period_s, t.io_s, t.latency_s] {
        assert!(0.0 <= p.p50 && p.p50 <= p.p99 && p.p99 <= p.max, "{t:?}");
    }
    // SAFETY: a NULL `out` is refused, not written.
    assert_eq!(
        unsafe { tp_board_loop_timing(b, null_mut()) },
        TpResult::Argument
    );
    // SAFETY: `b` is open; closing frees it (and stops the loop).
    assert_eq!(unsafe { tp_board_close(b) }, TpResult::Ok);
    // A board that runs its own loop has no PC loop to time.
    let mut b: *mut TpBoard = null_mut();
    // SAFETY: `b` is a valid place for the board's pointer.
    assert_eq!(
        unsafe { tp_board_open_simulated(2.0, &mut b) },
        TpResult::Ok
    );
    // SAFETY: `b` is open and `t` is a writable TpLoopTiming.
    assert_eq!(
        unsafe { tp_board_loop_timing(b, &mut t) },
        TpResult::Argument
    );
    // SAFETY: `b` is open; closing frees it.
    assert_eq!(unsafe { tp_board_close(b) }, TpResult::Ok);
}

/// A device's rest pose by name: written where there is room for it,
/// refused, naming the room, where there is not; an unknown device, and
/// one opened with a reason for unproven gains but not there, are named.
#[test]
fn a_devices_rest_pose_and_open_by_name_through_the_c_abi() {
    let mut rest = [0.0f64; TP_MAX_AXES];
    let mut axes = 0usize;
    // SAFETY: NUL-terminated names; `rest` holds `TP_MAX_AXES` doubles.
    let r =
        unsafe { tp_device_rest_pose(c"touch".as_ptr(), rest.as_mut_ptr(), rest.len(), &mut axes) };
    assert_eq!((r, axes), (TpResult::Ok, 3));
    let want = twoport_board::linkage::touch::TOUCH.rest_rad.map(f64::from);
    assert_eq!(rest, want);
    // SAFETY: as above, with room for one.
    let r = unsafe { tp_device_rest_pose(c"falcon".as_ptr(), rest.as_mut_ptr(), 1, &mut axes) };
    assert_eq!(r, TpResult::Argument);
    assert!(last_error().contains("3 axes"), "{}", last_error());
    // SAFETY: as above.
    let r =
        unsafe { tp_device_rest_pose(c"omni".as_ptr(), rest.as_mut_ptr(), rest.len(), &mut axes) };
    assert_ne!(r, TpResult::Ok);
    assert!(
        last_error().contains("haply-2diy, falcon, touch"),
        "{}",
        last_error()
    );
    let mut b = null_mut();
    // SAFETY: NUL-terminated strings; `b` is a writable pointer.
    let r = unsafe {
        tp_board_open_device_unproven(
            c"haply-2diy".as_ptr(),
            c"/dev/twoport-no-such-port".as_ptr(),
            std::ptr::null(),
            c"a study".as_ptr(),
            &mut b,
        )
    };
    assert_ne!(r, TpResult::Ok);
    assert!(b.is_null());
    assert!(last_error().contains("no such port"), "{}", last_error());
}
