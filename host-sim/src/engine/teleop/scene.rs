//! A teleoperation scene file: two devices, the law between them and the
//! channel that carries it.

use crate::engine::scene::{
    checked, parse_toml, read, Coupling, Effects, HumanSpec, IntegratorSpec, PlantSpec, Scene,
    VeSpec,
};
use crate::Error;
use serde::Deserialize;
use std::path::Path;
use twoport_control::servo::Display;
use twoport_design::verify::{TeleopLaw, MAX_DELAY_TICKS};

/// A teleoperation scene, as read from TOML: a master under the
/// operator's hand and a slave on the environment, each a one-axis
/// device as a scene gives it, joined by `law` across `channel`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TeleopScene {
    /// A name for reports.
    #[serde(default)]
    pub name: String,
    /// Simulated time (s).
    #[serde(default = "default_duration")]
    pub duration_s: f64,
    /// Both devices' control period (s); 1 ms by default.
    pub period_s: Option<f64>,
    /// The teleoperator's law: `[law.gains]` (Lawrence's four channels,
    /// each gain not named off) or `[law.wave]`, as `twoport teleop`
    /// takes them.
    pub law: TeleopLaw,
    /// What carries each side's packets to the other.
    #[serde(default)]
    pub channel: ChannelSpec,
    /// The device under the operator's hand; its `human` is the operator.
    pub master: SideSpec,
    /// The device on the environment; its `environment` (a hand's grasp
    /// and script) and its effects (a `hard_stop` for a wall) are what it
    /// touches.
    pub slave: SideSpec,
}

/// The channel between the two sides, each way.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ChannelSpec {
    /// Its constant delay (ticks, each way): the one the proof takes.
    #[serde(default)]
    pub delay_ticks: usize,
    /// Each packet's extra delay, drawn uniformly from `0..=jitter_ticks`
    /// (ticks); a packet overtaken by a newer one is not used.
    #[serde(default)]
    pub jitter_ticks: usize,
    /// The fraction of packets lost, in `[0, 1)`.
    #[serde(default)]
    pub drop_fraction: f64,
    /// The jitter's and the drops' seed (nonzero).
    #[serde(default = "default_seed")]
    pub seed: u64,
    /// A time-domain passivity guard at each port (for a channel whose
    /// delay varies, or that drops packets); absent means none.
    pub guard: Option<GuardSpec>,
}

impl Default for ChannelSpec {
    fn default() -> Self {
        ChannelSpec {
            delay_ticks: 0,
            jitter_ticks: 0,
            drop_fraction: 0.0,
            seed: default_seed(),
            guard: None,
        }
    }
}

impl ChannelSpec {
    /// Whether the channel is the proof's: a constant delay, nothing lost,
    /// no guard.
    pub fn is_constant(&self) -> bool {
        self.jitter_ticks == 0 && self.drop_fraction == 0.0 && self.guard.is_none()
    }
}

/// The passivity guard's limits at each port.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GuardSpec {
    /// The lighter device's moving mass (kg), which bounds the damping
    /// the guard may add in one tick.
    pub mass_kg: f64,
    /// The most force the guard may hold (N).
    pub force_limit_n: f64,
}

/// One device of a teleoperation scene: what a one-axis scene says of
/// its device, its hand and its effects.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SideSpec {
    /// The device (a model file with the `flexibility` effect, else the
    /// rigid reduction). Not a linkage.
    #[serde(default)]
    pub plant: PlantSpec,
    /// How the plant is advanced.
    #[serde(default)]
    pub integrator: IntegratorSpec,
    /// The master's operator, or the slave's environment: a grasp and a
    /// script of moves, pushes and grips.
    #[serde(default, alias = "environment")]
    pub human: HumanSpec,
    /// Effects to simulate on this device.
    #[serde(default)]
    pub effects: Effects,
}

fn default_duration() -> f64 {
    10.0
}

fn default_seed() -> u64 {
    1
}

impl TeleopScene {
    /// Read a teleoperation scene file, apply `--set` overrides, and
    /// check it.
    pub fn load(path: &Path, sets: &[String]) -> Result<Self, Error> {
        Self::parse(&read(path)?, &path.display().to_string(), sets)
    }

