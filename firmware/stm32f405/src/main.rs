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
//! Zero duty is 50 % in locked antiphase, i.e. zero average voltage; the
//! outputs are off (MOE clear) until the loop runs, and any panic or
//! HardFault turns them off again. Loop timing comes from the DWT cycle
//! counter (real hardware only; QEMU does not model it).
//!
//! Flash with `cargo run --release` in this folder (probe-rs, see
//! `.cargo/config.toml`). This image builds in CI; it is not run here.

#![no_std]
#![no_main]

use core::cell::RefCell;
use cortex_m::interrupt::Mutex;
use cortex_m::peripheral::DWT;
use cortex_m_rt::{entry, exception, ExceptionFrame};
use stm32f4::stm32f405::{self as pac, interrupt};
use twoport_board::excalibur::{self, REGION_POINTS};
use twoport_board::{Board, DUTY_FULL_SCALE};
use twoport_control::servo::SensorFrame;
use twoport_control::ve::UnilateralWall;

/// TIM1 auto-reload: 168 MHz / (2 x 4200) = 20 kHz centre-aligned PWM.
const PWM_ARR: u32 = 4200;
/// ADC mid-scale: a bipolar load-cell amplifier sits at 1.65 V for 0 N.
const ADC_ZERO: i32 = 2048;

type TheBoard = Board<UnilateralWall, REGION_POINTS>;

/// The loop, shared by the control interrupt (ticks) and the main loop
/// (link bytes).
static BOARD: Mutex<RefCell<Option<TheBoard>>> = Mutex::new(RefCell::new(None));
static TICK: Mutex<RefCell<u32>> = Mutex::new(RefCell::new(0));

fn clocks(rcc: &pac::RCC, flash: &pac::FLASH) {
    rcc.cr().modify(|_, w| w.hseon().set_bit());
    while rcc.cr().read().hserdy().bit_is_clear() {}
    // SAFETY: PLLM = 8, PLLN = 336, PLLQ = 7 are inside the reference
    // manual's ranges (8 MHz / 8 x 336 / 2 = 168 MHz, / 7 = 48 MHz).
    rcc.pllcfgr().write(|w| unsafe {
        w.pllsrc()
            .hse()
            .pllm()
            .bits(8)
            .plln()
            .bits(336)
            .pllp()
            .div2()
            .pllq()
            .bits(7)
    });
    rcc.cr().modify(|_, w| w.pllon().set_bit());
    while rcc.cr().read().pllrdy().bit_is_clear() {}
    flash.acr().modify(|_, w| {
        w.latency()
            .ws5()
            .prften()
            .set_bit()
            .icen()
            .set_bit()
            .dcen()
            .set_bit()
    });
    rcc.cfgr()
        .modify(|_, w| w.hpre().div1().ppre1().div4().ppre2().div2().sw().pll());
    while !rcc.cfgr().read().sws().is_pll() {}
    rcc.ahb1enr().modify(|_, w| {
        w.gpioaen()
            .set_bit()
            .gpioben()
            .set_bit()
            .gpiocen()
            .set_bit()
    });
    rcc.apb1enr()
        .modify(|_, w| w.tim2en().set_bit().tim3en().set_bit().usart2en().set_bit());
    rcc.apb2enr()
        .modify(|_, w| w.tim1en().set_bit().adc1en().set_bit());
}

fn pins(a: &pac::GPIOA, b: &pac::GPIOB, c: &pac::GPIOC) {
    a.afrl().modify(|_, w| w.afrl2().af7().afrl3().af7());
    a.afrh().modify(|_, w| w.afrh8().af1());
    a.moder().modify(|_, w| {
        w.moder0()
            .analog()
            .moder2()
            .alternate()
            .moder3()
            .alternate()
            .moder8()
            .alternate()
    });
    b.afrl().modify(|_, w| w.afrl4().af2().afrl5().af2());
    b.afrh().modify(|_, w| w.afrh13().af1());
    b.moder().modify(|_, w| {
        w.moder4()
            .alternate()
            .moder5()
            .alternate()
            .moder13()
            .alternate()
    });
    b.pupdr()
        .modify(|_, w| w.pupdr4().pull_up().pupdr5().pull_up());
    c.moder().modify(|_, w| w.moder0().input());
    c.pupdr().modify(|_, w| w.pupdr0().pull_up());
}

