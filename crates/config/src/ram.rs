//! A NOR flash in RAM, for QEMU images and host tests: erasing sets bytes
//! to 0xFF, writing can only clear bits, and its power can be cut after a
//! given number of byte operations, in the middle of an erase or a write.

use embedded_storage::nor_flash::{
    check_erase, check_read, check_write, ErrorType, NorFlash, NorFlashError, NorFlashErrorKind,
    ReadNorFlash,
};

/// Why the RAM flash refused an operation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum RamFlashError {
    /// Misaligned or out of bounds.
    Kind(NorFlashErrorKind),
    /// The power was cut (see [`RamFlash::cut_power_after`]).
    PowerLost,
}

impl NorFlashError for RamFlashError {
    fn kind(&self) -> NorFlashErrorKind {
        match self {
            RamFlashError::Kind(k) => *k,
            RamFlashError::PowerLost => NorFlashErrorKind::Other,
        }
    }
}

/// `N` bytes of NOR flash in erase units of `ERASE` bytes, written in
/// 4-byte words (as the STM32F405's at 2.7-3.6 V).
#[derive(Clone, Debug)]
pub struct RamFlash<const N: usize, const ERASE: usize> {
    bytes: [u8; N],
    /// Byte operations left before the power goes (`None`: never).
    budget: Option<usize>,
}

impl<const N: usize, const ERASE: usize> Default for RamFlash<N, ERASE> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize, const ERASE: usize> RamFlash<N, ERASE> {
    /// An erased flash.
    ///
    /// # Examples
    ///
    /// ```
    /// use embedded_storage::nor_flash::{NorFlash, ReadNorFlash};
    /// use twoport_config::RamFlash;
    /// let mut f = RamFlash::<2048, 1024>::new();
    /// f.write(0, &[0x0F, 0xF0, 0x00, 0xAA]).unwrap();
    /// // NOR: a write can only clear bits.
    /// f.write(0, &[0xF0, 0xFF, 0xFF, 0xFF]).unwrap();
    /// let mut b = [0u8; 4];
    /// f.read(0, &mut b).unwrap();
    /// assert_eq!(b, [0x00, 0xF0, 0x00, 0xAA]);
    /// ```
    pub const fn new() -> Self {
        RamFlash {
            bytes: [0xFF; N],
            budget: None,
        }
    }

    /// Cut the power after `ops` more bytes have been erased or written:
    /// the operation in progress stops there and fails, as does every
    /// later one until [`restore_power`](Self::restore_power).
    pub fn cut_power_after(&mut self, ops: usize) {
        self.budget = Some(ops);
    }

    /// Power back on (a reboot): the bytes are as the cut left them.
    pub fn restore_power(&mut self) {
        self.budget = None;
    }

    /// The raw contents.
    pub fn bytes(&self) -> &[u8; N] {
        &self.bytes
    }

    /// The raw contents, to corrupt them in a test.
    pub fn bytes_mut(&mut self) -> &mut [u8; N] {
        &mut self.bytes
    }

    fn spend(&mut self) -> Result<(), RamFlashError> {
        match &mut self.budget {
            None => Ok(()),
            Some(0) => Err(RamFlashError::PowerLost),
            Some(n) => {
                *n -= 1;
                Ok(())
            }
        }
    }
}

impl<const N: usize, const ERASE: usize> ErrorType for RamFlash<N, ERASE> {
    type Error = RamFlashError;
}

impl<const N: usize, const ERASE: usize> ReadNorFlash for RamFlash<N, ERASE> {
    const READ_SIZE: usize = 1;

    fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), Self::Error> {
        check_read(self, offset, bytes.len()).map_err(RamFlashError::Kind)?;
        if self.budget == Some(0) {
            return Err(RamFlashError::PowerLost);
        }
        let o = offset as usize;
        bytes.copy_from_slice(&self.bytes[o..o + bytes.len()]);
        Ok(())
    }

    fn capacity(&self) -> usize {
        N
    }
}

impl<const N: usize, const ERASE: usize> NorFlash for RamFlash<N, ERASE> {
    const WRITE_SIZE: usize = 4;
    const ERASE_SIZE: usize = ERASE;

    fn erase(&mut self, from: u32, to: u32) -> Result<(), Self::Error> {
        check_erase(self, from, to).map_err(RamFlashError::Kind)?;
        for i in from as usize..to as usize {
            self.spend()?;
            self.bytes[i] = 0xFF;
        }
        Ok(())
    }

    fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), Self::Error> {
        check_write(self, offset, bytes.len()).map_err(RamFlashError::Kind)?;
        for (i, b) in bytes.iter().enumerate() {
            self.spend()?;
            self.bytes[offset as usize + i] &= b;
        }
        Ok(())
    }
}
