//! Bringing the chip up: clocks, pins and peripheral modes. The emulated
//! build (`qemu` feature) differs only where QEMU's `netduinoplus2` does:
//! no RCC ready bits to wait on, and timers with a fixed 1 GHz clock.

use stm32f4::stm32f405 as pac;
use twoport_board::excalibur;

/// TIM1 auto-reload: 168 MHz / (2 x 4200) = 20 kHz centre-aligned PWM.
pub const PWM_ARR: u32 = 4200;

/// HSE and PLL to 168 MHz, flash wait states, peripheral clocks on.
pub fn clocks(rcc: &pac::RCC, flash: &pac::FLASH) {
    rcc.cr().modify(|_, w| w.hseon().set_bit());
    wait_for(|| rcc.cr().read().hserdy().bit_is_set());
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
    wait_for(|| rcc.cr().read().pllrdy().bit_is_set());
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
    wait_for(|| rcc.cfgr().read().sws().is_pll());
    rcc.ahb1enr().modify(|_, w| {
        w.gpioaen()
            .set_bit()
            .gpioben()
            .set_bit()
            .gpiocen()
            .set_bit()
    });
    rcc.apb1enr().modify(|_, w| {
        w.tim2en()
            .set_bit()
            .tim3en()
            .set_bit()
            .tim5en()
            .set_bit()
            .usart2en()
            .set_bit()
    });
    rcc.apb2enr()
        .modify(|_, w| w.tim1en().set_bit().adc1en().set_bit());
    #[cfg(feature = "xyz")]
    {
        rcc.apb1enr().modify(|_, w| w.tim4en().set_bit());
        rcc.apb2enr()
            .modify(|_, w| w.tim8en().set_bit().adc2en().set_bit().adc3en().set_bit());
    }
}

/// The pins of the table in the crate docs.
pub fn pins(a: &pac::GPIOA, b: &pac::GPIOB, c: &pac::GPIOC) {
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
    #[cfg(feature = "xyz")]
    xyz_pins(a, b, c);
}

/// The y and z axes' pins: encoders on TIM4 (PB6, PB7, AF2) and TIM8
/// (PC6, PC7, AF3), drives on TIM1's CH2/CH2N (PA9, PB14) and CH3/CH3N
/// (PA10, PB15, AF1), load cells on PA1 (ADC2 IN1) and PC2 (ADC3 IN12).
#[cfg(feature = "xyz")]
fn xyz_pins(a: &pac::GPIOA, b: &pac::GPIOB, c: &pac::GPIOC) {
    a.afrh().modify(|_, w| w.afrh9().af1().afrh10().af1());
    a.moder().modify(|_, w| {
        w.moder1()
            .analog()
            .moder9()
            .alternate()
            .moder10()
            .alternate()
    });
    b.afrl().modify(|_, w| w.afrl6().af2().afrl7().af2());
    b.afrh().modify(|_, w| w.afrh14().af1().afrh15().af1());
    b.moder().modify(|_, w| {
        w.moder6()
            .alternate()
            .moder7()
            .alternate()
            .moder14()
            .alternate()
            .moder15()
            .alternate()
    });
    b.pupdr()
        .modify(|_, w| w.pupdr6().pull_up().pupdr7().pull_up());
    c.afrl().modify(|_, w| w.afrl6().af3().afrl7().af3());
    c.moder().modify(|_, w| {
        w.moder2()
            .analog()
            .moder6()
            .alternate()
            .moder7()
            .alternate()
    });
    c.pupdr()
        .modify(|_, w| w.pupdr6().pull_up().pupdr7().pull_up());
}

/// TIM3 counts the encoder's quadrature edges (TIM4 too, on three axes).
pub fn encoder(t: &pac::tim3::RegisterBlock) {
    // Encoder mode 3: count on both edges of both channels.
    t.ccmr1_input().write(|w| w.cc1s().ti1().cc2s().ti2());
    t.smcr().write(|w| w.sms().encoder_mode_3());
    t.arr().write(|w| w.arr().set(0xFFFF));
    t.cr1().modify(|_, w| w.cen().set_bit());
}

