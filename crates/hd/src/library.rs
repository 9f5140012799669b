//! Loading the library and resolving its documented calls.

use crate::consts::*;
use crate::device::HdDevice;
use crate::HdError;
use core::ffi::{c_char, c_ulong, c_void};
use libloading::Library;
use std::ffi::CString;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The library's calls this crate makes, as `hd.h` and `hdScheduler.h`
/// declare them.
pub(crate) struct Calls {
    pub init_device: unsafe extern "C" fn(*const c_char) -> Hhd,
    pub disable_device: unsafe extern "C" fn(Hhd),
    pub make_current_device: unsafe extern "C" fn(Hhd),
    pub begin_frame: unsafe extern "C" fn(Hhd),
    pub end_frame: unsafe extern "C" fn(Hhd),
    pub get_doublev: unsafe extern "C" fn(u32, *mut f64),
    pub get_integerv: unsafe extern "C" fn(u32, *mut i32),
    pub set_doublev: unsafe extern "C" fn(u32, *const f64),
    pub enable: unsafe extern "C" fn(u32),
    pub disable: unsafe extern "C" fn(u32),
    pub get_error: unsafe extern "C" fn() -> HdErrorInfo,
    pub start_scheduler: unsafe extern "C" fn(),
    pub stop_scheduler: unsafe extern "C" fn(),
    pub set_scheduler_rate: unsafe extern "C" fn(c_ulong),
    pub schedule_asynchronous: unsafe extern "C" fn(HdCallback, *mut c_void, u16) -> c_ulong,
    pub unschedule: unsafe extern "C" fn(c_ulong),
}

/// OpenHaptics' HD library, loaded.
pub struct HdLibrary {
    pub(crate) calls: Calls,
    path: PathBuf,
    // (Last: the calls point into it.)
    _library: Library,
}

/// The library's file name where the system's loader looks for it.
#[cfg(windows)]
pub const DEFAULT_NAME: &str = "hd.dll";
/// The library's file name where the system's loader looks for it.
#[cfg(not(windows))]
pub const DEFAULT_NAME: &str = "libHD.so";

impl HdLibrary {
    /// Load the library at `path`, or the system's `libHD.so` (`hd.dll`
    /// on Windows) where the loader finds it.
    pub fn load(path: Option<&Path>) -> Result<Arc<Self>, HdError> {
        let path = path.map_or_else(|| PathBuf::from(DEFAULT_NAME), Path::to_path_buf);
        let shown = path.display().to_string();
        // SAFETY: loading runs the library's initialisers; OpenHaptics'
        // (or a stand-in's) are those of an ordinary shared library, with
        // no preconditions on the loading process.
        let library = unsafe { Library::new(&path) }.map_err(|e| HdError::NoLibrary {
            path: shown.clone(),
            why: e.to_string(),
        })?;
        macro_rules! call {
            ($name:literal) => {{
                // SAFETY: the symbol is the HD API's call of that name,
                // whose C signature `hd.h` (or `hdScheduler.h`) declares
                // as the field's type; the pointer stays valid while
                // `library` is loaded, which `HdLibrary` holds.
                let symbol = unsafe { library.get(concat!($name, "\0").as_bytes()) };
                *symbol.map_err(|_| HdError::MissingCall {
                    path: shown.clone(),
                    symbol: $name,
                })?
            }};
        }
        let calls = Calls {
            init_device: call!("hdInitDevice"),
            disable_device: call!("hdDisableDevice"),
            make_current_device: call!("hdMakeCurrentDevice"),
            begin_frame: call!("hdBeginFrame"),
            end_frame: call!("hdEndFrame"),
            get_doublev: call!("hdGetDoublev"),
            get_integerv: call!("hdGetIntegerv"),
            set_doublev: call!("hdSetDoublev"),
            enable: call!("hdEnable"),
            disable: call!("hdDisable"),
            get_error: call!("hdGetError"),
            start_scheduler: call!("hdStartScheduler"),
            stop_scheduler: call!("hdStopScheduler"),
            set_scheduler_rate: call!("hdSetSchedulerRate"),
            schedule_asynchronous: call!("hdScheduleAsynchronous"),
            unschedule: call!("hdUnschedule"),
        };
        Ok(Arc::new(HdLibrary {
            calls,
            path,
            _library: library,
        }))
    }

    /// Where it was loaded from.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Open the device Touch Setup named `name` (`None`: the default
    /// device).
    pub fn init_device(self: &Arc<Self>, name: Option<&str>) -> Result<HdDevice, HdError> {
        let name = name
            .map(|n| CString::new(n).map_err(|_| HdError::Name(n.to_string())))
            .transpose()?;
        let ptr = name.as_ref().map_or(core::ptr::null(), |n| n.as_ptr());
        // SAFETY: `ptr` is null (the default device, as `hd.h` allows) or
        // a NUL-terminated string that outlives the call.
        let handle = unsafe { (self.calls.init_device)(ptr) };
        self.check("hdInitDevice")?;
        if handle == HD_INVALID_HANDLE {
            return Err(HdError::Value(
                "hdInitDevice gave no device and no error".into(),
            ));
        }
        Ok(HdDevice::new(Arc::clone(self), handle))
    }

    /// The library's latest error, as `call`'s.
    pub(crate) fn check(&self, call: &'static str) -> Result<(), HdError> {
        // SAFETY: `hdGetError` takes nothing and returns its record by
        // value.
        let e = unsafe { (self.calls.get_error)() };
        if e.error_code == HD_SUCCESS {
            Ok(())
        } else {
            Err(HdError::Call {
                call,
                code: e.error_code,
                internal: e.internal_error_code,
            })
        }
    }
}
