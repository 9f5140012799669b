//! Homing: find the encoder's offset by driving slowly into a hard stop
//! with a small force, and calling the place where the handle stalls the
//! stop's position.
//!
//! An incremental encoder counts from wherever the device was at power-on,
//! so a board knows its position only up to an offset until it has homed.
//! The law is a soft position servo (stiffness and damping a few percent of
//! the coupling's) whose set point creeps toward the stop at a fixed speed
//! and never leads the handle by more than the force limit allows, so that
//! pressing on the stop (or on a hand in the way) never pushes harder than
//! `force_limit_n`. It has stalled on the stop when the handle has stood
//! still, with the servo pushing at least [`STALL_FORCE_FRACTION`] of the
//! limit, for `stall_s`.

use crate::{param, ParamError, Position, Real, NM_PER_M};

/// Of the force limit, what the servo must push with for a stall to count:
/// a handle that stands still under less is held by something softer than
/// a stop (or by friction), not by the stop.
pub const STALL_FORCE_FRACTION: f32 = 0.8;

/// How to home one axis. Units are SI.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HomingConfig {
    /// Whether the stop lies toward positive positions.
    pub toward_positive: bool,
    /// Speed of the set point toward the stop (m/s).
    pub speed_mps: f32,
    /// The servo's stiffness (N/m).
    pub stiffness_npm: f32,
    /// The servo's damping (N s/m).
    pub damping_nspm: f32,
    /// The largest force homing pushes with (N).
    pub force_limit_n: f32,
    /// Below this speed the handle counts as standing still (m/s).
    pub stall_speed_mps: f32,
    /// How long the handle must stand still on the stop (s).
    pub stall_s: f32,
    /// Homing fails if it has not stalled after this long (s).
    pub timeout_s: f32,
    /// Where the handle is when it rests on the stop under the homing
    /// force: the position the encoder reads from then on.
    pub stop_position: Position,
    /// The encoder's index mark, where it has one: the position its
    /// pulse marks. Homing then ends at the first index pulse (the board
    /// calibrates from the count it latched) and a stall before it is a
    /// failure; without one, the stall on the stop ends it.
    pub index_position: Option<Position>,
    /// Control period `T` (s).
    pub period_s: f32,
}

impl HomingConfig {
    /// Gentle homing toward the negative end at `stop_position`, at
    /// period `period_s` (s): 20 mm/s, 2,000 N/m and 60 N s/m, at most
    /// 5 N, a stall of 0.1 s below 2 mm/s, and 10 s to find the stop.
    ///
    /// # Examples
    ///
    /// ```
    /// use twoport_control::homing::HomingConfig;
    /// use twoport_control::Position;
    /// let cfg = HomingConfig::gentle(Position::from_nm(-20_000_000), 1e-3);
    /// assert!(cfg.validate().is_ok());
    /// assert_eq!(cfg.force_limit_n, 5.0);
    /// ```
    pub const fn gentle(stop_position: Position, period_s: f32) -> Self {
        HomingConfig {
            toward_positive: false,
            speed_mps: 0.02,
            stiffness_npm: 2000.0,
            damping_nspm: 60.0,
            force_limit_n: 5.0,
            stall_speed_mps: 0.002,
            stall_s: 0.1,
            timeout_s: 10.0,
            stop_position,
            index_position: None,
            period_s,
        }
    }

    /// Check every field; the error names the field.
    pub fn validate(&self) -> Result<(), ParamError> {
        param::positive("homing.period_s (s)", self.period_s)?;
        param::positive("homing.speed_mps (m/s)", self.speed_mps)?;
        param::positive("homing.stiffness_npm (N/m)", self.stiffness_npm)?;
        param::non_negative("homing.damping_nspm (N s/m)", self.damping_nspm)?;
        param::positive("homing.force_limit_n (N)", self.force_limit_n)?;
        param::positive("homing.stall_speed_mps (m/s)", self.stall_speed_mps)?;
        param::positive("homing.stall_s (s)", self.stall_s)?;
        param::positive("homing.timeout_s (s)", self.timeout_s)?;
        if self.speed_mps * self.period_s * NM_PER_M < 1.0 {
            return Err(ParamError {
                name: "homing.speed_mps (m/s)",
                value: self.speed_mps,
                problem: "moves the set point less than 1 nm per tick",
            });
        }
        if self.stall_s > self.timeout_s {
            return Err(ParamError {
                name: "homing.stall_s (s)",
                value: self.stall_s,
                problem: "must not exceed homing.timeout_s",
            });
        }
        Ok(())
    }
}

