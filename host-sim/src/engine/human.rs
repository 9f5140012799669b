//! The human operator: a grasp impedance `b + k/s` between the handle and
//! a hand whose motion (and grip) follows a script.

use crate::engine::plant::{Arm, Grasp};
use crate::Error;
use serde::Deserialize;

/// Grasp presets. The paper bounds the human by `Z_max = 300 + 1000/s`
/// (maximum grasp, arm extended); hands-off is `Z = 0`. "Relaxed" is this
/// project's assumption of a light grip: 30 N s/m and 200 N/m.
/// "Fingertips" is the least grasp a linkage's design assumes (a dead-man
/// switch keeps force off without one): 2 N s/m and 50 N/m.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum GraspKind {
    /// No contact.
    HandsOff,
    /// A light grip.
    Relaxed,
    /// A pen held in the fingertips: the least grasp linkages are proven
    /// for.
    Fingertips,
    /// The paper's maximum grasp.
    Maximum,
}

impl GraspKind {
    /// The impedance (with no arm behind it).
    pub fn grasp(self) -> Grasp {
        let (b, k) = match self {
            GraspKind::HandsOff => (0.0, 0.0),
            GraspKind::Relaxed => (30.0, 200.0),
            GraspKind::Fingertips => (2.0, 50.0),
            GraspKind::Maximum => (300.0, 1000.0),
        };
        Grasp {
            damping_nspm: b,
            stiffness_npm: k,
            arm: None,
        }
    }

    /// The scene-file name.
    pub fn name(self) -> &'static str {
        match self {
            GraspKind::HandsOff => "hands_off",
            GraspKind::Relaxed => "relaxed",
            GraspKind::Fingertips => "fingertips",
            GraspKind::Maximum => "maximum",
        }
    }
}

/// One scripted event, starting at `at_s`. `V` is a position or force
/// along the axis (`f64`), or an [`AxisValue`] as a scene file gives it.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Event<V = f64> {
    /// Move the hand linearly to `to_m` over `over_s`.
    Move {
        /// Start (s).
        at_s: f64,
        /// Target hand position (m).
        to_m: V,
        /// Duration (s), > 0.
        over_s: f64,
    },
    /// Change the grip (`hands_off` lets go).
    Grip {
        /// When (s).
        at_s: f64,
        /// The new grasp.
        grasp: GraspKind,
    },
    /// Shake the hand sinusoidally about its path.
    Shake {
        /// Start (s).
        at_s: f64,
        /// Amplitude (m).
        amplitude_m: V,
        /// Frequency (Hz).
        frequency_hz: f64,
        /// Duration (s).
        for_s: f64,
    },
    /// Push the handle with a force independent of the grasp (a bump, a
    /// finger, the scope's mouse).
    Force {
        /// Start (s).
        at_s: f64,
        /// Force along +x (N).
        force_n: V,
        /// Duration (s).
        for_s: f64,
    },
}

impl<V> Event<V> {
    /// This event along one axis, `pick` reading its value there.
    pub fn along<U>(&self, pick: impl Fn(&V) -> U) -> Event<U> {
        match self {
            Event::Move { at_s, to_m, over_s } => Event::Move {
                at_s: *at_s,
                to_m: pick(to_m),
                over_s: *over_s,
            },
            Event::Grip { at_s, grasp } => Event::Grip {
                at_s: *at_s,
                grasp: *grasp,
            },
            Event::Shake {
                at_s,
                amplitude_m,
                frequency_hz,
                for_s,
            } => Event::Shake {
                at_s: *at_s,
                amplitude_m: pick(amplitude_m),
                frequency_hz: *frequency_hz,
                for_s: *for_s,
            },
            Event::Force {
                at_s,
                force_n,
                for_s,
            } => Event::Force {
                at_s: *at_s,
                force_n: pick(force_n),
                for_s: *for_s,
            },
        }
    }

    /// The values this event carries (none for a grip).
    pub fn values(&self) -> Option<&V> {
        match self {
            Event::Move { to_m: v, .. }
            | Event::Shake { amplitude_m: v, .. }
            | Event::Force { force_n: v, .. } => Some(v),
            Event::Grip { .. } => None,
        }
    }
}

/// A scripted value in a scene of any number of axes: a number on a
/// one-axis device, or an array of one number per axis, x first.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(
    untagged,
    expecting = "a number, or an array of one number per axis (x first)"
)]
pub enum AxisValue {
    /// One number: a one-axis scene's.
    One(f64),
    /// One number per axis.
    Each(Vec<f64>),
}

