//! The servo scheduler: a thread calling each scheduled callback once a
//! millisecond until it says it is done.

use core::ffi::{c_ulong, c_void};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Mutex, MutexGuard};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};
use twoport_hd::{HdCallback, HD_CALLBACK_DONE};

struct Scheduler {
    callbacks: Vec<(c_ulong, HdCallback, usize)>,
    next: c_ulong,
    thread: Option<JoinHandle<()>>,
}

static SCHEDULER: Mutex<Scheduler> = Mutex::new(Scheduler {
    callbacks: Vec::new(),
    next: 1,
    thread: None,
});
static STOP: AtomicBool = AtomicBool::new(false);
/// The device stopped answering: the scheduler calls nothing.
static SILENT: AtomicBool = AtomicBool::new(false);

fn scheduler() -> MutexGuard<'static, Scheduler> {
    SCHEDULER.lock().unwrap_or_else(|p| p.into_inner())
}

pub fn silence(on: bool) {
    SILENT.store(on, Ordering::Relaxed);
}

pub fn add(callback: HdCallback, data: usize) -> c_ulong {
    let mut s = scheduler();
    let handle = s.next;
    s.next += 1;
    s.callbacks.push((handle, callback, data));
    handle
}

pub fn remove(handle: c_ulong) {
    scheduler().callbacks.retain(|c| c.0 != handle);
}

pub fn start() {
    let mut s = scheduler();
    if s.thread.is_some() {
        return;
    }
    STOP.store(false, Ordering::Relaxed);
    s.thread = std::thread::Builder::new()
        .name("hd-standin-servo".into())
        .spawn(run)
        .ok();
}

pub fn stop() {
    STOP.store(true, Ordering::Relaxed);
    let thread = scheduler().thread.take();
    if let Some(t) = thread {
        let _ = t.join();
    }
}

fn run() {
    let period = Duration::from_millis(1);
    let mut next = Instant::now();
    while !STOP.load(Ordering::Relaxed) {
        let now = Instant::now();
        if next > now {
            std::thread::sleep(next - now);
        }
        next = Instant::now().max(next) + period;
        if SILENT.load(Ordering::Relaxed) {
            continue;
        }
        let due: Vec<_> = scheduler().callbacks.clone();
        for (handle, callback, data) in due {
            if callback(data as *mut c_void) == HD_CALLBACK_DONE {
                remove(handle);
            }
        }
    }
}
