//! A scene's effects compiled into the per-tick pipeline when the
//! simulation is built: each stage holds its own parameters, the tick asks
//! nothing of the scene, and each effect's measured cost has a slot of its
//! own instead of a name to look up.

use crate::engine::scene::{Effects, SlackEffect, StopOn, StopSide};
use std::collections::VecDeque;
use std::time::Instant;
use twoport_control::servo::SensorFrame;

/// The effects a scene can name, in the order reports list them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Effect {
    /// The device's structure (the 5-DOF model instead of a rigid mass).
    Flexibility,
    /// The flexure and filter of a load cell.
    LoadCell,
    /// Encoder quantisation and counter wrap.
    Encoder,
    /// The load cell's ADC: noise and quantisation.
    Adc,
    /// The amplifier's force limit.
    Saturation,
    /// Coulomb friction at the actuator.
    Coulomb,
    /// Motor cogging.
    Cogging,
    /// Free play in the cable.
    CableSlack,
    /// Measurement-to-actuation delay.
    Delay,
    /// The force applied inside the tick, a time after the sample.
    Latency,
    /// A hard stop at the end of travel.
    HardStop,
}

impl Effect {
    /// Every effect.
    pub const ALL: [Effect; 11] = [
        Effect::Flexibility,
        Effect::LoadCell,
        Effect::Encoder,
        Effect::Adc,
        Effect::Saturation,
        Effect::Coulomb,
        Effect::Cogging,
        Effect::CableSlack,
        Effect::Delay,
        Effect::Latency,
        Effect::HardStop,
    ];

    /// The name scene files and reports use.
    pub fn name(self) -> &'static str {
        match self {
            Effect::Flexibility => "flexibility",
            Effect::LoadCell => "load_cell",
            Effect::Encoder => "encoder",
            Effect::Adc => "adc",
            Effect::Saturation => "saturation",
            Effect::Coulomb => "coulomb",
            Effect::Cogging => "cogging",
            Effect::CableSlack => "cable_slack",
            Effect::Delay => "delay",
            Effect::Latency => "latency",
            Effect::HardStop => "hard_stop",
        }
    }

    fn on(self, e: &Effects) -> bool {
        match self {
            Effect::Flexibility => e.flexibility,
            Effect::LoadCell => e.load_cell,
            Effect::Encoder => e.encoder.is_some(),
            Effect::Adc => e.adc.is_some(),
            Effect::Saturation => e.saturation.is_some(),
            Effect::Coulomb => e.coulomb.is_some(),
            Effect::Cogging => e.cogging.is_some(),
            Effect::CableSlack => e.cable_slack.is_some(),
            Effect::Delay => e.delay.is_some(),
            Effect::Latency => e.latency.is_some(),
            Effect::HardStop => e.hard_stop.is_some(),
        }
    }
}

/// One tick in this many is timed for the effects' cost: a clock read costs
/// more than most effects do.
pub const TIMING_STRIDE: u64 = 64;

/// Wall time each effect added (ns, summed over the timed ticks and scaled
/// by [`TIMING_STRIDE`]).
#[derive(Clone, Debug)]
pub struct Costs {
    on: [bool; Effect::ALL.len()],
    ns: [f64; Effect::ALL.len()],
    /// What reading the clock twice costs (ns), subtracted from timings.
    clock_ns: f64,
}

impl Costs {
    fn new(e: &Effects) -> Self {
        Costs {
            on: Effect::ALL.map(|x| x.on(e)),
            ns: [0.0; Effect::ALL.len()],
            clock_ns: (0..32)
                .map(|_| {
                    let t = Instant::now();
                    t.elapsed().as_nanos() as f64
                })
                .fold(f64::INFINITY, f64::min),
        }
    }

    /// Charge the time since `since` to the effects in `to`, shared evenly.
    pub fn charge(&mut self, to: &[Effect], since: Option<Instant>) {
        let Some(since) = since else { return };
        let raw = since.elapsed().as_nanos() as f64 - self.clock_ns;
        let ns = raw.max(0.0) * TIMING_STRIDE as f64 / to.len().max(1) as f64;
        for e in to {
            self.ns[*e as usize] += ns;
        }
    }

    /// The effects the scene names, with their cost per tick over `ticks`.
    pub fn per_tick(&self, ticks: f64) -> impl Iterator<Item = (Effect, f64)> + '_ {
        Effect::ALL
            .into_iter()
            .filter(|e| self.on[*e as usize])
            .map(move |e| (e, self.ns[e as usize] / ticks))
    }
}

/// A xorshift stream: the effects' noise, a link's jitter. Seeded
/// nonzero.
#[derive(Clone, Debug)]
pub(crate) struct Rng(pub(crate) u64);