impl AxisValue {
    /// How many axes it gives a value for.
    pub fn len(&self) -> usize {
        match self {
            AxisValue::One(_) => 1,
            AxisValue::Each(v) => v.len(),
        }
    }

    /// Whether it gives none.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Its value along `axis` (0 past its end, which a checked scene
    /// never asks for).
    pub fn on(&self, axis: usize) -> f64 {
        match self {
            AxisValue::One(x) if axis == 0 => *x,
            AxisValue::One(_) => 0.0,
            AxisValue::Each(v) => v.get(axis).copied().unwrap_or(0.0),
        }
    }
}

impl From<f64> for AxisValue {
    fn from(x: f64) -> Self {
        AxisValue::One(x)
    }
}

impl From<Vec<f64>> for AxisValue {
    fn from(v: Vec<f64>) -> Self {
        AxisValue::Each(v)
    }
}

impl Event {
    fn at(&self) -> f64 {
        match self {
            Event::Move { at_s, .. }
            | Event::Grip { at_s, .. }
            | Event::Shake { at_s, .. }
            | Event::Force { at_s, .. } => *at_s,
        }
    }
}

/// What the hand does at one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HandState {
    /// The grasp in force.
    pub grasp: GraspKind,
    /// Hand position (m).
    pub position_m: f64,
    /// Hand velocity (m/s).
    pub velocity_mps: f64,
    /// Extra force on the handle (N).
    pub push_n: f64,
}

impl HandState {
    /// The held input force on the handle: `k x_hand + b v_hand + push` (N).
    pub fn input_force(&self) -> f64 {
        let g = self.grasp.grasp();
        g.stiffness_npm * self.position_m + g.damping_nspm * self.velocity_mps + self.push_n
    }

    /// The force on the handle for a handle at `x_h`, `v_h` (N).
    pub fn force_on(&self, x_h: f64, v_h: f64) -> f64 {
        let g = self.grasp.grasp();
        self.input_force() - g.stiffness_npm * x_h - g.damping_nspm * v_h
    }
}

/// A human: an initial grasp and a script of events.
#[derive(Clone, Debug, PartialEq)]
pub struct Human {
    grasp: GraspKind,
    events: Vec<Event>,
    arm: Option<Arm>,
}

impl Human {
    /// A human with `grasp` and `events` (checked: times >= 0, durations
    /// > 0, finite numbers); the error names the event.
    pub fn new(grasp: GraspKind, mut events: Vec<Event>) -> Result<Self, Error> {
        for (i, e) in events.iter().enumerate() {
            let bad = |what: &str| Err(sim_err!("human.script[{i}]: {what}"));
            let finite = |v: f64| v.is_finite();
            // (A NaN fails each comparison.)
            let start = |t: f64| finite(t) && t >= 0.0;
            let span = |t: f64| finite(t) && t > 0.0;
            match *e {
                Event::Move { at_s, to_m, over_s } => {
                    if !(start(at_s) && finite(to_m) && span(over_s)) {
                        return bad("move needs at_s >= 0, a finite to_m and over_s > 0");
                    }
                }
                Event::Grip { at_s, .. } => {
                    if !start(at_s) {
                        return bad("grip needs at_s >= 0");
                    }
                }
                Event::Shake {
                    at_s,
                    amplitude_m,
                    frequency_hz,
                    for_s,
                } => {
                    if !(start(at_s) && finite(amplitude_m) && span(frequency_hz) && span(for_s)) {
                        return bad("shake needs at_s >= 0, a finite amplitude_m, frequency_hz > 0 and for_s > 0");
                    }
                }
                Event::Force {
                    at_s,
                    force_n,
                    for_s,
                } => {
                    if !(start(at_s) && finite(force_n) && span(for_s)) {
                        return bad("force needs at_s >= 0, a finite force_n and for_s > 0");
                    }
                }
            }
        }
        events.sort_by(|a, b| a.at().total_cmp(&b.at()));
        Ok(Human {
            grasp,
            events,
            arm: None,
        })
    }

    /// Put a passive arm behind every grasp but hands-off; the hand then
    /// stays still and only `force` events act (on the handle).
    pub fn with_arm(mut self, arm: Option<Arm>) -> Result<Self, Error> {
        if let Some(a) = arm {
            let ok = |v: f64| v.is_finite() && v >= 0.0;
            if !(a.mass_kg.is_finite()
                && a.mass_kg > 0.0
                && ok(a.damping_nspm)
                && ok(a.stiffness_npm))
            {
                return Err(
                    "human.arm needs mass_kg > 0 and finite damping_nspm, stiffness_npm >= 0"
                        .into(),
                );
            }
            if self
                .events
                .iter()
                .any(|e| matches!(e, Event::Move { .. } | Event::Shake { .. }))
            {
                return Err("human.arm: the hand is still behind an arm; use force events, not move or shake".into());
            }
        }
        self.arm = arm;
        Ok(self)
    }

