//! The image's board support: the CMSDK APB UART of the ARM MPS2 boards
//! (QEMU `mps2-an386`, UART0 is the first `-serial`) and SysTick. Polled:
//! the loop is driven by the bytes that arrive, so nothing here needs an
//! interrupt. The sensors and the amplifier are the host's, over the link.

use core::ptr::{read_volatile, write_volatile};
use cortex_m::peripheral::SYST;
use twoport_board::{BoardSupport, RawSensors};

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

/// UART0 and SysTick, owned by the loop.
pub struct Uart {
    /// SysTick's last reading, and the 32-bit count it extends to.
    last: u32,
    cycles: u32,
    /// The watchdog the loop feeds.
    pub watchdog: Option<crate::watchdog::Watchdog>,
    /// The control period in SysTick counts where the image keeps its own
    /// time (the simulated device's); 0 where the host paces the ticks.
    pub cycles_per_tick: u32,
}

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
        Uart {
            last: 0,
            cycles: 0,
            watchdog: None,
            cycles_per_tick: 0,
        }
    }

    fn state(&self) -> u32 {
        // SAFETY: UART0's STATE register, a side-effect-free read.
        unsafe { read_volatile(STATE as *const u32) }
    }

    fn read(&mut self) -> Option<u8> {
        if self.state() & STATE_RX_FULL == 0 {
            return None;
        }
        // SAFETY: UART0's DATA register; reading it takes the byte.
        Some(unsafe { read_volatile(DATA as *const u32) } as u8)
    }

    /// Send `b` if the transmitter has room now; `false` if it is full
    /// (the free-running image's link, which never waits on the UART).
    #[cfg(feature = "sim-device")]
    pub fn try_send(&mut self, b: u8) -> bool {
        if self.state() & STATE_TX_FULL != 0 {
            return false;
        }
        // SAFETY: UART0's DATA register; writing it sends the byte.
        unsafe { write_volatile(DATA as *mut u32, b as u32) };
        true
    }

    fn send(&mut self, bytes: &[u8]) {
        for &b in bytes {
            while self.state() & STATE_TX_FULL != 0 {}
            // SAFETY: UART0's DATA register; writing it sends the byte.
            unsafe { write_volatile(DATA as *mut u32, b as u32) };
        }
    }
}

impl<const N: usize> BoardSupport<N> for Uart {
    // Never called: the sensors are the host's (processor in the loop)
    // or the simulated device's in front of this support.
    fn sample(&mut self) -> RawSensors<N> {
        RawSensors::default()
    }
    // The duties go back to the host in the board's actuator frame.
    fn set_duty(&mut self, _: [i16; N]) {}
    // No amplifier: the host sees the outputs as the duty it is sent,
    // which is zero whenever the board is disarmed.
    fn set_outputs(&mut self, _: bool) {}
    fn feed_watchdog(&mut self) {
        if let Some(w) = &mut self.watchdog {
            w.feed();
        }
    }
    fn cycles_per_tick(&self) -> u32 {
        self.cycles_per_tick
    }
    fn read_byte(&mut self) -> Option<u8> {
        self.read()
    }
    fn write(&mut self, bytes: &[u8]) {
        self.send(bytes)
    }
    fn cycles(&mut self) -> u32 {
        // SysTick counts down over 24 bits; the elapsed counts since the
        // last look extend it to 32, which is right while looks come less
        // than 2^24 cycles apart (both looks of a tick do).
        let now = SYST::get_current();
        self.cycles = self
            .cycles
            .wrapping_add(self.last.wrapping_sub(now) & 0x00FF_FFFF);
        self.last = now;
        self.cycles
    }
}
