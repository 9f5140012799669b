//! The safety layer between every law and the actuator. Whatever a law asks
//! for, the actuator gets at most this layer's answer; any fault gives zero
//! force in the same tick, latches, and is reported until explicitly cleared.

use crate::{param, ParamError, Real};
use core::fmt;

/// A set of fault reasons (bit flags).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Faults(pub u16);

impl Faults {
    /// No fault.
    pub const NONE: Faults = Faults(0);
    /// A sensor gave NaN or infinity.
    pub const SENSOR_NOT_FINITE: Faults = Faults(1 << 0);
    /// A sensor reading is beyond its range or at its rail.
    pub const SENSOR_OUT_OF_RANGE: Faults = Faults(1 << 1);
    /// The encoder gave a raw value its counter cannot hold.
    pub const ENCODER_INVALID: Faults = Faults(1 << 2);
    /// The handle moved faster than the velocity limit.
    pub const VELOCITY_LIMIT: Faults = Faults(1 << 3);
    /// The dead-man switch opened while enabled.
    pub const DEAD_MAN: Faults = Faults(1 << 4);
    /// A control tick was missed (the tick counter skipped).
    pub const MISSED_TICK: Faults = Faults(1 << 5);
    /// No link heartbeat within the timeout while enabled.
    pub const HEARTBEAT_LOST: Faults = Faults(1 << 6);
    /// A law produced a non-finite force.
    pub const COMMAND_NOT_FINITE: Faults = Faults(1 << 7);
    /// Homing found no hard stop: it timed out, or its own checks failed.
    pub const HOMING_FAILED: Faults = Faults(1 << 8);
    /// The board restarted from its watchdog: the loop had hung.
    pub const WATCHDOG_RESET: Faults = Faults(1 << 9);

    const NAMES: [(Faults, &'static str); 10] = [
        (Faults::SENSOR_NOT_FINITE, "sensor reading not finite"),
        (Faults::SENSOR_OUT_OF_RANGE, "sensor reading out of range"),
        (Faults::ENCODER_INVALID, "encoder value invalid"),
        (Faults::VELOCITY_LIMIT, "velocity limit exceeded"),
        (Faults::DEAD_MAN, "dead-man switch released"),
        (Faults::MISSED_TICK, "control tick missed"),
        (Faults::HEARTBEAT_LOST, "link heartbeat lost"),
        (Faults::COMMAND_NOT_FINITE, "force command not finite"),
        (Faults::HOMING_FAILED, "homing found no hard stop"),
        (Faults::WATCHDOG_RESET, "watchdog reset: the loop hung"),
    ];

    /// Whether no fault is set.
    pub const fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// Whether every fault of `other` is set.
    pub const fn contains(self, other: Faults) -> bool {
        self.0 & other.0 == other.0
    }

    /// The union.
    pub const fn with(self, other: Faults) -> Faults {
        Faults(self.0 | other.0)
    }

    /// The lowest-numbered fault set, alone.
    pub const fn lowest(self) -> Faults {
        Faults(self.0 & self.0.wrapping_neg())
    }

    /// Each set fault's description.
    pub fn names(self) -> impl Iterator<Item = &'static str> {
        Self::NAMES
            .into_iter()
            .filter(move |(f, _)| self.contains(*f))
            .map(|(_, n)| n)
    }
}

impl fmt::Display for Faults {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.is_empty() {
            return f.write_str("no fault");
        }
        for (i, n) in self.names().enumerate() {
            if i > 0 {
                f.write_str(", ")?;
            }
            f.write_str(n)?;
        }
        Ok(())
    }
}

