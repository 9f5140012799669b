//! The board loop on an STM32F405 motor controller (the MCU of ODrive v3 and
//! VESC boards). Thin board support around `twoport-board`:
//!
//! | what              | peripheral                    | pins              |
//! |-------------------|-------------------------------|-------------------|
//! | encoder           | TIM3 encoder mode (x4), 16 bit| PB4, PB5 (AF2)    |
//! | force command     | TIM1 CH1/CH1N, 20 kHz centre-aligned, locked antiphase | PA8, PB13 (AF1) |
//! | load cell         | ADC1 channel 0, 12 bit        | PA0               |
//! | dead-man switch   | input, pull-up, closed = low  | PC0               |
//! | link              | USART2, 115200 8N1            | PA2, PA3 (AF7)    |
//! | control loop      | TIM2 update interrupt, 1/T (1 kHz shipped) |      |
//!
//! Clocks: 8 MHz crystal, PLL to 168 MHz (APB1 42 MHz, APB2 84 MHz).
//! Zero duty is 50 % in locked antiphase, i.e. zero average voltage. The
//! board boots disarmed with the outputs off (MOE clear); the loop turns
//! them on only while it homes or is armed, and any fault, panic or
//! HardFault turns them off again. Loop timing comes from the DWT cycle
//! counter.
//!
//! The `xyz` feature builds the three-axis image (the Excalibur's three
//! Cartesian axes on the building-block world, `twoport_board::excalibur::xyz`),
//! with two more of each axis's peripherals:
//!
//! | what              | y axis                  | z axis                   |
//! |-------------------|-------------------------|--------------------------|
//! | encoder           | TIM4, PB6, PB7 (AF2)    | TIM8, PC6, PC7 (AF3)     |
//! | force command     | TIM1 CH2/CH2N, PA9, PB14 (AF1) | TIM1 CH3/CH3N, PA10, PB15 (AF1) |
//! | load cell         | ADC2 channel 1, PA1     | ADC3 channel 12, PC2     |
//!
//! One control interrupt samples every axis: one start converts the
//! three load cells at the same instant (the ADCs in triple simultaneous
//! mode), the three encoder counters are read back to back while they
//! convert, and the three duties go into TIM1's preloaded compare
//! registers, which take effect together at the next PWM update.
//!
//! The `serial-arm` and `delta` features build a linkage image
//! (`twoport_board::linkage`) on the same three channels: each encoder
//! counts a joint, each PWM pair drives a joint's motor.
//!
//! Flash with `cargo run --release` in this folder (probe-rs, see
//! `.cargo/config.toml`); add `--features xyz` for the three-axis image.
//!
//! The `qemu` feature builds the same image for QEMU's `netduinoplus2`
//! (an STM32F405 SoC): the same interrupt, the same loop, but the clocks
//! are not waited on, the timers run from QEMU's fixed clock, the loop is
//! timed in instructions (TIM5 under `-icount shift=0`), and the sensors
//! come from the host over the link, one frame per tick, for
//! processor-in-the-loop runs (`cargo xtask pil --board stm32f405`).
//! There, USART2 is QEMU's second `-serial`, and a panic or HardFault
//! ends QEMU with a failure code.

#![no_std]
#![no_main]

#[cfg(not(feature = "qemu"))]
mod flash;
mod init;
mod log;
mod support;

use core::cell::RefCell;
use cortex_m::interrupt::Mutex;
use cortex_m_rt::entry;
use stm32f4::stm32f405::{self as pac, interrupt};
use support::Stm32;
#[cfg(not(any(feature = "serial-arm", feature = "delta")))]
use twoport_board::excalibur;
#[cfg(feature = "qemu")]
use twoport_qemu_exit as _;

/// The axes this image drives.
#[cfg(not(feature = "xyz"))]
pub const AXES: usize = 1;
/// The axes this image drives.
#[cfg(feature = "xyz")]
pub const AXES: usize = 3;

#[cfg(not(any(feature = "xyz", feature = "fast")))]
type TheBoard = twoport_board::Board<
    twoport_control::Servo<twoport_control::ve::UnilateralWall>,
    { excalibur::REGION_POINTS },
>;
#[cfg(feature = "fast")]
type TheBoard = twoport_board::Board<
    twoport_control::Servo<twoport_control::ve::UnilateralWall>,
    { excalibur::fast::REGION_POINTS },
