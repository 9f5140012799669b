//! The layer itself: each tick's checks, the latch, the limits and the
//! ramp, over every axis.

use super::{AxisError, Faults, SafetyConfig};
use crate::{ParamError, Real};

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
    /// Each motor's I^2 t budget (N^2 ticks).
    budget: [f32; N],
    enabled: bool,
    latched: Faults,
    first: Faults,
    ramp_done: u32,
    /// Each motor's I^2 t state above its continuous rating, >= 0, in
    /// N^2 ticks (N^2 s over the period: the tick's update is then one
    /// multiply-add and a subtraction).
    heat: [R; N],
    /// The tick number the next step must bring.
    next_tick: u32,
    /// Whether a tick has been seen (the first may bring any number).
    ticking: bool,
    heartbeat_age: u32,
    /// Largest heartbeat age that is not a fault (`u32::MAX`: unchecked).
    heartbeat_limit: u32,
    /// Each `continuous_force_n^2` (N^2), the heat a motor sheds per tick.
    continuous_sq_n2: [R; N],
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
            budget: cfg.map(|c| c.thermal_budget() / period),
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
    /// continuous force once its I²t budget is spent, and whether it was.
    #[inline(always)]
    fn clip(&self, i: usize, command: R) -> (R, bool) {
        let c = &self.cfg[i];
        let limit = R::of(if self.heat[i] >= R::of(self.budget[i]) {
            c.continuous_force_n
        } else {
            c.peak_force_n
        });
        // (Not `clamp`, which carries an assertion on its bounds; the
        // command is finite here, or a fault would have latched.)
        if command > limit {
            (limit, true)
        } else if command < -limit {
            (-limit, true)
        } else {
            (command, false)
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
                    let (clipped, limited) = self.clip(i, command);
                    out.force_n[i] = clipped * fraction;
                    out.limited[i] = ramping | limited;
                }
            } else {
                for (i, &command) in command_n.iter().enumerate() {
                    (out.force_n[i], out.limited[i]) = self.clip(i, command);
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
            let h = *heat + (f * f - shed);
            // (`f` is finite: a comparison, not `max`'s NaN handling.)
            *heat = if h > R::ZERO { h } else { R::ZERO };
        }
        out
    }
}