/// Limits of one actuator axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SafetyConfig {
    /// Sample period `T` (s).
    pub period_s: f32,
    /// Largest force at any instant (N).
    pub peak_force_n: f32,
    /// Largest force that may be held indefinitely (N).
    pub continuous_force_n: f32,
    /// Time at peak force from cold before the thermal budget folds the limit
    /// back to the continuous force (s). Sets the I^2 t budget
    /// `(peak^2 - continuous^2) * peak_duration`.
    pub peak_duration_s: f32,
    /// Largest handle speed (m/s).
    pub max_velocity_mps: f32,
    /// Load-cell range (N): a reading beyond it is a fault.
    pub max_sensor_force_n: f32,
    /// Ticks without a link heartbeat before a fault; 0 disables the check.
    pub heartbeat_timeout_ticks: u32,
    /// Ticks over which force ramps in after enable or clear (>= 1).
    pub ramp_ticks: u32,
    /// Whether an open dead-man switch is a fault.
    pub require_dead_man: bool,
}

impl SafetyConfig {
    /// A cautious configuration for any actuator: `peak_force_n` (N) for
    /// at most 2 s from cold, `continuous_force_n` (N) indefinitely, at
    /// period `period_s` (s); 1 m/s at most, a load-cell range of 1.25 times
    /// the peak, a 100 ms ramp-in, the dead-man switch required and no link
    /// heartbeat. Adjust the fields for the device; [`validate`](Self::validate)
    /// names a bad one.
    ///
    /// # Examples
    ///
    /// ```
    /// use twoport_control::SafetyConfig;
    /// let cfg = SafetyConfig::new(1e-3, 10.0, 4.0);
    /// assert!(cfg.validate().is_ok());
    /// assert!(cfg.require_dead_man);
    /// assert!(SafetyConfig::new(1e-3, 4.0, 10.0).validate().is_err());
    /// ```
    pub fn new(period_s: f32, peak_force_n: f32, continuous_force_n: f32) -> Self {
        SafetyConfig {
            period_s,
            peak_force_n,
            continuous_force_n,
            peak_duration_s: 2.0,
            max_velocity_mps: 1.0,
            max_sensor_force_n: 1.25 * peak_force_n,
            heartbeat_timeout_ticks: 0,
            ramp_ticks: ((0.1 / period_s) as u32).max(1),
            require_dead_man: true,
        }
    }

    /// Excalibur's axis: 200 N peak, 100 N continuous (paper section III),
    /// 2 s at peak, 1 m/s, a 250 N load cell, 100 ms ramp, 1 kHz.
    pub const fn excalibur() -> Self {
        SafetyConfig {
            period_s: 1.0e-3,
            peak_force_n: 200.0,
            continuous_force_n: 100.0,
            peak_duration_s: 2.0,
            max_velocity_mps: 1.0,
            max_sensor_force_n: 250.0,
            heartbeat_timeout_ticks: 0,
            ramp_ticks: 100,
            require_dead_man: false,
        }
    }

    /// Check every field; the error names the field.
    pub fn validate(&self) -> Result<(), ParamError> {
        param::positive("safety.period_s (s)", self.period_s)?;
        param::positive("safety.peak_force_n (N)", self.peak_force_n)?;
        param::positive("safety.continuous_force_n (N)", self.continuous_force_n)?;
        if self.continuous_force_n > self.peak_force_n {
            return Err(ParamError {
                name: "safety.continuous_force_n (N)",
                value: self.continuous_force_n,
                problem: "must not exceed safety.peak_force_n",
            });
        }
        param::non_negative("safety.peak_duration_s (s)", self.peak_duration_s)?;
        param::positive("safety.max_velocity_mps (m/s)", self.max_velocity_mps)?;
        param::positive("safety.max_sensor_force_n (N)", self.max_sensor_force_n)?;
        if self.ramp_ticks == 0 {
            return Err(ParamError {
                name: "safety.ramp_ticks",
                value: 0.0,
                problem: "must be >= 1",
            });
        }
        Ok(())
    }

    fn thermal_budget(&self) -> f32 {
        let (p, c) = (self.peak_force_n, self.continuous_force_n);
        (p * p - c * c) * self.peak_duration_s
    }
}

