//! The simulator's port layer: the board's passivity controller, a delay of
//! what the display's element sees, and the books the scope and the report
//! read (observed energy, added damping, energy dissipated).

use crate::engine::scene::{Coupling, LayerPort, Scene};
use crate::Error;
use std::collections::VecDeque;
use twoport_control::passivity::{
    EnergyObserver, ParallelDamper, ParallelLimits, PassivityLimits, SeriesDamper,
};
use twoport_control::servo::{Display, PortLayer};
use twoport_control::{Position, Real, SafetyConfig};

/// What sits between the simulated device and the scene's element.
#[derive(Clone, Debug)]
pub struct SceneLayer<R: Real> {
    series: Option<SeriesDamper<R>>,
    parallel: Option<ParallelDamper<R>>,
    /// The element's view of the device, oldest first, and how old it is.
    delay: VecDeque<(Position, R)>,
    delay_ticks: usize,
    /// The series damper's correction, booked like the element's force:
    /// the energy it took in is what the layer dissipated (as commanded,
    /// before the safety layer's limit, which rarely binds here).
    correction: EnergyObserver<R>,
    /// The parallel damper's dissipation (J).
    parallel_dissipated_j: f64,
    period_s: f64,
}

impl<R: Real> SceneLayer<R> {
    /// Axis `axis`'s layer (its own coupling sets an admittance display's
    /// damper), or `None` when the scene has neither a passivity table nor
    /// an element delay (the servo then runs with no layer at all).
    pub fn for_axis(
        scene: &Scene,
        safety: &SafetyConfig,
        axis: usize,
    ) -> Result<Option<Self>, Error> {
        let delay_ticks = scene.effects.element_delay.map_or(0, |d| d.ticks as usize);
        let spec = scene
            .passivity
            .as_ref()
            .filter(|p| p.enabled && p.port == LayerPort::Device);
        if spec.is_none() && delay_ticks == 0 {
            return Ok(None);
        }
        let (mut series, mut parallel) = (None, None);
        if let Some(p) = spec {
            let t = safety.period_s;
            match scene.display {
                Display::Impedance => {
                    let mass = p.mass_kg.unwrap_or(scene.plant.rigid_mass_kg) as f32;
                    let mut l = PassivityLimits::for_device(mass, t, safety.peak_force_n)
                        .map_err(|e| e.to_string())?;
                    l.device_damping_nspm = p.device_damping_nspm as f32;
                    if let Some(v) = p.min_velocity_mps {
                        l.min_velocity_mps = v as f32;
                    }
                    if let Some(e) = p.max_reserve_j {
                        l.max_reserve_j = e as f32;
                    }
                    series = Some(SeriesDamper::new(l).map_err(|e| e.to_string())?);
                }
                Display::Admittance => {
                    let m = match scene.coupling_of(axis) {
                        Coupling::Admittance { m, .. } => *m as f32,
                        // (A checked scene's coupling is its display's.)
                        Coupling::Impedance { .. } => 0.0,
                    };
                    let mut l = ParallelLimits::for_display(m, t, safety.max_velocity_mps)
                        .map_err(|e| e.to_string())?;
                    if let Some(e) = p.max_reserve_j {
                        l.max_reserve_j = e as f32;
                    }
                    parallel = Some(ParallelDamper::new(l).map_err(|e| e.to_string())?);
                }
            }
        }
        Ok(Some(SceneLayer {
            series,
            parallel,
            delay: VecDeque::with_capacity(delay_ticks + 1),
            delay_ticks,
            correction: EnergyObserver::new(),
            parallel_dissipated_j: 0.0,
            period_s: safety.period_s as f64,
        }))
    }

    /// The energy the controlled element has taken in (J), as the layer's
    /// observer books it; NaN without a controller.
    pub fn energy_in_j(&self) -> f64 {
        match (&self.series, &self.parallel) {
            (Some(s), _) => s.energy_in_j().to_f64(),
            (_, Some(p)) => p.energy_in_j().to_f64(),
            _ => f64::NAN,
        }
    }

    /// What the controller added in the last tick: damping (N s/m) on an
    /// impedance display, conductance (m/(N s)) on an admittance display;
    /// NaN without a controller.
    pub fn added(&self) -> f64 {
        match (&self.series, &self.parallel) {
            (Some(s), _) => s.damping_nspm().to_f64(),
            (_, Some(p)) => p.conductance_mpns().to_f64(),
            _ => f64::NAN,
        }
    }

    /// The energy the controller has dissipated so far (J); 0 without one.
    pub fn dissipated_j(&self) -> f64 {
        self.correction.energy_in_j().to_f64() + self.parallel_dissipated_j
    }
}

impl<R: Real> PortLayer<R> for SceneLayer<R> {
    fn display(&self) -> Option<Display> {
        match (&self.series, &self.parallel) {
            (Some(_), _) => Some(Display::Impedance),
            (_, Some(_)) => Some(Display::Admittance),
            _ => None,
        }
    }

    fn element_motion(&mut self, x: Position, v_mps: R) -> (Position, R) {
        if self.delay_ticks == 0 {
            return (x, v_mps);
        }
        self.delay.push_back((x, v_mps));
        // Until the line is full the element sees the first sample: the
        // device at rest where it was enabled.
        if self.delay.len() > self.delay_ticks + 1 {
            self.delay.pop_front();
        }
        self.delay[0]
    }

    fn impedance_force(&mut self, x: Position, v_mps: R, force_n: R) -> R {
        let Some(pc) = &mut self.series else {
            return force_n;
        };
        let out = PortLayer::impedance_force(pc, x, v_mps, force_n);
        self.correction.update(x, out - force_n);
        out
    }

    fn admittance_velocity(&mut self, force_n: R, velocity_mps: R) -> R {
        let Some(pc) = &mut self.parallel else {
            return velocity_mps;
        };
        let out = pc.step(force_n, velocity_mps);
        self.parallel_dissipated_j +=
            self.period_s * force_n.to_f64() * (out - velocity_mps).to_f64();
        out
    }

    fn held(&mut self, force_n: R) {
        if let Some(pc) = &mut self.series {
            PortLayer::held(pc, force_n);
        }
    }

    fn reset(&mut self, x: Position) {
        if let Some(pc) = &mut self.series {
            pc.reset(x);
        }
        if let Some(pc) = &mut self.parallel {
            pc.reset();
        }
        self.delay.clear();
        self.correction.restart(x);
        self.parallel_dissipated_j = 0.0;
    }
}
