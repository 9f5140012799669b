//! An open device: its servo frame, its motors' output, and the
//! library's scheduler running a closure.

use crate::consts::*;
use crate::library::HdLibrary;
use crate::HdError;
use core::ffi::{c_ulong, c_void};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::Arc;

/// The doubles any `hdGet*v` parameter writes, at most (a transform's
/// sixteen): every read gives the library this much room.
const ROOM: usize = 16;

/// A device the library has opened (`HHD`); disabled when dropped.
pub struct HdDevice {
    lib: Arc<HdLibrary>,
    handle: Hhd,
}

/// What a servo frame read.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HdFrame {
    /// The first three joints' angles (rad), as `HD_CURRENT_JOINT_ANGLES`
    /// gives them.
    pub joint_rad: [f64; 3],
    /// The buttons, a bit each (`HD_DEVICE_BUTTON_1` ...).
    pub buttons: i32,
}

impl HdDevice {
    pub(crate) fn new(lib: Arc<HdLibrary>, handle: Hhd) -> Self {
        HdDevice { lib, handle }
    }

    /// Its handle.
    pub fn handle(&self) -> Hhd {
        self.handle
    }

    /// One servo frame: the first three joints' torques (mN m, as
    /// `HD_CURRENT_JOINT_TORQUE` takes them) out, the joints' angles and
    /// the buttons in. Call it from the scheduler's thread (a closure
    /// [`HdDevice::schedule`] runs).
    pub fn frame(&self, torque_mnm: [f64; 3]) -> Result<HdFrame, HdError> {
        let c = &self.lib.calls;
        let mut q = [0.0f64; ROOM];
        let mut b = [0i32; ROOM];
        // SAFETY: the handle is the library's, open until `self` drops;
        // each read has `ROOM` values of room, more than the parameter
        // writes (three doubles, one integer), and the write reads the
        // three doubles `torque_mnm` holds.
        unsafe {
            (c.begin_frame)(self.handle);
            (c.get_doublev)(HD_CURRENT_JOINT_ANGLES, q.as_mut_ptr());
            (c.get_integerv)(HD_CURRENT_BUTTONS, b.as_mut_ptr());
            (c.set_doublev)(HD_CURRENT_JOINT_TORQUE, torque_mnm.as_ptr());
            (c.end_frame)(self.handle);
        }
        self.lib.check("the servo frame")?;
        let joint_rad = [q[0], q[1], q[2]];
        if joint_rad.iter().any(|a| !a.is_finite()) {
            return Err(HdError::Value(format!(
                "the library gave joint angles {joint_rad:?} rad: not a device's"
            )));
        }
        Ok(HdFrame {
            joint_rad,
            buttons: b[0],
        })
    }

    /// Enable or disable the motors' output (`HD_FORCE_OUTPUT`).
    pub fn force_output(&self, on: bool) -> Result<(), HdError> {
        let c = &self.lib.calls;
        // SAFETY: the handle is the library's, open until `self` drops;
        // the capability is one `hdDefines.h` lists.
        unsafe {
            (c.make_current_device)(self.handle);
            if on {
                (c.enable)(HD_FORCE_OUTPUT);
            } else {
                (c.disable)(HD_FORCE_OUTPUT);
            }
        }
        self.lib.check(if on { "hdEnable" } else { "hdDisable" })
    }

    /// Run `tick` in the library's servo scheduler, at `rate_hz`, at the
    /// greatest priority, until it returns `false` or the [`Scheduled`]
    /// is dropped. A `tick` that panics is not called again.
    pub fn schedule(
        &self,
        rate_hz: u32,
        tick: impl FnMut() -> bool + Send + 'static,
    ) -> Result<Scheduled, HdError> {
        let c = &self.lib.calls;
        let boxed: Box<Tick> = Box::new(Box::new(tick));
        let data = Box::into_raw(boxed);
        // SAFETY: `trampoline` is a callback of the type `hdScheduler.h`
        // declares; `data` stays valid until `Scheduled` drops, after the
        // scheduler has stopped and the callback is unscheduled.
        let handle = unsafe {
            (c.set_scheduler_rate)(c_ulong::from(rate_hz));
            let handle =
                (c.schedule_asynchronous)(trampoline, data.cast(), HD_MAX_SCHEDULER_PRIORITY);
            (c.start_scheduler)();
            handle
        };
        let scheduled = Scheduled {
            lib: Arc::clone(&self.lib),
            handle,
            data: data as usize,
        };
        self.lib.check("hdStartScheduler")?;
        Ok(scheduled)
    }
}

impl Drop for HdDevice {
    fn drop(&mut self) {
        // SAFETY: the handle is the library's and is disabled once.
        unsafe { (self.lib.calls.disable_device)(self.handle) };
    }
}

type Tick = Box<dyn FnMut() -> bool + Send>;

extern "C" fn trampoline(data: *mut c_void) -> u32 {
    // SAFETY: `data` is the `Box<Tick>` `schedule` made, alive until the
    // callback is unscheduled, and the scheduler calls it from one thread
    // at a time.
    let tick = unsafe { &mut *data.cast::<Tick>() };
    match catch_unwind(AssertUnwindSafe(tick)) {
        Ok(true) => HD_CALLBACK_CONTINUE,
        _ => HD_CALLBACK_DONE,
    }
}

/// A closure the library's scheduler runs: dropping it stops the
/// scheduler, unschedules the closure and drops it.
pub struct Scheduled {
    lib: Arc<HdLibrary>,
    handle: c_ulong,
    // (The `Box<Tick>`'s address: an integer, so that this is `Send`.)
    data: usize,
}

impl Drop for Scheduled {
    fn drop(&mut self) {
        let c = &self.lib.calls;
        // SAFETY: the scheduler is stopped before the callback is
        // unscheduled, and both before its data is freed, which happens
        // once: `hdStopScheduler` returns when the scheduler's thread no
        // longer runs callbacks.
        unsafe {
            (c.stop_scheduler)();
            (c.unschedule)(self.handle);
            drop(Box::from_raw(self.data as *mut Tick));
        }
    }
}
