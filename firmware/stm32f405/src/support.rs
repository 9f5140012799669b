//! The image's board support: the peripherals the loop reads and drives,
//! as `twoport-board` asks for them.

use crate::init::PWM_ARR;
use crate::AXES;
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
    #[cfg(feature = "xyz")]
    yz: Yz,
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
                #[cfg(feature = "xyz")]
                yz: Yz {
                    tim4: pac::TIM4::steal(),
                    tim8: pac::TIM8::steal(),
                    adc2: pac::ADC2::steal(),
                    adc3: pac::ADC3::steal(),
                },
                gpioc: pac::GPIOC::steal(),
                usart: pac::USART2::steal(),
                iwdg: pac::IWDG::steal(),
                #[cfg(feature = "qemu")]
                tim5: pac::TIM5::steal(),
            }
        }
    }
}

/// The three-axis image's y and z peripherals.
#[cfg(feature = "xyz")]
struct Yz {
    tim4: pac::TIM4,
    tim8: pac::TIM8,
    adc2: pac::ADC2,
    adc3: pac::ADC3,
}

/// A converter's reading, offset removed, once its conversion has ended;
/// a stuck converter reads as far out of range, which the admittance
/// display's range check turns into zero force.
fn converted(eoc: impl Fn() -> bool, data: impl Fn() -> u16) -> i32 {
    for _ in 0..ADC_POLLS {
        if eoc() {
            return data() as i32 - ADC_ZERO;
        }
    }
    i32::MAX
}

/// Locked antiphase: 50 % is zero force, full scale is 0 or 100 %.
fn ccr(duty: i16) -> u16 {
    let half = (PWM_ARR / 2) as i32;
    (half + duty as i32 * half / DUTY_FULL_SCALE as i32) as u16
}

impl Stm32 {
    /// Every axis's encoder count, read back to back (within a few core
    /// cycles of each other).
    fn encoders(&self) -> [u32; AXES] {
        let x = self.tim3.cnt().read().bits() & 0xFFFF;
        #[cfg(feature = "xyz")]
        return [
            x,
            self.yz.tim4.cnt().read().bits() & 0xFFFF,
            self.yz.tim8.cnt().read().bits() & 0xFFFF,
        ];
        #[cfg(not(feature = "xyz"))]
        [x]
    }

    /// Every axis's load cell, from the conversions one start began.
    fn load_cells(&self) -> [i32; AXES] {
        let a = &self.adc;
        let x = converted(
            || a.sr().read().eoc().bit_is_set(),
            || a.dr().read().data().bits(),
        );
        #[cfg(feature = "xyz")]
        {
            let (b, c) = (&self.yz.adc2, &self.yz.adc3);
            return [
                x,
                converted(
                    || b.sr().read().eoc().bit_is_set(),
                    || b.dr().read().data().bits(),
                ),
                converted(
                    || c.sr().read().eoc().bit_is_set(),
                    || c.dr().read().data().bits(),
                ),
            ];
        }
        #[cfg(not(feature = "xyz"))]
        [x]
    }
}

impl BoardSupport<AXES> for Stm32 {
    fn sample(&mut self) -> RawSensors<AXES> {
        // One start samples every load cell (in the three-axis image the
        // ADCs run in simultaneous mode); the encoders are latched while
        // they convert.
        self.adc.cr2().modify(|_, w| w.swstart().set_bit());
        let encoder_raw = self.encoders();
        let dead_man_closed = self.gpioc.idr().read().idr0().bit_is_clear();
        RawSensors {
            encoder_raw,
            load_cell_counts: self.load_cells(),
            dead_man_closed,
            // The shipped wiring has no index input.
            index_raw: [None; AXES],
        }
    }

    fn set_duty(&mut self, duty: [i16; AXES]) {
        // The compare registers are preloaded: every axis's new duty takes
        // effect at the same PWM update.
        self.tim1.ccr1().write(|w| w.ccr().set(ccr(duty[0])));
        #[cfg(feature = "xyz")]
        {
            self.tim1.ccr2().write(|w| w.ccr().set(ccr(duty[1])));
            self.tim1.ccr3().write(|w| w.ccr().set(ccr(duty[2])));
        }
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
