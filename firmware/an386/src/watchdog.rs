//! The CMSDK APB watchdog of the MPS2 boards (0x40008000, clocked at
//! 25 MHz), which QEMU models on `mps2-an386`. Its first time-out raises
//! its interrupt; a second, with the interrupt still pending, resets the
//! system. The loop feeds it every tick, so a hung loop resets the board
//! within two time-outs.
//!
//! Nothing on this board records why it reset, so the image keeps a word
//! in RAM that no reset clears and the boot code does not initialise: set
//! while the loop runs, found set at the next boot only if that boot was
//! a reset without a power loss, which on this board is the watchdog.

use core::mem::MaybeUninit;
use core::ptr::{addr_of_mut, write_volatile};

const BASE: usize = 0x4000_8000;
const LOAD: usize = BASE;
const CTRL: usize = BASE + 0x08;
const INTCLR: usize = BASE + 0x0C;
const LOCK: usize = BASE + 0xC00;
const UNLOCK_KEY: u32 = 0x1ACC_E551;
const CTRL_INTEN_RESEN: u32 = 0b11;
/// Its clock (Hz).
pub(crate) const CLOCK_HZ: u32 = 25_000_000;

/// The word that outlives a reset ("TPWD" while the loop runs).
#[link_section = ".uninit.twoport_watchdog"]
static mut RUNNING: MaybeUninit<u32> = MaybeUninit::uninit();
const RUNNING_MARK: u32 = u32::from_le_bytes(*b"TPWD");

/// Whether this boot follows a reset of a running loop (the watchdog's),
/// and mark the loop running from now on.
pub fn reset_by_watchdog() -> bool {
    // SAFETY: read and written only here, before the loop starts, by the
    // one thread there is; any bit pattern is a valid u32.
    unsafe {
        let p = addr_of_mut!(RUNNING).cast::<u32>();
        let was = core::ptr::read_volatile(p) == RUNNING_MARK;
        write_volatile(p, RUNNING_MARK);
        was
    }
}

/// The watchdog, running.
pub struct Watchdog;

impl Watchdog {
    /// Start it with a time-out of `timeout_ms` (the reset follows one
    /// more time-out later).
    pub fn start(timeout_ms: u32) -> Self {
        // SAFETY: the watchdog's MMIO registers at their fixed addresses
        // on this machine; only this image touches them.
        unsafe {
            write_volatile(LOCK as *mut u32, UNLOCK_KEY);
            write_volatile(LOAD as *mut u32, CLOCK_HZ / 1000 * timeout_ms);
            write_volatile(CTRL as *mut u32, CTRL_INTEN_RESEN);
            write_volatile(LOCK as *mut u32, 0);
        }
        Watchdog
    }

    /// Feed it: clear its interrupt and reload its count (locked, it
    /// ignores every write but the key's).
    pub fn feed(&mut self) {
        // SAFETY: the watchdog's lock and interrupt-clear registers.
        unsafe {
            write_volatile(LOCK as *mut u32, UNLOCK_KEY);
            write_volatile(INTCLR as *mut u32, 1);
            write_volatile(LOCK as *mut u32, 0);
        }
    }
}