>;
#[cfg(all(feature = "xyz", not(any(feature = "serial-arm", feature = "delta"))))]
type TheBoard = excalibur::xyz::XyzBoard;
#[cfg(feature = "serial-arm")]
type TheBoard = twoport_board::linkage::SerialArmBoard;
#[cfg(feature = "delta")]
type TheBoard = twoport_board::linkage::DeltaBoard;

/// The loop, shared by the control interrupt (ticks) and the main loop
/// (link bytes).
static BOARD: Mutex<RefCell<Option<TheBoard>>> = Mutex::new(RefCell::new(None));

/// The stored configuration, shared the same way: the main loop saves,
/// and so does a processor-in-the-loop tick waiting on its host.
static STORE: Mutex<RefCell<Option<ConfigStore>>> = Mutex::new(RefCell::new(None));

#[cfg(not(feature = "qemu"))]
type ConfigStore = twoport_config::Store<flash::ConfigFlash>;
#[cfg(feature = "qemu")]
type ConfigStore = twoport_config::Store<twoport_config::RamFlash<512, 256>>;

/// Write a save the host asked for (disarmed only), under the lock, so
/// that the tick waits out an erase, which it may, with the outputs off.
fn service_config(b: &mut TheBoard, cs: &cortex_m::interrupt::CriticalSection) {
    if let Some(st) = STORE.borrow(cs).borrow_mut().as_mut() {
        b.service_config(st);
    }
}

/// Outputs off: the amplifier sees no drive, the actuator no force.
fn force_off() {
    // SAFETY: only clears TIM1's main output enable, which is safe to do
    // from any context, including a fault handler that owns nothing.
    let tim1 = unsafe { pac::TIM1::steal() };
    tim1.bdtr().modify(|_, w| w.moe().clear_bit());
}

/// Stop with the outputs off.
fn halt() -> ! {
    force_off();
    #[allow(clippy::empty_loop)]
    loop {}
}

#[entry]
fn main() -> ! {
    let (Some(dp), Some(cp)) = (pac::Peripherals::take(), cortex_m::Peripherals::take()) else {
        halt()
    };
    init::clocks(&dp.RCC, &dp.FLASH);
    init::pins(&dp.GPIOA, &dp.GPIOB, &dp.GPIOC);
    init::encoder(&dp.TIM3);
    init::pwm(&dp.TIM1);
    init::adc(&dp.ADC1);
    #[cfg(feature = "xyz")]
    {
        init::encoders_yz(&dp.TIM4, &dp.TIM8);
        init::adcs_yz(&dp.ADC2, &dp.ADC3, &dp.ADC_COMMON);
    }
    init::usart(&dp.USART2);
    #[cfg(not(feature = "qemu"))]
    {
        let mut cp = cp;
        cp.DCB.enable_trace();
        cp.DWT.enable_cycle_counter();
    }
    // QEMU models no DWT: TIM5 counts instructions instead.
    #[cfg(feature = "qemu")]
    {
        let _ = cp;
        init::instruction_counter(&dp.TIM5);
    }
    // A board that cannot build its law never drives the amplifier.
    #[cfg(not(any(feature = "xyz", feature = "fast")))]
    let board = excalibur::stiff_wall_board().map_err(|_| ());
    #[cfg(feature = "fast")]
    let board = excalibur::fast::board().map_err(|_| ());
    #[cfg(all(feature = "xyz", not(any(feature = "serial-arm", feature = "delta"))))]
    let board = excalibur::xyz::board().map_err(|_| ());
    #[cfg(feature = "serial-arm")]
    let board = twoport_board::linkage::serial_arm_board().map_err(|_| ());
    #[cfg(feature = "delta")]
    let board = twoport_board::linkage::delta_board().map_err(|_| ());
    let Ok(board) = board else { halt() };
    let mut board = board
        .with_pil(cfg!(feature = "qemu"))
        .with_link_rate(init::LINK_BYTES_PER_S)
        // The DWT counts the 168 MHz core's cycles; in QEMU, TIM5 counts
        // instructions, at one cycle each.
        .with_count_rate(168_000_000);
    if init::reset_by_watchdog(&dp.RCC) {
        board.trip(twoport_control::Faults::WATCHDOG_RESET);
        log::watchdog_reset();
    }
    let mut store = config_store(dp.FLASH);
    log::config(board.boot_config(&mut store));
    cortex_m::interrupt::free(|cs| {
        BOARD.borrow(cs).replace(Some(board));
        STORE.borrow(cs).replace(Some(store));
    });
    // Said before the first tick, which in QEMU waits for the host.
    #[cfg(feature = "qemu")]
    cortex_m_semihosting::hprintln!("twoport-stm32f405 (qemu): board loop up, waiting on USART2");
    init::watchdog(&dp.IWDG);
    init::control_timer(&dp.TIM2);
    // SAFETY: the handler only shares state through the critical-section
    // mutex above.
    unsafe { cortex_m::peripheral::NVIC::unmask(pac::Interrupt::TIM2) };
    // SAFETY: the main loop uses the link's registers only inside the
    // critical section, or to transmit, which the interrupt does only in
    // the emulated build, where this loop transmits inside it too.
    let mut io = unsafe { Stm32::steal() };
    let mut seen = log::Seen::default();
    loop {
        service_link(&mut io);
        cortex_m::interrupt::free(|cs| {
            if let Some(b) = BOARD.borrow(cs).borrow().as_ref() {
                seen.changes(b.status());
            }
        });
        cortex_m::interrupt::free(|cs| {
            if let Some(b) = BOARD.borrow(cs).borrow_mut().as_mut() {
                service_config(b, cs);
            }
        });
    }
}

