//! The board's stored configuration, one record per axis in one flash
//! record: read at boot (falling back to the image's defaults, with the
//! reason, over the link), saved on the host's request while disarmed.

use super::Board;
use crate::io::IoScale;
use embedded_storage::nor_flash::NorFlash;
use twoport_config::{Config, HomingSetup, Limits, LoadCell, Store};
use twoport_control::drive::Drive;
use twoport_control::homing::HomingConfig;
use twoport_control::servo::Gains;
use twoport_control::{Position, SafetyConfig};
use twoport_link::{BoardMode, ConfigFallback, ConfigSource, Message, ModeRefusal, ModeRequest};

impl<D: Drive<N>, const R: usize, const N: usize> Board<D, R, N> {
    /// The configuration in force, each axis's as a record would store it.
    pub fn config(&self) -> [Config; N] {
        let limits = *self.servo.servo().safety().configs();
        let gains = self.servo.servo().gains();
        core::array::from_fn(|i| self.axis_config(i, &limits[i], gains[i]))
    }

    fn axis_config(&self, i: usize, s: &SafetyConfig, gains: Gains) -> Config {
        let h = &self.homing_cfg[i];
        let io = &self.io[i];
        Config {
            gains,
            load_cell: LoadCell {
                offset_counts: io.load_cell_offset_counts,
                n_per_count: io.load_cell_n_per_count,
            },
            homing: HomingSetup {
                stop_nm: h.stop_position.nm(),
                toward_positive: h.toward_positive,
                force_limit_n: h.force_limit_n,
                index_nm: h.index_position.map(Position::nm),
            },
            limits: Limits {
                peak_force_n: s.peak_force_n,
                continuous_force_n: s.continuous_force_n,
                max_velocity_mps: s.max_velocity_mps,
                heartbeat_timeout_ticks: s.heartbeat_timeout_ticks,
            },
        }
    }

    /// Where the configuration in force came from (`None` before
    /// [`boot_config`](Self::boot_config)).
    pub fn config_source(&self) -> Option<ConfigSource> {
        self.config_source
    }

    /// Put `cfg` in force, every axis's all of it or, with the reason,
    /// none: each axis's gains must lie in its proven region and every
    /// value must hold. Disarmed only.
    pub fn apply_config(&mut self, cfg: &[Config; N]) -> Result<(), ConfigFallback> {
        if self.mode != BoardMode::Disarmed || cfg.iter().any(|c| c.validate().is_err()) {
            return Err(ConfigFallback::Invalid);
        }
        let gains = cfg.map(|c| c.gains);
        if self.check(&gains).is_err() {
            return Err(ConfigFallback::NotProven);
        }
        let now = *self.servo.servo().safety().configs();
        let limits: [SafetyConfig; N] = core::array::from_fn(|i| SafetyConfig {
            peak_force_n: cfg[i].limits.peak_force_n,
            continuous_force_n: cfg[i].limits.continuous_force_n,
            max_velocity_mps: cfg[i].limits.max_velocity_mps,
            heartbeat_timeout_ticks: cfg[i].limits.heartbeat_timeout_ticks,
            ..now[i]
        });
        let homing: [HomingConfig; N] = core::array::from_fn(|i| HomingConfig {
            stop_position: Position::from_nm(cfg[i].homing.stop_nm),
            toward_positive: cfg[i].homing.toward_positive,
            force_limit_n: cfg[i].homing.force_limit_n,
            index_position: cfg[i].homing.index_nm.map(Position::from_nm),
            ..self.homing_cfg[i]
        });
        if limits.iter().any(|l| l.validate().is_err())
            || homing.iter().any(|h| h.validate().is_err())
        {
            return Err(ConfigFallback::Invalid);
        }
        // Gains first: the only step that can still refuse, and it
        // changes nothing when it does.
        let old = self.servo.servo().gains();
        self.servo
            .servo_mut()
            .set_gains(gains)
            .map_err(|_| ConfigFallback::Invalid)?;
        if self.servo.servo_mut().set_limits(limits).is_err() {
            // Validated above and disarmed: unreachable, but never half
            // applied.
            let _ = self.servo.servo_mut().set_gains(old);
            return Err(ConfigFallback::Invalid);
        }
        self.homing_cfg = homing;
        for (io, c) in self.io.iter_mut().zip(cfg) {
            *io = IoScale {
                load_cell_offset_counts: c.load_cell.offset_counts,
                load_cell_n_per_count: c.load_cell.n_per_count,
                ..*io
            };
        }
        Ok(())
    }

    /// At boot: the stored configuration if there is a valid one that this
    /// image can run, else the image's own, and a [`Message::Config`]
    /// saying which and why.
    pub fn boot_config<F: NorFlash>(&mut self, store: &mut Store<F>) -> ConfigSource {
        let defaults = self.config();
        let (cfg, mut source) = store.load_axes(&defaults);
        if let ConfigSource::Stored { .. } = source {
            if let Err(why) = self.apply_config(&cfg) {
                let _ = self.apply_config(&defaults);
                source = ConfigSource::Defaults { why };
            }
        }
        self.config_source = Some(source);
        self.queue(Message::Config(source));
        source
    }

    /// `SaveConfig`: remembered for the main loop, which owns the flash.
    pub(super) fn request_save(&mut self) {
        match self.mode {
            BoardMode::Disarmed => self.save_pending = true,
            mode => self.refuse(ModeRequest::SaveConfig, ModeRefusal::NotDisarmed { mode }),
        }
    }

    /// The main loop's part: write a requested save to `store` and report
    /// the outcome. Writing flash may stall the processor for the erase,
    /// so it runs only while disarmed (checked again here).
    pub fn service_config<F: NorFlash>(&mut self, store: &mut Store<F>) {
        if !core::mem::take(&mut self.save_pending) {
            return;
        }
        if self.mode != BoardMode::Disarmed {
            let mode = self.mode;
            return self.refuse(ModeRequest::SaveConfig, ModeRefusal::NotDisarmed { mode });
        }
        match store.save_axes(&self.config()) {
            Ok(seq) => {
                let source = ConfigSource::Stored { seq };
                self.config_source = Some(source);
                self.queue(Message::Config(source));
            }
            Err(_) => self.refuse(ModeRequest::SaveConfig, ModeRefusal::FlashFailed),
        }
    }

    pub(super) fn report_config(&mut self) {
        if let Some(s) = self.config_source {
            self.queue(Message::Config(s));
        }
    }
}