/// The y and z axes' encoders: TIM4 as TIM3, and the advanced TIM8 in
/// the same mode.
#[cfg(feature = "xyz")]
pub fn encoders_yz(t4: &pac::TIM4, t8: &pac::TIM8) {
    encoder(t4);
    t8.ccmr1_input().write(|w| w.cc1s().ti1().cc2s().ti2());
    t8.smcr().write(|w| w.sms().encoder_mode_3());
    t8.arr().write(|w| w.arr().set(0xFFFF));
    t8.cr1().modify(|_, w| w.cen().set_bit());
}

/// TIM1 drives the amplifiers in locked antiphase: channel 1 the x axis's
/// and, in the three-axis image, channels 2 and 3 the y and z axes'. The
/// compare registers are preloaded, so a tick's duties all take effect at
/// the same update event.
pub fn pwm(t: &pac::TIM1) {
    t.arr().write(|w| w.arr().set(PWM_ARR as u16));
    t.ccr1().write(|w| w.ccr().set((PWM_ARR / 2) as u16));
    t.ccmr1_output()
        .write(|w| w.oc1m().pwm_mode1().oc1pe().set_bit());
    t.ccer().write(|w| w.cc1e().set_bit().cc1ne().set_bit());
    #[cfg(feature = "xyz")]
    {
        t.ccr2().write(|w| w.ccr().set((PWM_ARR / 2) as u16));
        t.ccr3().write(|w| w.ccr().set((PWM_ARR / 2) as u16));
        t.ccmr1_output()
            .modify(|_, w| w.oc2m().pwm_mode1().oc2pe().set_bit());
        t.ccmr2_output()
            .write(|w| w.oc3m().pwm_mode1().oc3pe().set_bit());
        t.ccer().modify(|_, w| {
            w.cc2e()
                .set_bit()
                .cc2ne()
                .set_bit()
                .cc3e()
                .set_bit()
                .cc3ne()
                .set_bit()
        });
    }
    // SAFETY: DTG = 84 is 500 ns of dead time at 168 MHz, inside the
    // field's 8 bits.
    t.bdtr().write(|w| unsafe { w.dtg().bits(84) });
    t.cr1()
        .write(|w| w.cms().center_aligned1().arpe().set_bit().cen().set_bit());
}

/// ADC1 converts the load cell on request.
pub fn adc(a: &pac::ADC1) {
    a.smpr2().write(|w| w.smp0().cycles84());
    // SAFETY: channel 0 is a valid first conversion of the sequence.
    a.sqr3().write(|w| unsafe { w.sq1().bits(0) });
    a.cr2().write(|w| w.adon().set_bit());
}

/// The three-axis image's load cells: ADC2 converts IN1 and ADC3 IN12 in
/// triple regular simultaneous mode with ADC1, so that ADC1's start
/// samples all three cells at the same instant.
#[cfg(feature = "xyz")]
pub fn adcs_yz(a2: &pac::ADC2, a3: &pac::ADC3, common: &pac::ADC_COMMON) {
    a2.smpr2().write(|w| w.smp1().cycles84());
    // SAFETY: channel 1 is a valid first conversion of the sequence.
    a2.sqr3().write(|w| unsafe { w.sq1().bits(1) });
    a2.cr2().write(|w| w.adon().set_bit());
    a3.smpr1().write(|w| w.smp12().cycles84());
    // SAFETY: channel 12 is a valid first conversion of the sequence.
    a3.sqr3().write(|w| unsafe { w.sq1().bits(12) });
    a3.cr2().write(|w| w.adon().set_bit());
    // Triple mode, regular simultaneous only (RM0090 13.9: MULTI 10110).
    // SAFETY: 0b10110 is one of MULTI's defined modes.
    common
        .ccr()
        .modify(|_, w| unsafe { w.multi().bits(0b10110) });
}

/// USART2 carries the link.
pub fn usart(u: &pac::USART2) {
    // 42 MHz / 115200 = 22.79: mantissa 22, fraction 13/16.
    u.brr()
        .write(|w| w.div_mantissa().set(22).div_fraction().set(13));
    u.cr1()
        .write(|w| w.ue().set_bit().te().set_bit().re().set_bit());
}

/// The link's rate: 115,200 baud, 8N1 (ten bits a byte), in bytes/s, as
/// the board states it in its spec.
pub const LINK_BYTES_PER_S: u32 = 115_200 / 10;