/// The stored configuration: sectors 10 and 11 on the chip.
#[cfg(not(feature = "qemu"))]
fn config_store(flash: pac::FLASH) -> ConfigStore {
    twoport_config::Store::new(flash::ConfigFlash::new(flash), 0, 128 * 1024)
}

/// QEMU models no flash interface: the configuration lives in RAM there.
#[cfg(feature = "qemu")]
fn config_store(_: pac::FLASH) -> ConfigStore {
    twoport_config::Store::new(twoport_config::RamFlash::new(), 0, 256)
}

/// The main loop's work on real hardware: take the bytes received and the
/// next frame to send under the lock, and send it outside, so that a
/// frame's milliseconds on the wire never hold off the control interrupt.
#[cfg(not(feature = "qemu"))]
fn service_link(io: &mut Stm32) {
    use twoport_board::BoardSupport;
    let frame = cortex_m::interrupt::free(|cs| {
        let mut board = BOARD.borrow(cs).borrow_mut();
        let b = board.as_mut()?;
        b.poll_link(io);
        b.pop_tx()
    });
    if let Some(frame) = frame {
        io.write(&frame);
    }
}

/// The main loop's work in QEMU, where a tick waiting on the host sends
/// frames from the interrupt: everything under the lock, so that two
/// frames never interleave (QEMU's USART never stalls a write).
#[cfg(feature = "qemu")]
fn service_link(io: &mut Stm32) {
    cortex_m::interrupt::free(|cs| {
        if let Some(b) = BOARD.borrow(cs).borrow_mut().as_mut() {
            b.poll_link(io);
            b.flush(io);
        }
    });
}

#[interrupt]
fn TIM2() {
    // SAFETY: this interrupt is the only writer of TIM2's status; the
    // rest of the peripherals it uses go through the board's lock below.
    let tim2 = unsafe { pac::TIM2::steal() };
    tim2.sr().modify(|_, w| w.uif().clear_bit());
    // SAFETY: used only inside the critical section.
    let mut io = unsafe { Stm32::steal() };
    cortex_m::interrupt::free(|cs| {
        if let Some(b) = BOARD.borrow(cs).borrow_mut().as_mut() {
            b.control_tick_serving(&mut io, |b| service_config(b, cs));
        }
    });
}

#[cfg(not(feature = "qemu"))]
#[panic_handler]
fn panic(_info: &core::panic::PanicInfo) -> ! {
    force_off();
    #[cfg(feature = "defmt")]
    defmt::error!("panic: outputs off");
    halt()
}

#[cfg(not(feature = "qemu"))]
#[cortex_m_rt::exception]
// SAFETY: cortex-m-rt requires the HardFault handler to be an `unsafe fn`;
// it only turns the outputs off.
unsafe fn HardFault(_: &cortex_m_rt::ExceptionFrame) -> ! {
    halt()
}
