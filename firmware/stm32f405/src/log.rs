//! What the hardware image logs over RTT with the `defmt` feature: the
//! stored configuration at boot, a watchdog reset, and each change of mode
//! or of the latched faults. Without the feature every call here is empty,
//! and the QEMU builds report through semihosting and the link instead.

use twoport_link::{ConfigSource, Status};

#[cfg(feature = "defmt")]
use defmt_rtt as _;

/// The configuration the board boots with.
pub fn config(source: ConfigSource) {
    #[cfg(feature = "defmt")]
    match source {
        ConfigSource::Stored { seq } => defmt::info!("configuration: stored record {}", seq),
        ConfigSource::Defaults { why } => {
            defmt::warn!("configuration: defaults ({})", defmt::Debug2Format(&why))
        }
    }
    #[cfg(not(feature = "defmt"))]
    let _ = source;
}

/// The last reset was the watchdog's.
pub fn watchdog_reset() {
    #[cfg(feature = "defmt")]
    defmt::error!("restarted by the watchdog: the loop hung");
}

/// The state last logged, to log only changes.
#[derive(Default)]
pub struct Seen(Option<Status>);

impl Seen {
    /// Log `now` where its mode or faults differ from the last seen.
    pub fn changes(&mut self, now: Status) {
        let changed = self
            .0
            .is_none_or(|s| (s.mode, s.faults) != (now.mode, now.faults));
        if changed {
            #[cfg(feature = "defmt")]
            defmt::info!(
                "mode {}, calibrated {}, faults {=u16:#06x}",
                defmt::Debug2Format(&now.mode),
                now.calibrated,
                now.faults
            );
            self.0 = Some(now);
        }
    }
}