    /// The plant's grasp for `kind`, with the arm when there is one.
    pub fn grasp_of(&self, kind: GraspKind) -> Grasp {
        let g = kind.grasp();
        match (kind, self.arm) {
            (GraspKind::HandsOff, _) | (_, None) => g,
            (_, arm) => Grasp { arm, ..g },
        }
    }

    /// Whether an arm is behind the grasp.
    pub fn has_arm(&self) -> bool {
        self.arm.is_some()
    }

    /// Every grasp the script uses (to prepare the plant for each).
    pub fn grasps(&self) -> Vec<GraspKind> {
        let mut g = vec![self.grasp];
        for e in &self.events {
            if let Event::Grip { grasp, .. } = e {
                if !g.contains(grasp) {
                    g.push(*grasp);
                }
            }
        }
        g
    }

    /// When the script last changes what the hand does (s).
    pub fn last_event_end(&self) -> f64 {
        self.events
            .iter()
            .map(|e| match *e {
                Event::Move { at_s, over_s, .. } => at_s + over_s,
                Event::Grip { at_s, .. } => at_s,
                Event::Shake { at_s, for_s, .. } | Event::Force { at_s, for_s, .. } => at_s + for_s,
            })
            .fold(0.0, f64::max)
    }

    /// The hand at time `t` (s).
    pub fn at(&self, t: f64) -> HandState {
        let mut s = HandState {
            grasp: self.grasp,
            position_m: 0.0,
            velocity_mps: 0.0,
            push_n: 0.0,
        };
        for e in self.events.iter().take_while(|e| e.at() <= t) {
            match *e {
                Event::Move { at_s, to_m, over_s } => {
                    let from = s.position_m;
                    let f = ((t - at_s) / over_s).min(1.0);
                    s.position_m = from + (to_m - from) * f;
                    s.velocity_mps = if f < 1.0 { (to_m - from) / over_s } else { 0.0 };
                }
                Event::Grip { grasp, .. } => s.grasp = grasp,
                Event::Shake {
                    at_s,
                    amplitude_m,
                    frequency_hz,
                    for_s,
                } if t < at_s + for_s => {
                    let w = 2.0 * std::f64::consts::PI * frequency_hz;
                    s.position_m += amplitude_m * (w * (t - at_s)).sin();
                    s.velocity_mps += amplitude_m * w * (w * (t - at_s)).cos();
                }
                Event::Force {
                    at_s,
                    force_n,
                    for_s,
                } if t < at_s + for_s => s.push_n += force_n,
                _ => {}
            }
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn script_moves_shakes_pushes_and_lets_go() {
        let h = Human::new(
            GraspKind::Maximum,
            vec![
                Event::Grip {
                    at_s: 3.0,
                    grasp: GraspKind::HandsOff,
                },
                Event::Move {
                    at_s: 0.0,
                    to_m: 0.02,
                    over_s: 1.0,
                },
                Event::Force {
                    at_s: 2.0,
                    force_n: 5.0,
                    for_s: 0.5,
                },
                Event::Shake {
                    at_s: 1.0,
                    amplitude_m: 0.001,
                    frequency_hz: 2.0,
                    for_s: 0.5,
                },
            ],
        )
        .unwrap();
        let mid = h.at(0.5);
        assert!((mid.position_m - 0.01).abs() < 1e-12 && (mid.velocity_mps - 0.02).abs() < 1e-12);
        let shaking = h.at(1.125);
        assert!((shaking.position_m - 0.021).abs() < 1e-9, "{shaking:?}");
        assert_eq!(h.at(2.2).push_n, 5.0);
        assert_eq!(h.at(2.6).push_n, 0.0);
        assert_eq!(h.at(3.5).grasp, GraspKind::HandsOff);
        assert_eq!(h.at(3.5).input_force(), 0.0);
        assert_eq!(h.last_event_end(), 3.0);
        assert_eq!(h.grasps(), vec![GraspKind::Maximum, GraspKind::HandsOff]);
    }

    #[test]
    fn bad_events_are_named() {
        let e = Human::new(
            GraspKind::Relaxed,
            vec![Event::Move {
                at_s: 0.0,
                to_m: 1.0,
                over_s: 0.0,
            }],
        )
        .unwrap_err();
        assert!(e.to_string().starts_with("human.script[0]: move"), "{e}");
    }
}
