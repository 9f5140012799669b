//! The board loop on QEMU mps2-an386 (Cortex-M4F) for processor-in-the-loop
//! runs: the same `twoport-board` loop as the STM32F405 image, with its
//! sensors arriving and its PWM duty leaving as link frames on UART0, one
//! tick per sensor frame (lockstep with host-sim). Started by
//! `cargo xtask pil`; a panic or HardFault ends QEMU with a failure code.
//! With the `passivity` feature the image runs the series damper at the
//! actuator's port (`cargo xtask pil --passivity`); with `xyz`, the
//! three-axis Excalibur image on its building-block world (`cargo xtask
//! pil scenes/xyz/pil_blocks.toml`); with `serial-arm` or `delta`, a
//! linkage image (`twoport_board::linkage`: joint encoders in, joint
//! torques out; `cargo xtask pil --linkage serial-arm`).

#![no_std]
#![no_main]

mod uart;
mod watchdog;

use cortex_m::peripheral::syst::SystClkSource;
use cortex_m_rt::entry;
use cortex_m_semihosting::hprintln;

use twoport_config::{RamFlash, Store};
use twoport_qemu_exit::exit;

/// The watchdog's time-out (ms): the reset follows a second one, so a
/// hung loop is reset within 100 ms.
const WATCHDOG_MS: u32 = 50;

#[entry]
fn main() -> ! {
    #[cfg(not(any(
        feature = "passivity",
        feature = "xyz",
        feature = "serial-arm",
        feature = "delta"
    )))]
    let board = twoport_board::excalibur::stiff_wall_board().map_err(|_| ());
    #[cfg(feature = "passivity")]
    let board = twoport_board::excalibur::stiff_wall_board_with_passivity().map_err(|_| ());
    #[cfg(feature = "xyz")]
    let board = twoport_board::excalibur::xyz::board().map_err(|_| ());
    #[cfg(feature = "serial-arm")]
    let board = twoport_board::linkage::serial_arm_board().map_err(|_| ());
    #[cfg(feature = "delta")]
    let board = twoport_board::linkage::delta_board().map_err(|_| ());
    let Ok(mut board) = board.map(|b| b.with_pil(true)) else {
        hprintln!("the board image would not build");
        exit(false)
    };
    // QEMU's board has no flash for it: the configuration lives in RAM,
    // so every boot reports the defaults, and why (nothing stored).
    let mut store = Store::new(RamFlash::<512, 256>::new(), 0, 256);
    board.boot_config(&mut store);
    // A hung loop was reset by the watchdog: say so, latched, so that the
    // board stays disarmed until the host has seen it and cleared it.
    if watchdog::reset_by_watchdog() {
        board.trip(twoport_control::Faults::WATCHDOG_RESET);
        hprintln!("twoport-an386: restarted by the watchdog");
    }
    let mut io = uart::Uart::take();
    io.watchdog = Some(watchdog::Watchdog::start(WATCHDOG_MS));
    // SysTick times each tick; with `-icount shift=N` it is a
    // deterministic function of the instructions executed.
    if let Some(mut p) = cortex_m::Peripherals::take() {
        p.SYST.set_clock_source(SystClkSource::Core);
        p.SYST.set_reload(0x00FF_FFFF);
        p.SYST.clear_current();
        p.SYST.enable_counter();
    }
    hprintln!("twoport-an386: board loop up, waiting on UART0");
    // Lockstep: each control tick waits for the host's sensor frame.
    #[cfg(feature = "watchdog-test")]
    let mut armed_ticks = 0u32;
    loop {
        board.control_tick_serving(&mut io, |b| b.service_config(&mut store));
        board.service_config(&mut store);
        board.flush(&mut io);
        // The watchdog test's image hangs on purpose after 1,500 armed
        // ticks, as a loop stuck in a bug would.
        #[cfg(feature = "watchdog-test")]
        {
            if board.mode() == twoport_link::Mode::Armed {
                armed_ticks += 1;
            }
            if armed_ticks == 1500 {
                hprintln!("twoport-an386: hanging on purpose (watchdog test)");
                #[allow(clippy::empty_loop)]
                loop {}
            }
        }
    }
}