/// What the safety layer needs to know besides the force command.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SafetyInputs<R = f32> {
    /// The control tick number from the timer (wraps).
    pub tick: u32,
    /// Whether the dead-man switch is closed (operator present).
    pub dead_man_closed: bool,
    /// Handle or actuator velocity estimate (m/s).
    pub velocity_mps: R,
    /// Faults the sensor checks found this tick.
    pub sensor_faults: Faults,
}

/// [`SafetyInputs`] of a servo with `N` axes: one tick counter, one dead-man
/// switch, one velocity per axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AxesInputs<R, const N: usize> {
    /// The control tick number from the timer (wraps).
    pub tick: u32,
    /// Whether the dead-man switch is closed (operator present).
    pub dead_man_closed: bool,
    /// Each axis's handle or actuator velocity estimate (m/s).
    pub velocity_mps: [R; N],
    /// Faults the sensor checks of any axis found this tick.
    pub sensor_faults: Faults,
}

/// The actuator command after the safety layer.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SafeForce<R = f32> {
    /// The force to hold on the actuator this tick (N).
    pub force_n: R,
    /// Every latched fault (empty when running).
    pub faults: Faults,
    /// Whether the force was clipped (peak, thermal fold-back or ramp).
    pub limited: bool,
}

/// [`SafeForce`] of `N` axes: while any fault is latched, every axis is zero.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SafeForces<R, const N: usize> {
    /// The force to hold on each axis's actuator this tick (N).
    pub force_n: [R; N],
    /// Every latched fault, whichever axis found it (empty when running).
    pub faults: Faults,
    /// Whether each axis's force was clipped (peak, thermal fold-back or
    /// ramp).
    pub limited: [bool; N],
}

/// A limit or gain refused on one axis of a multi-axis layer or servo.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AxisError<E = ParamError> {
    /// The axis (0 is x).
    pub axis: usize,
    /// What is wrong with it.
    pub error: E,
}

impl<E> AxisError<E> {
    /// `error` on axis `axis`.
    pub const fn new(axis: usize, error: E) -> Self {
        AxisError { axis, error }
    }
}

impl<E: fmt::Display> fmt::Display for AxisError<E> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "axis {}: {}", self.axis, self.error)
    }
}

impl<E: fmt::Debug + fmt::Display> core::error::Error for AxisError<E> {}

/// Limits, guards, watchdogs, the fault latch and the ramp-in, for the `N`
/// Cartesian axes of one device (`N = 1` unless named).
///
/// Each axis has its own motor: its peak and continuous force, its I²t
/// budget, its speed limit and its load-cell range. The axes share one tick
/// counter, one dead-man switch, one heartbeat, one ramp-in and one latch,
/// so a fault that any axis finds gives zero force on every axis in the
/// tick that finds it. The shared fields of the axes' [`SafetyConfig`]s
/// (period, ramp, heartbeat, dead-man) must agree.
#[derive(Clone, Copy, Debug)]
pub struct SafetyLayer<R = f32, const N: usize = 1> {
    cfg: [SafetyConfig; N],
    budget: [f32; N],
    enabled: bool,
    latched: Faults,
    first: Faults,
    ramp_done: u32,
    /// Each motor's I^2 t state above its continuous rating (N^2 s), >= 0.
    heat: [R; N],
    /// The tick number the next step must bring.
    next_tick: u32,
    /// Whether a tick has been seen (the first may bring any number).
    ticking: bool,
    heartbeat_age: u32,
    /// Largest heartbeat age that is not a fault (`u32::MAX`: unchecked).
    heartbeat_limit: u32,
    /// Each `continuous_force_n^2` (N^2), the heat a motor sheds per second.
    continuous_sq_n2: [R; N],
    /// `T` (s).
    period: R,
}

impl SafetyLayer {
    /// A disabled layer with the given limits.
    pub fn new(cfg: SafetyConfig) -> Result<Self, ParamError> {
        Self::new_in(cfg)
    }
}

impl<R: Real> SafetyLayer<R> {
    /// [`SafetyLayer::new`] computing in `R`.
    pub fn new_in(cfg: SafetyConfig) -> Result<Self, ParamError> {
        Self::for_axes([cfg]).map_err(|e| e.error)
    }

