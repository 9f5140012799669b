//! The physical checks a scene's types cannot express; each message
//! names the field.

use super::{BlocksSpec, Coupling, LayerPort, Scene, VeSpec, MAX_AXES, MAX_BLOCKS};
use crate::engine::human::AxisValue;
use crate::Error;
use twoport_control::servo::Display;
use twoport_design::field;

impl Scene {
    /// Physical checks beyond the types; the message names the field.
    pub(crate) fn check(&self) -> Result<(), Error> {
        if !(1..=MAX_AXES).contains(&self.axes) {
            return Err(sim_err!(
                "axes = {}: the simulator runs devices of 1 to {MAX_AXES} axes",
                self.axes
            ));
        }
        let cc = self.plant.cross_coupling;
        if !(cc.is_finite() && (0.0..0.5).contains(&cc)) {
            return Err(sim_err!("plant.cross_coupling = {cc} must be in [0, 0.5)"));
        }
        if cc != 0.0 && self.axes == 1 {
            return Err(
                "plant.cross_coupling couples the axes of a device of several; this one has one"
                    .into(),
            );
        }
        self.check_linkage()?;
        self.check_identify()?;
        pos("duration_s", self.duration_s)?;
        if let Some(t) = self.period_s {
            if !(t.is_finite() && (1e-6..=0.1).contains(&t)) {
                return Err(sim_err!("period_s = {t} must be between 1e-6 and 0.1 s"));
            }
        }
        pos("plant.rigid_mass_kg", self.plant.rigid_mass_kg)?;
        nonneg("plant.handle_mass_kg", self.plant.handle_mass_kg)?;
        if self.plant.handle_mass_kg > 0.0 && self.plant.linkage.is_some() {
            return Err(
                "plant.handle_mass_kg: a mass on a linkage's handle is not modelled".into(),
            );
        }
        nonneg("plant.rigid_damping_nspm", self.plant.rigid_damping_nspm)?;
        if self.integrator.substeps == 0 || self.integrator.substeps > 100_000 {
            return Err(sim_err!(
                "integrator.substeps = {} must be 1..=100000",
                self.integrator.substeps
            ));
        }
        match &self.coupling_per_axis {
            None => self.check_coupling("coupling", &self.coupling)?,
            Some(each) => {
                if each.len() != self.axis_count() {
                    return Err(sim_err!(
                        "coupling_per_axis has {} couplings for {} axes",
                        each.len(),
                        self.axes
                    ));
                }
                for (a, c) in each.iter().enumerate() {
                    self.check_coupling(&format!("coupling_per_axis[{a}]"), c)?;
                }
            }
        }
        if self.display == Display::Admittance && !self.effects.load_cell {
            return Err(
                "an admittance display measures force: add `load_cell = true` to [effects]".into(),
            );
        }
        self.check_script()?;
        self.check_ve()?;
        self.check_effects()?;
        self.check_passivity()
    }

