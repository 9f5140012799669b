//! The image's board support: the peripherals the loop reads and drives,
//! as `twoport-board` asks for them.

use crate::init::PWM_ARR;
use stm32f4::stm32f405 as pac;
use twoport_board::{BoardSupport, RawSensors, DUTY_FULL_SCALE};

/// ADC mid-scale: a bipolar load-cell amplifier sits at 1.65 V for 0 N.
const ADC_ZERO: i32 = 2048;
/// Polls of the ADC's end of conversion before giving up: a conversion
/// takes about 400 core cycles, a poll about 10.
const ADC_POLLS: u32 = 2_000;

/// The peripherals of the table in the crate docs.
pub struct Stm32 {
    tim3: pac::TIM3,
    tim1: pac::TIM1,
    adc: pac::ADC1,
    gpioc: pac::GPIOC,
    usart: pac::USART2,
    iwdg: pac::IWDG,
    #[cfg(feature = "qemu")]
    tim5: pac::TIM5,
}

impl Stm32 {
    /// A handle on the peripherals, for the interrupt and the main loop
    /// alike.
    ///
    /// # Safety
    ///
    /// The registers are shared between the two contexts, and every use
    /// of them goes through the board's critical section, except `write`'s
    /// transmit polling, which only the main loop does.
    pub unsafe fn steal() -> Self {
        // SAFETY: the caller keeps the uses apart (above); stealing only
        // makes the handles.
        unsafe {
            Stm32 {
                tim3: pac::TIM3::steal(),
                tim1: pac::TIM1::steal(),
                adc: pac::ADC1::steal(),
                gpioc: pac::GPIOC::steal(),
                usart: pac::USART2::steal(),
                iwdg: pac::IWDG::steal(),
                #[cfg(feature = "qemu")]
                tim5: pac::TIM5::steal(),
            }
        }
    }
}

impl BoardSupport for Stm32 {
    fn sample(&mut self) -> RawSensors {
        self.adc.cr2().modify(|_, w| w.swstart().set_bit());
        let encoder_raw = self.tim3.cnt().read().bits() & 0xFFFF;
        let dead_man_closed = self.gpioc.idr().read().idr0().bit_is_clear();
        let mut polls = 0;
        while self.adc.sr().read().eoc().bit_is_clear() {
            polls += 1;
            if polls == ADC_POLLS {
                // A stuck converter reads as far out of range, which the
                // admittance display's range check turns into zero force.
                return RawSensors {
                    encoder_raw,
                    load_cell_counts: i32::MAX,
                    dead_man_closed,
                    index_raw: None,
                };
            }
        }
        RawSensors {
            encoder_raw,
            load_cell_counts: self.adc.dr().read().data().bits() as i32 - ADC_ZERO,
            dead_man_closed,
            // The shipped wiring has no index input.
            index_raw: None,
        }
    }

    fn set_duty(&mut self, duty: i16) {
        // Locked antiphase: 50 % is zero force, full scale is 0 or 100 %.
        let half = (PWM_ARR / 2) as i32;
        let ccr = half + duty as i32 * half / DUTY_FULL_SCALE as i32;
        self.tim1.ccr1().write(|w| w.ccr().set(ccr as u16));
    }

    fn set_outputs(&mut self, on: bool) {
        // TIM1's main output enable gates both bridge legs: off, the
        // amplifier sees no drive whatever the compare register holds.
        self.tim1.bdtr().modify(|_, w| w.moe().bit(on));
    }

    fn feed_watchdog(&mut self) {
        self.iwdg.kr().write(|w| w.key().feed());
    }

    fn read_byte(&mut self) -> Option<u8> {
        let sr = self.usart.sr().read();
        if sr.rxne().bit_is_set() || sr.ore().bit_is_set() {
            // Reading DR clears RXNE and an overrun; a lost byte is a
            // dropped frame the decoder counts.
            Some(self.usart.dr().read().dr().bits() as u8)
        } else {
            None
        }
    }

    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            while self.usart.sr().read().txe().bit_is_clear() {}
            self.usart.dr().write(|w| w.dr().set(b as u16));
        }
    }

    #[cfg(not(feature = "qemu"))]
    fn cycles(&mut self) -> u32 {
        cortex_m::peripheral::DWT::cycle_count()
    }

    #[cfg(feature = "qemu")]
    fn cycles(&mut self) -> u32 {
        self.tim5.cnt().read().bits()
    }

    /// 168 MHz at 1 kHz.
    #[cfg(not(feature = "qemu"))]
    fn cycles_per_tick(&self) -> u32 {
        168_000
    }

    /// In QEMU the host paces the ticks (processor in the loop).
    #[cfg(feature = "qemu")]
    fn cycles_per_tick(&self) -> u32 {
        0
    }
}