fn encoder(t: &pac::TIM3) {
    // Encoder mode 3: count on both edges of both channels.
    t.ccmr1_input().write(|w| w.cc1s().ti1().cc2s().ti2());
    t.smcr().write(|w| w.sms().encoder_mode_3());
    t.arr().write(|w| w.arr().set(0xFFFF));
    t.cr1().modify(|_, w| w.cen().set_bit());
}

fn pwm(t: &pac::TIM1) {
    t.arr().write(|w| w.arr().set(PWM_ARR as u16));
    t.ccr1().write(|w| w.ccr().set((PWM_ARR / 2) as u16));
    t.ccmr1_output()
        .write(|w| w.oc1m().pwm_mode1().oc1pe().set_bit());
    t.ccer().write(|w| w.cc1e().set_bit().cc1ne().set_bit());
    // SAFETY: DTG = 84 is 500 ns of dead time at 168 MHz, inside the
    // field's 8 bits.
    t.bdtr().write(|w| unsafe { w.dtg().bits(84) });
    t.cr1()
        .write(|w| w.cms().center_aligned1().arpe().set_bit().cen().set_bit());
}

fn adc(a: &pac::ADC1) {
    a.smpr2().write(|w| w.smp0().cycles84());
    // SAFETY: channel 0 is a valid first conversion of the sequence.
    a.sqr3().write(|w| unsafe { w.sq1().bits(0) });
    a.cr2().write(|w| w.adon().set_bit());
}

fn usart(u: &pac::USART2) {
    // 42 MHz / 115200 = 22.79: mantissa 22, fraction 13/16.
    u.brr()
        .write(|w| w.div_mantissa().set(22).div_fraction().set(13));
    u.cr1()
        .write(|w| w.ue().set_bit().te().set_bit().re().set_bit());
}

/// Control-loop timer counts (1 us each) per tick: the image's period, so
/// the interrupt rate and the laws' `T` cannot disagree. 1 kHz as shipped;
/// 100 to 1000 counts give the 1-10 kHz range (a new `T` needs its own
/// proven region: `twoport region impedance --period T --rust`).
const LOOP_COUNTS: u32 = (excalibur::PERIOD_S * 1.0e6 + 0.5) as u32;
const _: () = assert!(LOOP_COUNTS >= 100 && LOOP_COUNTS <= 1000);

fn control_timer(t: &pac::TIM2) {
    // 84 MHz timer clock / 84 = 1 MHz.
    t.psc().write(|w| w.psc().set(83));
    t.arr().write(|w| w.set(LOOP_COUNTS - 1));
    t.dier().write(|w| w.uie().set_bit());
    t.cr1().write(|w| w.cen().set_bit());
}

/// Outputs off: the amplifier sees no drive, the actuator no force.
fn force_off() {
    // SAFETY: only clears TIM1's main output enable, which is safe to do
    // from any context, including a fault handler that owns nothing.
    let tim1 = unsafe { pac::TIM1::steal() };
    tim1.bdtr().modify(|_, w| w.moe().clear_bit());
}