    /// The VE's fields.
    fn check_ve(&self) -> Result<(), Error> {
        // A spring VE anchored at `at` (m, named `at_name`).
        let spring = |at_name: &str, at: f64, k: f64, b: f64| {
            if !at.is_finite() {
                return Err(sim_err!("{at_name} = {at} must be finite"));
            }
            nonneg("ve.stiffness_npm", k)?;
            nonneg("ve.damping_nspm", b)
        };
        match &self.ve {
            VeSpec::Cursor { mass_kg, .. } => pos("ve.mass_kg", *mass_kg)?,
            VeSpec::Wall {
                position_m: at,
                stiffness_npm: k,
                damping_nspm: b,
                ..
            } => spring("ve.position_m", *at, *k, *b)?,
            VeSpec::Bilateral => {}
            VeSpec::Spring {
                anchor_m: at,
                stiffness_npm: k,
                damping_nspm: b,
                ..
            } => spring("ve.anchor_m", *at, *k, *b)?,
            VeSpec::Blocks(w) => check_blocks(w)?,
            VeSpec::World {
                blocks,
                cursor_mass_kg,
                friction,
                grab_at_s,
                release_at_s,
                ..
            } => {
                if self.axes != 3 {
                    return Err(sim_err!(
                        "ve.kind = \"world\" is a 3-D world: it needs axes = 3, not {}",
                        self.axes
                    ));
                }
                for (name, times) in [("grab_at_s", grab_at_s), ("release_at_s", release_at_s)] {
                    if let Some(t) = times.iter().find(|t| !(t.is_finite() && **t >= 0.0)) {
                        return Err(sim_err!("ve.{name}: {t} is not a time >= 0 (s)"));
                    }
                }
                if blocks.len() > MAX_BLOCKS {
                    return Err(sim_err!(
                        "ve.blocks: {} blocks, the world holds {MAX_BLOCKS}",
                        blocks.len()
                    ));
                }
                for (i, b) in blocks.iter().enumerate() {
                    let ok = b.at_m.iter().all(|x| x.is_finite() && x.abs() < 2.0)
                        && b.size_m
                            .iter()
                            .all(|s| s.is_finite() && *s > 0.0 && *s < 2.0)
                        && b.mass_kg.is_finite()
                        && b.mass_kg > 0.0;
                    if !ok {
                        return Err(sim_err!(
                            "ve.blocks[{i}]: at_m within 2 m, size_m in (0, 2) m and mass_kg > 0"
                        ));
                    }
                }
                pos("ve.cursor_mass_kg", *cursor_mass_kg)?;
                nonneg("ve.friction", *friction)?;
            }
        }
        Ok(())
    }

    /// The effects' fields, and the effects that need another.
    fn check_effects(&self) -> Result<(), Error> {
        let e = &self.effects;
        if let Some(x) = e.encoder {
            pos("effects.encoder.resolution_m", x.resolution_m)?;
            if !(2..=32).contains(&x.bits) {
                return Err(sim_err!("effects.encoder.bits = {} must be 2..=32", x.bits));
            }
            if let Some(m) = x.index_m {
                if !(m.is_finite() && m.abs() <= 1.0) {
                    return Err(sim_err!(
                        "effects.encoder.index_m = {m} must be within ±1 m"
                    ));
                }
            }
        }
        if let Some(x) = e.hard_stop {
            if !(x.position_m.is_finite() && x.position_m.abs() <= 1.0) {
                return Err(sim_err!(
                    "effects.hard_stop.position_m = {} must be within ±1 m",
                    x.position_m
                ));
            }
            pos("effects.hard_stop.stiffness_npm", x.stiffness_npm)?;
            nonneg("effects.hard_stop.damping_nspm", x.damping_nspm)?;
        }
        if let Some(x) = e.adc {
            pos("effects.adc.lsb_n", x.lsb_n)?;
            nonneg("effects.adc.noise_rms_n", x.noise_rms_n)?;
        }
        if let Some(x) = e.saturation {
            pos("effects.saturation.limit_n", x.limit_n)?;
        }
        if let Some(x) = e.coulomb {
            nonneg("effects.coulomb.force_n", x.force_n)?;
            pos("effects.coulomb.smoothing_mps", x.smoothing_mps)?;
        }
        if let Some(x) = e.cogging {
            nonneg("effects.cogging.amplitude_n", x.amplitude_n)?;
            pos("effects.cogging.period_m", x.period_m)?;
        }
        if let Some(x) = e.cable_slack {
            nonneg("effects.cable_slack.width_m", x.width_m)?;
            if !e.flexibility {
                return Err("effects.cable_slack needs the flexible model (flexibility = true): the rigid reduction has no cable".into());
            }
        }
        if let Some(x) = e.delay {
            if x.ticks > 1000 {
                return Err(sim_err!(
                    "effects.delay.ticks = {} must be <= 1000",
                    x.ticks
                ));
            }
        }
        if let Some(x) = e.latency {
            let v = match (x.seconds, x.periods) {
                (Some(v), None) => v,
                (None, Some(v)) => v * self.period(),
                _ => {
                    return Err(
                        "effects.latency: give one of seconds or periods (the time from sampling to the force)"
                            .into(),
                    )
                }
            };
            if !(v.is_finite() && v >= 0.0 && v <= 1000.0 * self.period()) {
                return Err(sim_err!(
                    "effects.latency = {v} s: must be a time from 0 to 1000 periods"
                ));
            }
        }
        if let Some(x) = e.element_delay {
            if x.ticks > 1000 {
                return Err(sim_err!(
                    "effects.element_delay.ticks = {} must be <= 1000",
                    x.ticks
                ));
            }
            if self.display != Display::Impedance {
                return Err("effects.element_delay delays the impedance display's element; an admittance display has none to delay".into());
            }
        }
        Ok(())
    }