    /// The limits.
    pub fn config(&self) -> &SafetyConfig {
        &self.cfg[0]
    }

    /// New limits (a stored configuration, at boot): only while disabled,
    /// and only limits that validate; the thermal state and the latch are
    /// kept. The period must stay the laws'.
    pub fn reconfigure(&mut self, cfg: SafetyConfig) -> Result<(), ParamError> {
        self.reconfigure_axes([cfg]).map_err(|e| e.error)
    }

    /// The thermal state as a fraction of the I^2 t budget (1 = folded back).
    pub fn thermal_load(&self) -> f32 {
        self.thermal_load_of(0)
    }

    /// One tick: check, latch, limit, ramp. Call exactly once per tick.
    // (Always inlined: called once per tick, and a call would pass its
    // inputs and answer through memory, 30 of the board tick's instructions.)
    #[inline(always)]
    pub fn step(&mut self, inputs: &SafetyInputs<R>, command_n: R) -> SafeForce<R> {
        let out = self.step_axes(
            &AxesInputs {
                tick: inputs.tick,
                dead_man_closed: inputs.dead_man_closed,
                velocity_mps: [inputs.velocity_mps],
                sensor_faults: inputs.sensor_faults,
            },
            [command_n],
        );
        SafeForce {
            force_n: out.force_n[0],
            faults: out.faults,
            limited: out.limited[0],
        }
    }
}

impl<R: Real, const N: usize> SafetyLayer<R, N> {
    /// A disabled layer with each axis's limits; the error names the axis
    /// and the field.
    ///
    /// # Examples
    ///
    /// ```
    /// use twoport_control::{SafetyConfig, SafetyLayer};
    /// let axis = SafetyConfig::excalibur();
    /// let layer = SafetyLayer::<f32, 3>::for_axes([axis; 3])?;
    /// assert_eq!(layer.configs()[2].peak_force_n, 200.0);
    /// // The axes share one period: a z axis at 2 kHz is refused, by name.
    /// let z = SafetyConfig { period_s: 5e-4, ..axis };
    /// let e = SafetyLayer::<f32, 3>::for_axes([axis, axis, z]).unwrap_err();
    /// assert_eq!((e.axis, e.error.name), (2, "safety.period_s (s)"));
    /// # Ok::<(), twoport_control::safety::AxisError>(())
    /// ```
    pub fn for_axes(cfg: [SafetyConfig; N]) -> Result<Self, AxisError> {
        Self::check_axes(&cfg)?;
        let period = match cfg.first() {
            Some(c) => c.period_s,
            None => {
                return Err(AxisError {
                    axis: 0,
                    error: ParamError {
                        name: "axes",
                        value: 0.0,
                        problem: "must be at least one",
                    },
                })
            }
        };
        let heartbeat_limit = match cfg[0].heartbeat_timeout_ticks {
            0 => u32::MAX,
            t => t,
        };
        Ok(SafetyLayer {
            budget: cfg.map(|c| c.thermal_budget()),
            continuous_sq_n2: cfg
                .map(|c| R::of(c.continuous_force_n) * R::of(c.continuous_force_n)),
            cfg,
            enabled: false,
            latched: Faults::NONE,
            first: Faults::NONE,
            ramp_done: 0,
            heat: [R::ZERO; N],
            next_tick: 0,
            ticking: false,
            heartbeat_age: 0,
            heartbeat_limit,
            period: R::of(period),
        })
    }

