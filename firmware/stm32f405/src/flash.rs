//! The configuration's flash: sectors 10 and 11 of the STM32F405 (128 KiB
//! each at 0x080C0000, outside the program's 768 KiB in `memory.x`), as an
//! `embedded-storage` NOR flash for `twoport-config`'s two-copy store.
//! Offsets are from the start of sector 10.
//!
//! Programming is by 32-bit words (x32 parallelism, which needs 2.7-3.6 V).
//! An erase stalls instruction fetch from flash for up to 2 s, so the
//! board saves only while disarmed with its outputs off, and the watchdog's
//! time-out is stretched to 32 s for the erase and set back after it.

use embedded_storage::nor_flash::{
    check_erase, check_read, check_write, ErrorType, NorFlash, NorFlashError, NorFlashErrorKind,
    ReadNorFlash,
};
use stm32f4::stm32f405 as pac;

/// Sector 10's address.
const BASE: u32 = 0x080C_0000;
/// One sector (bytes).
const SECTOR: usize = 128 * 1024;
/// The first of the two sectors.
const FIRST_SECTOR: u8 = 10;

/// Why the flash interface refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FlashError {
    /// Misaligned or out of bounds.
    Kind(NorFlashErrorKind),
    /// The flash interface reported a programming or protection error.
    Interface,
}

impl NorFlashError for FlashError {
    fn kind(&self) -> NorFlashErrorKind {
        match self {
            FlashError::Kind(k) => *k,
            FlashError::Interface => NorFlashErrorKind::Other,
        }
    }
}

/// Sectors 10 and 11 through the flash interface.
pub struct ConfigFlash {
    flash: pac::FLASH,
}

impl ConfigFlash {
    /// The flash interface, for the configuration only.
    pub fn new(flash: pac::FLASH) -> Self {
        ConfigFlash { flash }
    }

    fn wait(&self) -> Result<(), FlashError> {
        while self.flash.sr().read().bsy().bit_is_set() {}
        let sr = self.flash.sr().read();
        let bad = sr.operr().bit_is_set()
            || sr.wrperr().bit_is_set()
            || sr.pgaerr().bit_is_set()
            || sr.pgperr().bit_is_set()
            || sr.pgserr().bit_is_set();
        // The error flags clear by writing ones.
        self.flash.sr().write(|w| {
            w.operr().clear();
            w.wrperr().clear();
            w.pgaerr().clear();
            w.pgperr().clear();
            w.pgserr().clear()
        });
        if bad {
            Err(FlashError::Interface)
        } else {
            Ok(())
        }
    }

    fn unlocked<T>(
        &mut self,
        f: impl FnOnce(&mut Self) -> Result<T, FlashError>,
    ) -> Result<T, FlashError> {
        if self.flash.cr().read().lock().bit_is_set() {
            self.flash.keyr().write(|w| w.key().set(0x4567_0123));
            self.flash.keyr().write(|w| w.key().set(0xCDEF_89AB));
        }
        let r = self.wait().and_then(|_| f(self));
        self.flash.cr().modify(|_, w| {
            w.pg().clear_bit();
            w.ser().clear_bit();
            w.lock().set_bit()
        });
        r
    }
}

impl ErrorType for ConfigFlash {
    type Error = FlashError;
}

impl ReadNorFlash for ConfigFlash {
    const READ_SIZE: usize = 1;

    fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), Self::Error> {
        check_read(self, offset, bytes.len()).map_err(FlashError::Kind)?;
        for (i, b) in bytes.iter_mut().enumerate() {
            let addr = (BASE + offset + i as u32) as *const u8;
            // SAFETY: the address lies in sectors 10-11 (checked above),
            // which are memory-mapped and always readable.
            *b = unsafe { core::ptr::read_volatile(addr) };
        }
        Ok(())
    }

    fn capacity(&self) -> usize {
        2 * SECTOR
    }
}

impl NorFlash for ConfigFlash {
    const WRITE_SIZE: usize = 4;
    const ERASE_SIZE: usize = SECTOR;

    fn erase(&mut self, from: u32, to: u32) -> Result<(), Self::Error> {
        check_erase(self, from, to).map_err(FlashError::Kind)?;
        for s in (from as usize / SECTOR)..(to as usize / SECTOR) {
            stretch_watchdog(true);
            let r = self.unlocked(|f| {
                f.flash.cr().modify(|_, w| {
                    w.psize().psize32();
                    w.ser().set_bit();
                    // SAFETY: sector 10 or 11, both within SNB's range
                    // and outside the program.
                    unsafe { w.snb().bits(FIRST_SECTOR + s as u8) }
                });
                f.flash.cr().modify(|_, w| w.strt().set_bit());
                f.wait()
            });
            stretch_watchdog(false);
            r?;
        }
        Ok(())
    }

    fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), Self::Error> {
        check_write(self, offset, bytes.len()).map_err(FlashError::Kind)?;
        self.unlocked(|f| {
            f.flash.cr().modify(|_, w| {
                w.psize().psize32();
                w.pg().set_bit()
            });
            for (i, word) in bytes.chunks_exact(4).enumerate() {
                let addr = (BASE + offset + 4 * i as u32) as *mut u32;
                let v = u32::from_le_bytes([word[0], word[1], word[2], word[3]]);
                // SAFETY: a word-aligned address in sectors 10-11 (checked
                // above), programmed with PG set as the reference manual
                // prescribes; nothing else uses these sectors.
                unsafe { core::ptr::write_volatile(addr, v) };
                f.wait()?;
            }
            Ok(())
        })
    }
}

/// The watchdog's time-out: 32 s for a sector erase, which stalls the
/// processor, or the loop's 50 ms (as `init::watchdog` sets it).
fn stretch_watchdog(long: bool) {
    // SAFETY: called from the main loop under the board's lock, where
    // nothing else uses the watchdog; these are its documented key,
    // prescaler and reload writes.
    let iwdg = unsafe { pac::IWDG::steal() };
    // A new prescaler or reload takes effect once the last has.
    while iwdg.sr().read().bits() != 0 {}
    iwdg.kr().write(|w| w.key().feed());
    iwdg.kr().write(|w| w.key().unlock());
    if long {
        iwdg.pr().write(|w| w.pr().divide_by256());
        iwdg.rlr().write(|w| w.rl().set(4095));
    } else {
        iwdg.pr().write(|w| w.pr().divide_by4());
        iwdg.rlr().write(|w| w.rl().set(400));
    }
    while iwdg.sr().read().bits() != 0 {}
    iwdg.kr().write(|w| w.key().feed());
}