#[entry]
fn main() -> ! {
    let (Some(dp), Some(mut cp)) = (pac::Peripherals::take(), cortex_m::Peripherals::take()) else {
        force_off();
        #[allow(clippy::empty_loop)]
        loop {}
    };
    clocks(&dp.RCC, &dp.FLASH);
    pins(&dp.GPIOA, &dp.GPIOB, &dp.GPIOC);
    encoder(&dp.TIM3);
    pwm(&dp.TIM1);
    adc(&dp.ADC1);
    usart(&dp.USART2);
    cp.DCB.enable_trace();
    cp.DWT.enable_cycle_counter();
    let Ok(board) = excalibur::stiff_wall_board() else {
        // A board that cannot build its law never drives the amplifier.
        force_off();
        #[allow(clippy::empty_loop)]
        loop {}
    };
    cortex_m::interrupt::free(|cs| BOARD.borrow(cs).replace(Some(board)));
    dp.TIM1.bdtr().modify(|_, w| w.moe().set_bit());
    control_timer(&dp.TIM2);
    // SAFETY: the handler only shares state through the critical-section
    // mutexes above.
    unsafe { cortex_m::peripheral::NVIC::unmask(pac::Interrupt::TIM2) };
    let usart = dp.USART2;
    loop {
        let sr = usart.sr().read();
        if sr.rxne().bit_is_set() || sr.ore().bit_is_set() {
            // Reading DR clears RXNE and an overrun; a lost byte is a
            // dropped frame the decoder counts.
            let byte = usart.dr().read().dr().bits() as u8;
            cortex_m::interrupt::free(|cs| {
                if let Some(b) = BOARD.borrow(cs).borrow_mut().as_mut() {
                    b.on_bytes(&[byte]);
                }
            });
        }
        let frame = cortex_m::interrupt::free(|cs| {
            BOARD
                .borrow(cs)
                .borrow_mut()
                .as_mut()
                .and_then(|b| b.pop_tx())
        });
        if let Some(frame) = frame {
            for &b in frame.iter() {
                while usart.sr().read().txe().bit_is_clear() {}
                usart.dr().write(|w| w.dr().set(b as u16));
            }
        }
    }
}

#[interrupt]
fn TIM2() {
    let start = DWT::cycle_count();
    // SAFETY: this interrupt is the only writer of TIM2's status, TIM1's
    // compare register and ADC1's start bit; the reads are of registers no
    // other context changes.
    let (tim2, tim3, tim1, adc, gpioc) = unsafe {
        (
            pac::TIM2::steal(),
            pac::TIM3::steal(),
            pac::TIM1::steal(),
            pac::ADC1::steal(),
            pac::GPIOC::steal(),
        )
    };
    tim2.sr().modify(|_, w| w.uif().clear_bit());
    adc.cr2().modify(|_, w| w.swstart().set_bit());
    let encoder_raw = tim3.cnt().read().bits() & 0xFFFF;
    let dead_man_closed = gpioc.idr().read().idr0().bit_is_clear();
    while adc.sr().read().eoc().bit_is_clear() {}
    let counts = adc.dr().read().data().bits() as i32 - ADC_ZERO;
    let duty = cortex_m::interrupt::free(|cs| {
        let mut tick = TICK.borrow(cs).borrow_mut();
        let mut board = BOARD.borrow(cs).borrow_mut();
        let Some(b) = board.as_mut() else {
            return 0;
        };
        let frame = SensorFrame {
            tick: *tick,
            encoder_raw,
            load_cell_n: b.io().load_cell_n(counts),
            dead_man_closed,
        };
        *tick = tick.wrapping_add(1);
        b.tick(&frame);
        b.set_loop_cycles(DWT::cycle_count().wrapping_sub(start));
        b.duty()
    });
    // Locked antiphase: 50 % is zero force, full scale is 0 or 100 %.
    let half = (PWM_ARR / 2) as i32;
    let ccr = half + duty as i32 * half / DUTY_FULL_SCALE as i32;
    tim1.ccr1().write(|w| w.ccr().set(ccr as u16));
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    force_off();
    #[allow(clippy::empty_loop)]
    loop {}
}

#[exception]
// SAFETY: cortex-m-rt requires the HardFault handler to be an `unsafe fn`;
// it only turns the outputs off.
unsafe fn HardFault(_: &ExceptionFrame) -> ! {
    force_off();
    #[allow(clippy::empty_loop)]
    loop {}
}