    /// Each axis's limits valid, and the shared fields the same on every
    /// axis.
    fn check_axes(cfg: &[SafetyConfig; N]) -> Result<(), AxisError> {
        for (axis, c) in cfg.iter().enumerate() {
            let at = |error| AxisError { axis, error };
            c.validate().map_err(at)?;
            let x = &cfg[0];
            for (same, name, value) in [
                (c.period_s == x.period_s, "safety.period_s (s)", c.period_s),
                (
                    c.ramp_ticks == x.ramp_ticks,
                    "safety.ramp_ticks",
                    c.ramp_ticks as f32,
                ),
                (
                    c.heartbeat_timeout_ticks == x.heartbeat_timeout_ticks,
                    "safety.heartbeat_timeout_ticks",
                    c.heartbeat_timeout_ticks as f32,
                ),
                (
                    c.require_dead_man == x.require_dead_man,
                    "safety.require_dead_man",
                    c.require_dead_man as u8 as f32,
                ),
            ] {
                if !same {
                    return Err(at(ParamError {
                        name,
                        value,
                        problem: "must be the same on every axis",
                    }));
                }
            }
        }
        Ok(())
    }

    /// Each axis's limits.
    pub fn configs(&self) -> &[SafetyConfig; N] {
        &self.cfg
    }

    /// New limits for every axis (see [`reconfigure`](SafetyLayer::reconfigure)).
    pub fn reconfigure_axes(&mut self, cfg: [SafetyConfig; N]) -> Result<(), AxisError> {
        Self::check_axes(&cfg)?;
        if self.enabled {
            return Err(AxisError {
                axis: 0,
                error: ParamError {
                    name: "safety",
                    value: 0.0,
                    problem: "can change only while disabled",
                },
            });
        }
        if let Some(c) = cfg.first().filter(|c| c.period_s != self.cfg[0].period_s) {
            return Err(AxisError {
                axis: 0,
                error: ParamError {
                    name: "safety.period_s (s)",
                    value: c.period_s,
                    problem: "must stay the laws' period",
                },
            });
        }
        let fresh = Self::for_axes(cfg)?;
        *self = SafetyLayer {
            heat: self.heat,
            latched: self.latched,
            first: self.first,
            next_tick: self.next_tick,
            ticking: self.ticking,
            ..fresh
        };
        Ok(())
    }

    /// Enable force output, ramping in. Refused while a fault is latched.
    pub fn enable(&mut self) -> Result<(), Faults> {
        if !self.latched.is_empty() {
            return Err(self.latched);
        }
        if !self.enabled {
            self.enabled = true;
            self.ramp_done = 0;
            self.heartbeat_age = 0;
        }
        Ok(())
    }

    /// Disable force output (not a fault).
    pub fn disable(&mut self) {
        self.enabled = false;
    }

    /// Whether force output is enabled (it may still be faulted).
    pub fn is_enabled(&self) -> bool {
        self.enabled
    }

    /// Clear the latch. If enabled, force ramps in again from zero; a
    /// condition that persists latches again on the next tick.
    pub fn clear(&mut self) {
        self.latched = Faults::NONE;
        self.first = Faults::NONE;
        self.ramp_done = 0;
        self.heartbeat_age = 0;
    }

    /// A link heartbeat arrived.
    pub fn heartbeat(&mut self) {
        self.heartbeat_age = 0;
    }

    /// Latched faults.
    pub fn faults(&self) -> Faults {
        self.latched
    }

    /// The fault that latched first (the likely cause).
    pub fn first_fault(&self) -> Faults {
        self.first
    }

    /// Axis `axis`'s thermal state as a fraction of its I^2 t budget (1 =
    /// folded back); 0 for an axis the layer does not have.
    pub fn thermal_load_of(&self, axis: usize) -> f32 {
        let (Some(heat), Some(&budget)) = (self.heat.get(axis), self.budget.get(axis)) else {
            return 0.0;
        };
        let heat = heat.to_f32();
        if budget > 0.0 {
            heat / budget
        } else if heat > 0.0 {
            1.0
        } else {
            0.0
        }
    }