/// Where a homing run stands after a tick.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HomingState {
    /// Still moving toward the stop.
    Seeking,
    /// Stalled on the stop: the encoder should now read
    /// [`HomingConfig::stop_position`].
    Found,
    /// No stall within the timeout (or, homing on an index, a stall
    /// before the pulse).
    TimedOut,
}

/// One homing run: the creeping set point, the stall detector and the
/// clock. Runs in f32, on the board.
#[derive(Clone, Copy, Debug)]
pub struct Homing {
    cfg: HomingConfig,
    /// The set point.
    set_point: Position,
    /// Set-point step per tick (nm), signed toward the stop.
    step_nm: i32,
    /// The largest lead of the set point over the handle (nm).
    lead_nm: i32,
    ticks: u32,
    still_ticks: u32,
    stall_ticks: u32,
    timeout_ticks: u32,
    state: HomingState,
}

impl Homing {
    /// A run of `cfg` from the handle's position `from`.
    pub fn new(cfg: HomingConfig, from: Position) -> Result<Self, ParamError> {
        cfg.validate()?;
        let dir = if cfg.toward_positive { 1.0 } else { -1.0 };
        let ticks = |s: f32| ((s / cfg.period_s + 0.5) as u32).max(1);
        Ok(Homing {
            set_point: from,
            step_nm: (dir * cfg.speed_mps * cfg.period_s * NM_PER_M) as i32,
            lead_nm: (cfg.force_limit_n / cfg.stiffness_npm * NM_PER_M).min(i32::MAX as f32) as i32,
            ticks: 0,
            still_ticks: 0,
            stall_ticks: ticks(cfg.stall_s),
            timeout_ticks: ticks(cfg.timeout_s),
            state: HomingState::Seeking,
            cfg,
        })
    }

    /// The configuration.
    pub fn config(&self) -> &HomingConfig {
        &self.cfg
    }

    /// Where the run stands.
    pub fn state(&self) -> HomingState {
        self.state
    }

    /// The set point (the servo's target this tick).
    pub fn set_point(&self) -> Position {
        self.set_point
    }