/// Control-loop timer counts (1 us each) per tick: the image's period, so
/// the interrupt rate and the laws' `T` cannot disagree. 1 kHz as shipped;
/// 100 to 1000 counts give the 1-10 kHz range (a new `T` needs its own
/// proven region: `twoport region impedance --period T --rust`).
const LOOP_COUNTS: u32 = (PERIOD_S * 1.0e6 + 0.5) as u32;
#[cfg(feature = "fast")]
use excalibur::fast::PERIOD_S;
#[cfg(not(feature = "fast"))]
use excalibur::PERIOD_S;
const _: () = assert!(LOOP_COUNTS >= 100 && LOOP_COUNTS <= 1000);

/// TIM2's update interrupt calls the control tick every `PERIOD_S`.
#[cfg(not(feature = "qemu"))]
pub fn control_timer(t: &pac::TIM2) {
    // 84 MHz timer clock / 84 = 1 MHz; the chip counts ARR + 1 per period.
    t.psc().write(|w| w.psc().set(83));
    t.arr().write(|w| w.set(LOOP_COUNTS - 1));
    // Load the prescaler now, not at the first update (which would come
    // 84 times early), and drop the flag that load raises.
    t.egr().write(|w| w.ug().set_bit());
    t.sr().modify(|_, w| w.uif().clear_bit());
    t.dier().write(|w| w.uie().set_bit());
    t.cr1().write(|w| w.cen().set_bit());
}

/// TIM2's update interrupt calls the control tick every `PERIOD_S`.
///
/// QEMU's timers count a fixed 1 GHz over PSC + 1, whatever RCC says, a
/// period is ARR counts (not ARR + 1), and the alarm is armed by the
/// DIER and CR1 writes, so those come first. The count runs from reset
/// and never wraps at ARR, so it is zeroed before ARR is set: an ARR below
/// the count arms no alarm at all.
#[cfg(feature = "qemu")]
pub fn control_timer(t: &pac::TIM2) {
    t.dier().write(|w| w.uie().set_bit());
    t.cr1().write(|w| w.cen().set_bit());
    t.psc().write(|w| w.psc().set(999));
    t.cnt().write(|w| w.set(0));
    t.arr().write(|w| w.set(LOOP_COUNTS));
}

/// The `-icount shift` QEMU runs this image with: each instruction is
/// 2^shift ns of virtual time (a 62.5 MHz core at 4).
#[cfg(feature = "qemu")]
pub const ICOUNT_SHIFT: u32 = 4;

/// TIM5 free-running at QEMU's 1 GHz over 2^ICOUNT_SHIFT: one count per
/// instruction, which times the loop there.
#[cfg(feature = "qemu")]
pub fn instruction_counter(t: &pac::TIM5) {
    t.cr1().write(|w| w.cen().set_bit());
    t.psc().write(|w| w.psc().set((1 << ICOUNT_SHIFT) - 1));
    t.cnt().write(|w| w.set(0));
    t.arr().write(|w| w.set(u32::MAX));
}

/// Wait for a clock to come up. QEMU models no RCC ready bit, so the
/// emulated build goes on at once: its clocks are fixed.
fn wait_for(ready: impl Fn() -> bool) {
    if cfg!(feature = "qemu") {
        return;
    }
    while !ready() {}
}

/// The independent watchdog, from the ~32 kHz LSI divided by 4 (8 kHz):
/// 400 counts, 50 ms without a feed, resets the chip (the reset turns the
/// outputs off, and the next boot reports it). Once started it cannot be
/// stopped. QEMU models no IWDG: there these writes go nowhere.
pub fn watchdog(iwdg: &pac::IWDG) {
    iwdg.kr().write(|w| w.key().unlock());
    iwdg.pr().write(|w| w.pr().divide_by4());
    iwdg.rlr().write(|w| w.rl().set(400));
    iwdg.kr().write(|w| w.key().feed());
    iwdg.kr().write(|w| w.key().start());
}

/// Whether the last reset was the independent watchdog's; clears the
/// reset flags for the next boot.
pub fn reset_by_watchdog(rcc: &pac::RCC) -> bool {
    let was = rcc.csr().read().wdgrstf().bit_is_set();
    rcc.csr().modify(|_, w| w.rmvf().set_bit());
    was
}