impl Rng {
    /// Uniform in `[0, 1)`.
    pub(crate) fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }

    fn gaussian(&mut self) -> f64 {
        let u = self.uniform().max(1e-300);
        (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * self.uniform()).cos()
    }
}

/// The load cells' ADC: Gaussian noise, then quantisation; each axis's
/// noise has its own stream.
#[derive(Clone, Debug)]
struct Adc<const N: usize> {
    noise_rms_n: f64,
    lsb_n: f64,
    rng: [Rng; N],
}

/// A delay line of sensor frames.
#[derive(Clone, Debug)]
struct Delay<const N: usize> {
    ticks: usize,
    frames: VecDeque<SensorFrame<f64, N>>,
}

/// The nonlinear forces, evaluated inside the integrator's sub-steps.
#[derive(Clone, Debug)]
pub struct Forces {
    /// Coulomb friction `(force N, smoothing m/s)`.
    coulomb: Option<(f64, f64)>,
    /// Cogging `(amplitude N, period m)`.
    cogging: Option<(f64, f64)>,
    /// Cable slack: half the play (m) and the cable's stiffness (N/m).
    slack: Option<(f64, f64)>,
    /// Hard stop: face (m), +1 solid above or -1 below, stiffness (N/m),
    /// damping (N s/m), and whether it stops the handle (else the
    /// actuator).
    stop: Option<(f64, f64, f64, f64, bool)>,
    /// Which of them run (their cost is shared): the first `count` of
    /// `names`, kept inline so that charging them allocates nothing.
    names: [Effect; 4],
    count: usize,
}

impl Forces {
    /// The forces on the coordinates (N) at state `x` (`n` coordinates),
    /// added into `f`; the actuator acts along `dir`, the handle along
    /// `handle`.
    pub fn add(&self, n: usize, [dir, handle]: [&[f64]; 2], x: &[f64], f: &mut [f64]) {
        let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(p, q)| p * q).sum::<f64>();
        let xa = dot(dir, &x[..n]);
        let va = dot(dir, &x[n..2 * n]);
        let mut fa = 0.0;
        let mut fh = 0.0;
        if let Some((force_n, smoothing_mps)) = self.coulomb {
            fa -= force_n * (va / smoothing_mps).tanh();
        }
        if let Some((amplitude_n, period_m)) = self.cogging {
            fa += amplitude_n * (2.0 * std::f64::consts::PI * xa / period_m).sin();
        }
        if let Some((face_m, side, k, b, on_handle)) = self.stop {
            let (x, v, into) = if on_handle {
                (dot(handle, &x[..n]), dot(handle, &x[n..2 * n]), &mut fh)
            } else {
                (xa, va, &mut fa)
            };
            // Penetration into the solid side, and a push that never pulls.
            let depth = side * (x - face_m);
            if depth > 0.0 {
                *into -= side * (k * depth + b * side * v).max(0.0);
            }
        }
        for ((fi, di), hi) in f.iter_mut().zip(dir).zip(handle) {
            *fi += di * fa + hi * fh;
        }
        if let Some((half_play_m, cable_k)) = self.slack {
            // The linear K has the cable as k_c (q1 - q2); with free play the
            // cable only pulls past half the play.
            let d = x[0] - x[1];
            let dz = d.signum() * (d.abs() - half_play_m).max(0.0);
            let corr = cable_k * (d - dz);
            f[0] += corr;
            f[1] -= corr;
        }
    }

    /// The effects these forces are.
    pub fn effects(&self) -> &[Effect] {
        &self.names[..self.count]
    }
}

/// The per-tick pipeline of a device of `N` axes: sensing (ADC), the
/// delay line, the amplifier's limit, and the nonlinear forces, each with
/// the scene's parameters on every axis.
#[derive(Clone, Debug)]
pub struct Pipeline<const N: usize = 1> {
    encoder_timed: bool,
    adc: Option<Adc<N>>,
    delay: Option<Delay<N>>,
    saturation_n: Option<f64>,
    forces: Option<Forces>,
    /// What each effect cost.
    pub costs: Costs,
}