    /// The faults behind a tick whose checks did not all pass.
    #[cold]
    fn found(
        cfg: &[SafetyConfig; N],
        velocity_mps: [R; N],
        sensor_faults: Faults,
        [tick_ok, dead_man_open, heartbeat_lost, command_ok]: [bool; 4],
    ) -> Faults {
        let mut f = sensor_faults;
        for (v, c) in velocity_mps.iter().zip(cfg) {
            // (NaN fails the comparison too.)
            let within = v.abs() <= R::of(c.max_velocity_mps);
            if !within {
                f = f.with(if v.is_finite() {
                    Faults::VELOCITY_LIMIT
                } else {
                    Faults::SENSOR_NOT_FINITE
                });
            }
        }
        for (bad, fault) in [
            (!tick_ok, Faults::MISSED_TICK),
            (dead_man_open, Faults::DEAD_MAN),
            (heartbeat_lost, Faults::HEARTBEAT_LOST),
            (!command_ok, Faults::COMMAND_NOT_FINITE),
        ] {
            if bad {
                f = f.with(fault);
            }
        }
        f
    }

    /// Latch `f` now (faults found outside `step`, e.g. by the link).
    pub fn trip(&mut self, f: Faults) {
        if f.is_empty() {
            return;
        }
        if self.latched.is_empty() {
            self.first = f.lowest();
        }
        self.latched = self.latched.with(f);
    }

    /// Axis `i`'s finite `command` (N) clipped to its peak force, or to its
    /// continuous force once its I²t budget is spent.
    #[inline(always)]
    fn clip(&self, i: usize, command: R) -> R {
        let c = &self.cfg[i];
        let limit = R::of(if self.heat[i] >= R::of(self.budget[i]) {
            c.continuous_force_n
        } else {
            c.peak_force_n
        });
        // (Not `clamp`, which carries an assertion on its bounds; the
        // command is finite here, or a fault would have latched.)
        if command > limit {
            limit
        } else if command < -limit {
            -limit
        } else {
            command
        }
    }

