//! Two copies of the record in two erase units of a NOR flash, so that a
//! power loss at any instant of a save loses nothing that was committed.
//!
//! A save writes the copy that is not the newest valid one: it erases that
//! unit, writes the record without its magic word, reads it back, and only
//! then writes the magic word, which commits it. Cut anywhere before that
//! word and the unit holds no record, so the other copy, the last one
//! committed, is what the next boot reads; cut after it and the new one
//! is. Boot reads both and takes the valid one with the higher sequence
//! number.

use crate::record::{self, Config, RecordError, FORMAT_VERSION, MAGIC, MAX_RECORD};
use embedded_storage::nor_flash::NorFlash;
use twoport_link::{ConfigFallback, ConfigSource};

/// Why a save did not commit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum SaveError {
    /// The config does not validate (the field is named).
    Invalid(&'static str),
    /// The flash refused an erase, write or read.
    Flash,
    /// What was read back is not what was written.
    Verify,
    /// The flash's write unit does not divide the 4-byte magic word.
    Unsupported,
}

/// The two-copy store over `F`, its copies at byte offsets `a` and `b`,
/// each at the start of an erase unit of its own.
#[derive(Debug)]
pub struct Store<F> {
    flash: F,
    slots: [u32; 2],
}

/// One copy's state: its sequence number and configs, or why it is not
/// usable (`None`: the flash could not be read).
type SlotCopy<const N: usize> = Result<(u32, [Config; N]), Option<RecordError>>;

/// `a` is newer than `b`, across the sequence number's wrap.
fn newer(a: u32, b: u32) -> bool {
    (a.wrapping_sub(b) as i32) > 0
}

impl<F: NorFlash> Store<F> {
    /// A store in `flash` with its copies at offsets `a` and `b`.
    pub fn new(flash: F, a: u32, b: u32) -> Self {
        Store {
            flash,
            slots: [a, b],
        }
    }

    /// The flash, back.
    pub fn into_inner(self) -> F {
        self.flash
    }

    /// The flash, for tests that cut its power.
    pub fn flash_mut(&mut self) -> &mut F {
        &mut self.flash
    }

    fn read_slot<const N: usize>(&mut self, i: usize) -> SlotCopy<N> {
        let mut buf = [0u8; MAX_RECORD];
        self.flash.read(self.slots[i], &mut buf).map_err(|_| None)?;
        record::decode_axes(&buf).map_err(Some)
    }

    /// Each copy's state.
    fn read_both<const N: usize>(&mut self) -> [SlotCopy<N>; 2] {
        [self.read_slot(0), self.read_slot(1)]
    }

    /// The newest valid copy: its slot, sequence number and config.
    fn newest<const N: usize>(copies: &[SlotCopy<N>; 2]) -> Option<(usize, u32, [Config; N])> {
        let mut best: Option<(usize, u32, [Config; N])> = None;
        for (i, c) in copies.iter().enumerate() {
            if let Ok((seq, cfg)) = c {
                if best.is_none_or(|(_, s, _)| newer(*seq, s)) {
                    best = Some((i, *seq, *cfg));
                }
            }
        }
        best
    }

    /// The configuration to run: the newest valid copy, or `defaults`
    /// with the reason none is usable.
    pub fn load(&mut self, defaults: &Config) -> (Config, ConfigSource) {
        let ([c], source) = self.load_axes(&[*defaults]);
        (c, source)
    }

    /// [`load`](Self::load) for a board of `N` axes: a record of another
    /// number of axes is not used, and the fallback says so.
    pub fn load_axes<const N: usize>(
        &mut self,
        defaults: &[Config; N],
    ) -> ([Config; N], ConfigSource) {
        let copies = self.read_both::<N>();
        if let Some((_, seq, cfg)) = Self::newest(&copies) {
            return (cfg, ConfigSource::Stored { seq });
        }
        // The most telling reason of the two copies.
        let rank = |e: &Option<RecordError>| -> (u8, ConfigFallback) {
            match *e {
                None => (5, ConfigFallback::Unreadable),
                Some(RecordError::Version(v)) if v < FORMAT_VERSION => {
                    (4, ConfigFallback::OlderVersion { found: v })
                }
                Some(RecordError::Version(v)) => (4, ConfigFallback::NewerVersion { found: v }),
                Some(RecordError::Invalid(_)) => (3, ConfigFallback::Invalid),
                Some(RecordError::Axes { found }) => (3, ConfigFallback::WrongAxes { found }),
                Some(RecordError::Absent) => (1, ConfigFallback::Missing),
                Some(_) => (2, ConfigFallback::Corrupt),
            }
        };
        let why = copies
            .iter()
            .filter_map(|c| c.as_ref().err())
            .map(rank)
            .max_by_key(|(r, _)| *r)
            .map_or(ConfigFallback::Missing, |(_, w)| w);
        (*defaults, ConfigSource::Defaults { why })
    }

    /// Commit `config` as the newest record; returns its sequence number.
    pub fn save(&mut self, config: &Config) -> Result<u32, SaveError> {
        self.save_axes(core::array::from_ref(config))
    }

    /// [`save`](Self::save) for a board of `N` axes: one record holding
    /// every axis's config. A record of another number of axes already
    /// there is overwritten in turn, as an invalid one would be.
    pub fn save_axes<const N: usize>(&mut self, configs: &[Config; N]) -> Result<u32, SaveError> {
        for c in configs {
            c.validate().map_err(SaveError::Invalid)?;
        }
        if F::WRITE_SIZE == 0 || 4 % F::WRITE_SIZE != 0 {
            return Err(SaveError::Unsupported);
        }
        let copies = self.read_both::<N>();
        let (target, seq) = match Self::newest(&copies) {
            Some((i, s, _)) => (1 - i, s.wrapping_add(1)),
            None => (0, 1),
        };
        let mut buf = [0xFFu8; MAX_RECORD + 4];
        let n = record::encode_axes(configs, seq, &mut buf).ok_or(SaveError::Invalid("record"))?;
        // Pad to whole write units; the padding stays erased.
        let padded = n.div_ceil(F::WRITE_SIZE) * F::WRITE_SIZE;
        let at = self.slots[target];
        let unit = F::ERASE_SIZE as u32;
        self.flash
            .erase(at, at + unit)
            .map_err(|_| SaveError::Flash)?;
        self.flash
            .write(at + 4, &buf[4..padded])
            .map_err(|_| SaveError::Flash)?;
        let mut back = [0u8; MAX_RECORD];
        self.flash
            .read(at, &mut back)
            .map_err(|_| SaveError::Flash)?;
        if back[4..n] != buf[4..n] {
            return Err(SaveError::Verify);
        }
        self.flash.write(at, &MAGIC).map_err(|_| SaveError::Flash)?;
        match self.read_slot(target) {
            Ok((s, c)) if s == seq && c == *configs => Ok(seq),
            Err(None) => Err(SaveError::Flash),
            _ => Err(SaveError::Verify),
        }
    }
}