impl<const N: usize> Pipeline<N> {
    /// Compile `e`; `cable_k` is the device's cable stiffness (N/m).
    pub fn new(e: &Effects, cable_k: f64) -> Self {
        let mut names = [Effect::Coulomb; 4];
        let mut count = 0;
        for x in [
            Effect::Coulomb,
            Effect::Cogging,
            Effect::CableSlack,
            Effect::HardStop,
        ] {
            if x.on(e) {
                names[count] = x;
                count += 1;
            }
        }
        let forces = Forces {
            coulomb: e.coulomb.map(|c| (c.force_n, c.smoothing_mps)),
            cogging: e.cogging.map(|c| (c.amplitude_n, c.period_m)),
            slack: e
                .cable_slack
                .map(|s: SlackEffect| (0.5 * s.width_m, cable_k)),
            stop: e.hard_stop.map(|s| {
                let side = match s.solid {
                    StopSide::Above => 1.0,
                    StopSide::Below => -1.0,
                };
                let on_handle = s.on == StopOn::Handle;
                (
                    s.position_m,
                    side,
                    s.stiffness_npm,
                    s.damping_nspm,
                    on_handle,
                )
            }),
            names,
            count,
        };
        Pipeline {
            encoder_timed: e.encoder.is_some(),
            adc: e.adc.map(|a| Adc {
                noise_rms_n: a.noise_rms_n,
                lsb_n: a.lsb_n,
                // Axis 0 keeps the scene's seed; each other its own stream.
                rng: core::array::from_fn(|i| Rng(a.seed.wrapping_add(i as u64).max(1))),
            }),
            delay: e.delay.map(|d| Delay {
                ticks: d.ticks as usize,
                frames: VecDeque::with_capacity(d.ticks as usize + 1),
            }),
            saturation_n: e.saturation.map(|s| s.limit_n),
            forces: (count > 0).then_some(forces),
            costs: Costs::new(e),
        }
    }

    /// Whether the encoder's quantisation is timed (it always runs; ideal
    /// sensing is 1 nm counts).
    pub fn encoder_timed(&self) -> bool {
        self.encoder_timed
    }

    /// Axis `axis`'s load cell's reading of the force `f_n` (N).
    #[inline]
    pub fn adc(&mut self, axis: usize, f_n: f64, timing: bool) -> f64 {
        let Some(adc) = &mut self.adc else { return f_n };
        let t0 = timing.then(Instant::now);
        let f = f_n + adc.noise_rms_n * adc.rng[axis].gaussian();
        let f = (f / adc.lsb_n).round() * adc.lsb_n;
        self.costs.charge(&[Effect::Adc], t0);
        f
    }

    /// The frame the controller sees this tick.
    #[inline]
    pub fn delay(&mut self, frame: SensorFrame<f64, N>, timing: bool) -> SensorFrame<f64, N> {
        let Some(d) = &mut self.delay else {
            return frame;
        };
        let t0 = timing.then(Instant::now);
        d.frames.push_back(frame);
        let mut out = if d.frames.len() > d.ticks {
            d.frames.pop_front().unwrap_or(frame)
        } else {
            *d.frames.front().unwrap_or(&frame)
        };
        out.tick = frame.tick;
        self.costs.charge(&[Effect::Delay], t0);
        out
    }

    /// The force the amplifier delivers for `f_n` (N).
    #[inline]
    pub fn saturate(&mut self, f_n: f64, timing: bool) -> f64 {
        let Some(limit) = self.saturation_n else {
            return f_n;
        };
        let t0 = timing.then(Instant::now);
        let f = f_n.clamp(-limit, limit);
        self.costs.charge(&[Effect::Saturation], t0);
        f
    }

    /// The nonlinear forces, if the scene has any, and the costs.
    pub fn parts(&mut self) -> (Option<&Forces>, &mut Costs) {
        (self.forces.as_ref(), &mut self.costs)
    }

    /// The nonlinear forces, if the scene has any, and the costs to charge
    /// their time to.
    pub fn forces(&mut self) -> Option<(&Forces, &mut Costs)> {
        self.forces.as_ref().map(|f| (f, &mut self.costs))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::scene::HardStopEffect;

    /// The stop pushes back only from inside its solid side, with its
    /// stiffness and damping, and never pulls the actuator in.
    #[test]
    fn a_hard_stop_only_pushes_out_of_its_solid_side() {
        let stop = |solid| Effects {
            hard_stop: Some(HardStopEffect {
                position_m: -0.02,
                solid,
                stiffness_npm: 2.0e5,
                damping_nspm: 50.0,
                on: StopOn::Actuator,
            }),
            ..Effects::default()
        };
        let force = |e: &Effects, x: f64, v: f64| {
            let mut p = Pipeline::<1>::new(e, 0.0);
            let (forces, _) = p.forces().expect("a hard stop is a nonlinear force");
            let mut f = [0.0];
            forces.add(1, [&[1.0], &[1.0]], &[x, v], &mut f);
            f[0]
        };
        let below = stop(StopSide::Below);
        assert_eq!(force(&below, -0.019, -0.1), 0.0);
        // 1 mm in, still moving in at 0.1 m/s: 200 N + 5 N, outward (+x).
        assert!((force(&below, -0.021, -0.1) - 205.0).abs() < 1e-9);
        // Leaving fast: the damping would pull; the stop does not.
        assert_eq!(force(&below, -0.020_01, 10.0), 0.0);
        let above = stop(StopSide::Above);
        assert!((force(&above, -0.019, 0.0) + 200.0).abs() < 1e-9);
        assert_eq!(force(&above, -0.021, 0.0), 0.0);
    }
}