    /// The passivity layer's fields, and where it may sit.
    fn check_passivity(&self) -> Result<(), Error> {
        if let Some(p) = &self.passivity {
            if p.port == LayerPort::Ve {
                if self.display != Display::Impedance {
                    return Err("passivity.port = \"ve\" is for an impedance display (an admittance display's layer already sits at the load cell)".into());
                }
                if !matches!(self.ve, VeSpec::Cursor { .. }) {
                    return Err("passivity.port = \"ve\" needs a cursor VE (one that takes a force and answers with a velocity)".into());
                }
            }
            if let Some(m) = p.mass_kg {
                pos("passivity.mass_kg", m)?;
            }
            nonneg("passivity.device_damping_nspm", p.device_damping_nspm)?;
            if let Some(v) = p.min_velocity_mps {
                pos("passivity.min_velocity_mps", v)?;
            }
            if let Some(e) = p.max_reserve_j {
                nonneg("passivity.max_reserve_j", e)?;
            }
        }
        Ok(())
    }

    /// One axis's coupling, named `name` in errors: the scene's display's,
    /// with gains that make a coupling.
    fn check_coupling(&self, name: &str, c: &Coupling) -> Result<(), Error> {
        let nonneg = |field: &str, v: f64| nonneg(&format!("{name}.{field}"), v);
        let pos = |field: &str, v: f64| pos(&format!("{name}.{field}"), v);
        match (*c, self.display) {
            (Coupling::Impedance { k, b }, Display::Impedance) => {
                nonneg("k", k)?;
                nonneg("b", b)
            }
            (Coupling::Admittance { kp, bp, m, b }, Display::Admittance) => {
                nonneg("kp", kp)?;
                nonneg("bp", bp)?;
                pos("m", m)?;
                pos("b", b)
            }
            (Coupling::Impedance { .. }, Display::Admittance) => Err(sim_err!(
                "{name}: an admittance display's coupling needs kp, bp, m and b ({name}.m is required; k belongs to an impedance display)"
            )),
            (Coupling::Admittance { .. }, Display::Impedance) => Err(sim_err!(
                "{name}: an impedance display's coupling is k and b (kp, bp and m belong to an admittance display)"
            )),
        }
    }

    /// The script's positions and forces: numbers on a one-axis device,
    /// one per axis on a device of several.
    fn check_script(&self) -> Result<(), Error> {
        let n = self.axis_count();
        for (i, e) in self.human.script.iter().enumerate() {
            let Some(v) = e.values() else { continue };
            let fits = match v {
                AxisValue::One(_) => n == 1,
                AxisValue::Each(v) => v.len() == n,
            };
            if !fits {
                return Err(if n == 1 {
                    sim_err!("human.script[{i}]: a one-axis scene's values are numbers (or arrays of one)")
                } else {
                    sim_err!(
                        "human.script[{i}]: give one value per axis, {n} in all (x first), not {}",
                        v.len()
                    )
                });
            }
        }
        self.humans().map(|_| ())
    }