    /// One tick at handle position `x` and velocity `v_mps` (m/s): the
    /// actuator force (N, positive resists positive motion), within
    /// ±`force_limit_n`. Zero once the run has ended.
    pub fn step(&mut self, x: Position, v_mps: f32) -> f32 {
        if self.state != HomingState::Seeking {
            return 0.0;
        }
        // The set point creeps on, but never leads the handle by more than
        // the force limit's worth of spring: stalled, it waits.
        let next = self.set_point + self.step_nm;
        self.set_point = if self.step_nm > 0 {
            next.min(x + self.lead_nm)
        } else {
            next.max(x + -self.lead_nm)
        };
        let c = &self.cfg;
        let f = c.stiffness_npm * x.minus_m(self.set_point) + c.damping_nspm * v_mps;
        let limit = c.force_limit_n;
        let f = f.within(limit);
        // Pushing toward the stop is a negative force for a stop toward
        // positive positions (the force resists positive motion).
        let toward = if self.step_nm > 0 { -f } else { f };
        let still = v_mps.abs() < c.stall_speed_mps;
        if still && toward >= STALL_FORCE_FRACTION * limit {
            self.still_ticks += 1;
        } else {
            self.still_ticks = 0;
        }
        self.ticks += 1;
        if self.still_ticks >= self.stall_ticks {
            // Stalled: the stop, unless an index pulse was to come first.
            self.state = match c.index_position {
                None => HomingState::Found,
                Some(_) => HomingState::TimedOut,
            };
        } else if self.ticks >= self.timeout_ticks {
            self.state = HomingState::TimedOut;
        }
        f
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const T: f32 = 1e-3;

    /// A rigid mass `m_kg` with viscous damping on a stiff stop at
    /// `stop_m`, driven by the homing force: returns the run's end state,
    /// the handle's position (m) and the ticks it took.
    fn home_a_mass(
        cfg: HomingConfig,
        stop_m: Option<f32>,
        hand_npm: f32,
    ) -> (HomingState, f32, u32, f32) {
        let (m_kg, b_nspm, k_stop) = (0.5f32, 2.0f32, 2.0e5f32);
        let (mut x, mut v) = (0.0f32, 0.0f32);
        let mut h = Homing::new(cfg, Position::ZERO).unwrap();
        let mut peak = 0.0f32;
        let mut ticks = 0;
        while h.state() == HomingState::Seeking && ticks < 100_000 {
            let f_a = h.step(Position::from_m(x).unwrap(), v);
            peak = peak.max(f_a.abs());
            // 20 sub-steps of the plant per tick, the force held.
            for _ in 0..20 {
                let dt = T / 20.0;
                let mut f = -f_a - b_nspm * v - hand_npm * x;
                if let Some(s) = stop_m {
                    if x < s {
                        f += k_stop * (s - x) - 100.0 * v;
                    }
                }
                v += f / m_kg * dt;
                x += v * dt;
            }
            ticks += 1;
        }
        (h.state(), x, ticks, peak)
    }

    #[test]
    fn finds_the_stop_gently_and_in_time() {
        let cfg = HomingConfig::gentle(Position::from_nm(-20_000_000), T);
        let (state, x, ticks, peak) = home_a_mass(cfg, Some(-0.02), 0.0);
        assert_eq!(state, HomingState::Found);
        // Pressed onto the 2e5 N/m stop by at most 5 N: within 25 µm.
        assert!((x + 0.02).abs() < 30e-6, "stalled at {x} m");
        assert!(peak <= cfg.force_limit_n, "pushed {peak} N");
        // 20 mm at 20 mm/s, plus the stall time and the lag.
        assert!((1000..1400).contains(&ticks), "{ticks} ticks");
    }

    #[test]
    fn times_out_without_a_stop_and_never_exceeds_the_limit() {
        let mut cfg = HomingConfig::gentle(Position::ZERO, T);
        cfg.timeout_s = 1.5;
        let (state, x, ticks, peak) = home_a_mass(cfg, None, 0.0);
        assert_eq!(state, HomingState::TimedOut);
        assert_eq!(ticks, 1500);
        assert!(x < -0.025, "moved to {x} m");
        assert!(peak <= cfg.force_limit_n);
    }

    /// A handle held still (by a stop, or by a grip in the way) is a
    /// stall only once the servo pushes with most of its limit: the set
    /// point must first lead by over 2 mm (4 N at 2,000 N/m, 100 ticks of
    /// 20 µm), then the handle stand still for the 100 stall ticks. It stops
    /// leading at 2.5 mm, the full 5 N.
    #[test]
    fn stalls_only_under_most_of_the_force_limit() {
        let mut h = Homing::new(HomingConfig::gentle(Position::ZERO, T), Position::ZERO).unwrap();
        let mut ticks = 0;
        while h.state() == HomingState::Seeking && ticks < 1000 {
            h.step(Position::ZERO, 0.0);
            ticks += 1;
        }
        assert_eq!(h.state(), HomingState::Found);
        assert_eq!(ticks, 200);
        assert_eq!(h.set_point().nm(), -2_500_000);
    }

    #[test]
    fn toward_positive_pushes_the_other_way() {
        let mut cfg = HomingConfig::gentle(Position::from_nm(30_000_000), T);
        cfg.toward_positive = true;
        let mut h = Homing::new(cfg, Position::ZERO).unwrap();
        let f = (0..200)
            .map(|_| h.step(Position::ZERO, 0.0))
            .last()
            .unwrap();
        assert_eq!(f, -cfg.force_limit_n);
        assert_eq!(h.set_point().nm(), 2_500_000);
    }

    #[test]
    fn refuses_bad_configuration_by_name() {
        let mut cfg = HomingConfig::gentle(Position::ZERO, T);
        cfg.force_limit_n = f32::NAN;
        assert_eq!(cfg.validate().unwrap_err().name, "homing.force_limit_n (N)");
        let mut cfg = HomingConfig::gentle(Position::ZERO, T);
        cfg.speed_mps = 1e-7;
        assert_eq!(cfg.validate().unwrap_err().name, "homing.speed_mps (m/s)");
        let mut cfg = HomingConfig::gentle(Position::ZERO, T);
        cfg.stall_s = 20.0;
        assert_eq!(cfg.validate().unwrap_err().name, "homing.stall_s (s)");
    }
}