    /// One tick of every axis: check, latch, limit, ramp. Call exactly once
    /// per tick.
    #[inline(always)]
    pub fn step_axes(&mut self, inputs: &AxesInputs<R, N>, command_n: [R; N]) -> SafeForces<R, N> {
        // Every check a good tick passes, as flags joined into one branch;
        // the cold path works out which faults they were.
        // (One comparison for each speed: NaN fails it too.)
        let mut speed_ok = true;
        let mut command_ok = true;
        for ((v, c), f) in inputs.velocity_mps.iter().zip(&self.cfg).zip(&command_n) {
            speed_ok &= v.abs() <= R::of(c.max_velocity_mps);
            command_ok &= f.is_finite();
        }
        let tick_ok = (inputs.tick == self.next_tick) | !self.ticking;
        self.next_tick = inputs.tick.wrapping_add(1);
        self.ticking = true;
        let enabled = self.enabled;
        self.heartbeat_age = self.heartbeat_age.saturating_add(enabled as u32);
        let shared = &self.cfg[0];
        let dead_man_open = enabled & shared.require_dead_man & !inputs.dead_man_closed;
        let heartbeat_lost = enabled & (self.heartbeat_age > self.heartbeat_limit);
        let sensors_ok = inputs.sensor_faults.is_empty();
        if !(speed_ok & tick_ok & !dead_man_open & !heartbeat_lost & command_ok & sensors_ok) {
            self.trip(Self::found(
                &self.cfg,
                inputs.velocity_mps,
                inputs.sensor_faults,
                [tick_ok, dead_man_open, heartbeat_lost, command_ok],
            ));
        }

        let mut out = SafeForces {
            force_n: [R::ZERO; N],
            faults: self.latched,
            limited: [false; N],
        };
        if self.enabled && self.latched.is_empty() {
            // (ramp_done <= ramp_ticks always; once ramped in, the force
            // passes with neither a division nor a multiplication.)
            let ramp_ticks = self.cfg[0].ramp_ticks;
            if self.ramp_done < ramp_ticks {
                self.ramp_done += 1;
                let ramping = self.ramp_done < ramp_ticks;
                let fraction = R::of(self.ramp_done as f32 / ramp_ticks as f32);
                for (i, &command) in command_n.iter().enumerate() {
                    let clipped = self.clip(i, command);
                    out.force_n[i] = clipped * fraction;
                    out.limited[i] = ramping | (clipped != command);
                }
            } else {
                for (i, &command) in command_n.iter().enumerate() {
                    let clipped = self.clip(i, command);
                    out.force_n[i] = clipped;
                    out.limited[i] = clipped != command;
                }
            }
        } else {
            self.ramp_done = 0;
        }
        for ((heat, &f), &shed) in self
            .heat
            .iter_mut()
            .zip(&out.force_n)
            .zip(&self.continuous_sq_n2)
        {
            let h = *heat + (f * f - shed) * self.period;
            // (`f` is finite: a comparison, not `max`'s NaN handling.)
            *heat = if h > R::ZERO { h } else { R::ZERO };
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cfg() -> SafetyConfig {
        SafetyConfig {
            heartbeat_timeout_ticks: 5,
            require_dead_man: true,
            ..SafetyConfig::excalibur()
        }
    }

    fn ok_inputs(tick: u32) -> SafetyInputs {
        SafetyInputs {
            tick,
            dead_man_closed: true,
            velocity_mps: 0.0,
            sensor_faults: Faults::NONE,
        }
    }

    /// Enabled, past the ramp, heartbeat fresh, at tick `*t`.
    fn running(t: &mut u32) -> SafetyLayer {
        let mut s = SafetyLayer::new(cfg()).unwrap();
        s.enable().unwrap();
        for _ in 0..cfg().ramp_ticks {
            s.heartbeat();
            s.step(&ok_inputs(*t), 10.0);
            *t += 1;
        }
        assert_eq!(s.step(&ok_inputs(*t), 10.0).force_n, 10.0);
        *t += 1;
        s
    }

    /// Each fault path: zero force in the tick it appears, latched (zero
    /// force, reported) while the condition is gone, until `clear`.
    #[test]
    fn every_fault_gives_zero_force_at_once_and_latches() {
        type Inject = fn(&mut SafetyInputs, &mut f32);
        let cases: [(Faults, Inject); 7] = [
            (Faults::SENSOR_NOT_FINITE, |i, _| i.velocity_mps = f32::NAN),
            (Faults::SENSOR_OUT_OF_RANGE, |i, _| {
                i.sensor_faults = Faults::SENSOR_OUT_OF_RANGE
            }),
            (Faults::ENCODER_INVALID, |i, _| {
                i.sensor_faults = Faults::ENCODER_INVALID
            }),
            (Faults::VELOCITY_LIMIT, |i, _| i.velocity_mps = -1.5),
            (Faults::DEAD_MAN, |i, _| i.dead_man_closed = false),
            (Faults::MISSED_TICK, |i, _| i.tick += 1),
            (Faults::COMMAND_NOT_FINITE, |_, f| *f = f32::INFINITY),
        ];
        for (fault, inject) in cases {
            let mut t = 0;
            let mut s = running(&mut t);
            let (mut i, mut f) = (ok_inputs(t), 50.0);
            inject(&mut i, &mut f);
            let out = s.step(&i, f);
            assert_eq!(out.force_n, 0.0, "{fault}");
            assert!(out.faults.contains(fault), "{fault}: got {}", out.faults);
            assert_eq!(s.first_fault(), fault);
            t = i.tick + 1;
            for _ in 0..50 {
                s.heartbeat();
                let out = s.step(&ok_inputs(t), 50.0);
                t += 1;
                assert_eq!(out.force_n, 0.0, "{fault} must stay latched");
                assert!(out.faults.contains(fault));
            }
            assert_eq!(s.enable(), Err(s.faults()));
            s.clear();
            s.heartbeat();
            let out = s.step(&ok_inputs(t), 50.0);
            assert!(out.faults.is_empty(), "{fault}: {}", out.faults);
            assert!(
                out.force_n > 0.0 && out.force_n < 50.0,
                "ramps in after clear"
            );
        }
    }

    /// With a 5-tick timeout, five ticks after a heartbeat still run; the
    /// sixth gives zero force and the fault.
    #[test]
    fn heartbeat_loss_trips_after_the_timeout() {
        let mut t = 0;
        let mut s = running(&mut t);
        s.heartbeat();
        let timeout = cfg().heartbeat_timeout_ticks;
        for n in 1..=timeout + 1 {
            let out = s.step(&ok_inputs(t), 10.0);
            t += 1;
            let lost = out.faults.contains(Faults::HEARTBEAT_LOST);
            assert_eq!(lost, n > timeout, "tick {n} after the heartbeat");
            assert_eq!(out.force_n == 0.0, lost);
        }
    }

    #[test]
    fn ramp_in_is_bounded_by_elapsed_fraction_of_peak() {
        let c = cfg();
        let mut s = SafetyLayer::new(c).unwrap();
        s.enable().unwrap();
        for n in 1..=c.ramp_ticks + 10 {
            s.heartbeat();
            let out = s.step(&ok_inputs(n), 1.0e6);
            let bound = c.peak_force_n * (n.min(c.ramp_ticks) as f32 / c.ramp_ticks as f32);
            assert!(
                out.force_n <= bound * (1.0 + 1e-6),
                "tick {n}: {}",
                out.force_n
            );
            assert!(out.limited);
            if n >= c.ramp_ticks {
                assert_eq!(out.force_n, c.peak_force_n);
            }
        }
    }

    #[test]
    fn disabled_gives_zero_and_enable_is_refused_while_latched() {
        let mut s = SafetyLayer::new(cfg()).unwrap();
        assert_eq!(s.step(&ok_inputs(0), 80.0).force_n, 0.0);
        s.trip(Faults::HEARTBEAT_LOST);
        assert_eq!(s.enable(), Err(Faults::HEARTBEAT_LOST));
        s.clear();
        assert_eq!(s.enable(), Ok(()));
    }

    /// Held at peak, the force folds back to the continuous rating once the
    /// I^2 t budget is spent (2 s at 200 N from cold), and the RMS over a
    /// long run stays at the continuous rating.
    #[test]
    fn thermal_budget_folds_back_to_continuous() {
        let c = SafetyConfig::excalibur();
        let mut s = SafetyLayer::new(c).unwrap();
        s.enable().unwrap();
        let (mut sum_sq, mut fold_tick) = (0.0f64, None);
        let n = 20_000u32;
        for k in 0..n {
            let f = s.step(&ok_inputs(k), 500.0).force_n;
            if fold_tick.is_none() && k > c.ramp_ticks && f < c.peak_force_n {
                fold_tick = Some(k);
            }
            sum_sq += (f as f64) * (f as f64);
        }
        let fold_s = fold_tick.expect("must fold back") as f32 * c.period_s;
        assert!((fold_s - 2.05).abs() < 0.1, "folded at {fold_s} s");
        let rms_tail = {
            let mut s2 = s;
            let mut acc = 0.0f64;
            for k in n..n + 10_000 {
                let f = s2.step(&ok_inputs(k), 500.0).force_n as f64;
                acc += f * f;
            }
            (acc / 10_000.0).sqrt()
        };
        assert!(
            rms_tail <= c.continuous_force_n as f64 * 1.01,
            "rms {rms_tail}"
        );
        assert!(sum_sq > 0.0);
    }

    #[test]
    fn refuses_bad_config_naming_the_field() {
        let e = SafetyLayer::new(SafetyConfig {
            continuous_force_n: 300.0,
            ..SafetyConfig::excalibur()
        })
        .unwrap_err();
        assert_eq!(e.name, "safety.continuous_force_n (N)");
        let e = SafetyLayer::new(SafetyConfig {
            max_velocity_mps: f32::NAN,
            ..SafetyConfig::excalibur()
        })
        .unwrap_err();
        assert!(e.name.starts_with("safety.max_velocity_mps"));
    }
}
