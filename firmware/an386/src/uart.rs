//! The CMSDK APB UART of the ARM MPS2 boards (QEMU `mps2-an386`, UART0 is
//! the first `-serial`). Polled: the loop is driven by the bytes that
//! arrive, so nothing here needs an interrupt.

use core::ptr::{read_volatile, write_volatile};

/// UART0's registers.
const BASE: usize = 0x4000_4000;
const DATA: usize = BASE;
const STATE: usize = BASE + 0x04;
const CTRL: usize = BASE + 0x08;
const BAUDDIV: usize = BASE + 0x10;
const STATE_TX_FULL: u32 = 1 << 0;
const STATE_RX_FULL: u32 = 1 << 1;
const CTRL_TX_EN: u32 = 1 << 0;
const CTRL_RX_EN: u32 = 1 << 1;

/// UART0, owned by the loop.
pub struct Uart(());

impl Uart {
    /// Enable transmit and receive. The divider only matters to real
    /// hardware (QEMU passes bytes at host speed); 16 is its legal minimum.
    pub fn take() -> Self {
        // SAFETY: fixed, aligned MMIO addresses of UART0 on this machine;
        // only this loop touches them.
        unsafe {
            write_volatile(BAUDDIV as *mut u32, 16);
            write_volatile(CTRL as *mut u32, CTRL_TX_EN | CTRL_RX_EN);
        }
        Uart(())
    }

    fn state(&self) -> u32 {
        // SAFETY: UART0's STATE register, a side-effect-free read.
        unsafe { read_volatile(STATE as *const u32) }
    }

    /// A received byte, if one is waiting.
    pub fn read(&mut self) -> Option<u8> {
        if self.state() & STATE_RX_FULL == 0 {
            return None;
        }
        // SAFETY: UART0's DATA register; reading it takes the byte.
        Some(unsafe { read_volatile(DATA as *const u32) } as u8)
    }

    /// Send `bytes`, waiting while the transmit buffer is full.
    pub fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            while self.state() & STATE_TX_FULL != 0 {}
            // SAFETY: UART0's DATA register; writing it sends the byte.
            unsafe { write_volatile(DATA as *mut u32, b as u32) };
        }
    }
}