    /// A linkage scene: its file loads, has the scene's joints, starts at
    /// a pose its limits allow and its kinematics serve; and the scene asks
    /// nothing of it that belongs to an axis's model (the file's encoders,
    /// losses and motors stand in for the axes' effects).
    fn check_linkage(&self) -> Result<(), Error> {
        let p = &self.plant;
        let Some(path) = &p.linkage else {
            if !p.pose_rad.is_empty() || p.gravity_mps2 != 0.0 || p.friction.is_some() {
                return Err(
                    "plant.pose_rad, plant.gravity_mps2 and plant.friction belong to a linkage \
                     (plant.linkage)"
                        .into(),
                );
            }
            return Ok(());
        };
        let file = twoport_design::linkage::LinkageFile::load(path)
            .map_err(|e| sim_err!("plant.linkage: {e}"))?;
        let joints = file.geometry.joints();
        if joints != self.axis_count() {
            return Err(sim_err!(
                "plant.linkage: {} has {joints} joints; the scene has axes = {}",
                path.display(),
                self.axes
            ));
        }
        if p.pose_rad.len() != joints || p.pose_rad.iter().any(|q| !q.is_finite()) {
            return Err(sim_err!(
                "plant.pose_rad: give {joints} finite joint angles (rad), not {:?}",
                p.pose_rad
            ));
        }
        if !file.within_limits(&p.pose_rad) {
            return Err(sim_err!(
                "plant.pose_rad = {:?}: outside the joint limits of {}",
                p.pose_rad,
                path.display()
            ));
        }
        if let Err(f) = file.pose(&p.pose_rad) {
            return Err(sim_err!("plant.pose_rad = {:?}: {f:?}", p.pose_rad));
        }
        if !(p.gravity_mps2.is_finite() && p.gravity_mps2 >= 0.0) {
            return Err(sim_err!(
                "plant.gravity_mps2 = {} must be finite and >= 0",
                p.gravity_mps2
            ));
        }
        let e = &self.effects;
        let axis_effects = [
            ("flexibility", e.flexibility),
            ("load_cell", e.load_cell),
            ("encoder", e.encoder.is_some()),
            ("adc", e.adc.is_some()),
            ("saturation", e.saturation.is_some()),
            ("coulomb", e.coulomb.is_some()),
            ("cogging", e.cogging.is_some()),
            ("cable_slack", e.cable_slack.is_some()),
            ("delay", e.delay.is_some()),
            ("latency", e.latency.is_some()),
            ("hard_stop", e.hard_stop.is_some()),
            ("element_delay", e.element_delay.is_some()),
        ];
        if let Some((name, _)) = axis_effects.iter().find(|(_, on)| *on) {
            return Err(sim_err!(
                "effects.{name}: a linkage's encoders, losses and motors are its file's; \
                 the axes' effects do not apply"
            ));
        }
        if self.passivity.is_some() {
            return Err("passivity: not run on a linkage yet".into());
        }
        if self.display != Display::Impedance {
            return Err("display: a linkage runs the impedance display".into());
        }
        if self.human.arm.is_some() {
            return Err("human.arm: a linkage's hand has no arm yet".into());
        }
        Ok(())
    }
}

/// `Ok` where `v` (the field `name`) is finite and > 0.
/// The 1-D world's fields: a cursor's mass, blocks of positive width and
/// mass left to right between the limits, not overlapping.
fn check_blocks(w: &BlocksSpec) -> Result<(), Error> {
    pos("ve.cursor_mass_kg", w.cursor_mass_kg)?;
    nonneg("ve.stick_force_n", w.stick_force_n)?;
    nonneg("ve.floor_damping_nspm", w.floor_damping_nspm)?;
    if !(w.limits_m[0].is_finite() && w.limits_m[1].is_finite() && w.limits_m[0] < w.limits_m[1]) {
        return Err("ve.limits_m must be [low, high] with low < high".into());
    }
    let mut edge = w.limits_m[0];
    for (i, b) in w.blocks.iter().enumerate() {
        pos(&format!("ve.blocks[{i}].width_m"), b.width_m)?;
        pos(&format!("ve.blocks[{i}].mass_kg"), b.mass_kg)?;
        if !(b.at_m.is_finite() && b.at_m >= edge - 1e-12) {
            return Err(sim_err!(
                "ve.blocks[{i}] overlaps the block or limit to its left"
            ));
        }
        edge = b.at_m + b.width_m;
    }
    if edge > w.limits_m[1] + 1e-12 {
        return Err("ve.blocks extend past ve.limits_m[1]".into());
    }
    Ok(())
}

fn pos(name: &str, v: f64) -> Result<(), Error> {
    field::positive(name, v).map(drop).map_err(Error::Sim)
}

/// `Ok` where `v` (the field `name`) is finite and >= 0.
fn nonneg(name: &str, v: f64) -> Result<(), Error> {
    field::non_negative(name, v).map(drop).map_err(Error::Sim)
}