    /// Parse teleoperation scene text; `source` names it in errors.
    pub fn parse(text: &str, source: &str, sets: &[String]) -> Result<Self, Error> {
        let scene = checked(parse_toml(text, source, sets)?, source, Self::check)?;
        for (name, side) in scene.sides() {
            checked(&scene.side(side, name), source, |s| {
                s.check().map_err(|e| sim_err!("{name}: {e}"))
            })?;
        }
        Ok(scene)
    }

    /// Whether the scene file at `path` is a teleoperation scene (it has
    /// a `[master]` table) rather than a one-device scene.
    pub fn is_teleop(path: &Path) -> Result<bool, Error> {
        let text = read(path)?;
        let table: toml::Table = toml::from_str(&text)
            .map_err(|e| Error::Scene(format!("{}: {}", path.display(), e.message())))?;
        Ok(table.contains_key("master"))
    }

    /// The control period (s).
    pub fn period(&self) -> f64 {
        self.period_s.unwrap_or(1e-3)
    }

    /// Each side with its name: the master first.
    pub fn sides(&self) -> [(&'static str, &SideSpec); 2] {
        [("master", &self.master), ("slave", &self.slave)]
    }

    /// `side` as a one-axis scene whose servo the teleoperator replaces
    /// (an impedance display with a damper for a coupling, which never
    /// runs: the teleoperator steps the device).
    pub fn side(&self, side: &SideSpec, name: &str) -> Scene {
        Scene {
            name: format!("{} ({name})", self.name),
            axes: 1,
            duration_s: self.duration_s,
            period_s: self.period_s,
            plant: side.plant.clone(),
            integrator: side.integrator,
            display: Display::Impedance,
            coupling: Coupling::Impedance { k: 0.0, b: 1.0 },
            coupling_per_axis: None,
            ve: VeSpec::Bilateral,
            human: side.human.clone(),
            effects: side.effects.clone(),
            passivity: None,
            identify: None,
        }
    }

    /// What the types cannot say: the channel's numbers, and a law the
    /// devices can run.
    fn check(&self) -> Result<(), Error> {
        let c = &self.channel;
        let longest = c.delay_ticks + c.jitter_ticks;
        if longest > MAX_DELAY_TICKS {
            return Err(sim_err!(
                "channel: delay_ticks + jitter_ticks = {longest}: at most {MAX_DELAY_TICKS}"
            ));
        }
        if !(0.0..1.0).contains(&c.drop_fraction) {
            return Err(sim_err!(
                "channel.drop_fraction = {} must be in [0, 1)",
                c.drop_fraction
            ));
        }
        if c.seed == 0 {
            return Err("channel.seed must be nonzero".into());
        }
        if let Some(g) = c.guard {
            for (name, v) in [("mass_kg", g.mass_kg), ("force_limit_n", g.force_limit_n)] {
                if !(v.is_finite() && v > 0.0) {
                    return Err(sim_err!("channel.guard.{name} = {v} must be positive"));
                }
            }
        }
        for (name, side) in self.sides() {
            if side.plant.linkage.is_some() {
                return Err(sim_err!(
                    "{name}.plant.linkage: a teleoperator joins one-axis devices; give a model"
                ));
            }
        }
        match self.law {
            TeleopLaw::Wave(_) if !c.is_constant() => Err(
                "channel: the wave channel runs its own constant delay; jitter, drops and the guard are for law.gains"
                    .into(),
            ),
            TeleopLaw::Wave(_) if c.delay_ticks == 0 => {
                Err("channel.delay_ticks: the wave channel needs at least one tick".into())
            }
            TeleopLaw::FourChannel(g) => {
                let reads = [("master", g.c3 != 0.0 || g.c6 != 0.0), ("slave", g.c2 != 0.0 || g.c5 != 0.0)];
                for ((name, side), (_, read)) in self.sides().into_iter().zip(reads) {
                    if read && !side.effects.load_cell {
                        return Err(sim_err!(
                            "law.gains: the law reads the {name}'s load cell; add `load_cell = true` to [{name}.effects] or turn its force channels off"
                        ));
                    }
                }
                Ok(())
            }
            TeleopLaw::Wave(_) => Ok(()),
        }
    }
}
