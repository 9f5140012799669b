//! How the QEMU images end (knurling style): a panic or a HardFault prints
//! what happened through semihosting and exits QEMU with a failure code, so
//! a run can neither hang nor pass by accident. Link it with
//! `use twoport_qemu_exit as _;`.

#![no_std]

use cortex_m_rt::{exception, ExceptionFrame};
use cortex_m_semihosting::{debug, hprintln};

/// Leave QEMU with success or failure.
pub fn exit(success: bool) -> ! {
    debug::exit(if success {
        debug::EXIT_SUCCESS
    } else {
        debug::EXIT_FAILURE
    });
    // Only reached without a semihosting host (a real board): stop here.
    #[allow(clippy::empty_loop)]
    loop {}
}

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    hprintln!("panic: {}", info);
    exit(false)
}

#[exception]
// SAFETY: cortex-m-rt requires the HardFault handler to be an `unsafe fn`;
// it only reads the stacked frame it is handed and exits.
unsafe fn HardFault(ef: &ExceptionFrame) -> ! {
    hprintln!("HardFault at pc {:#010x}", ef.pc());
    exit(false)
}
