//! The passivity layer on a teleoperator's channel, on two devices
//! simulated apart from the laws: a master under an operator who pushes
//! it 20 mm and holds, a slave that meets a stiff wall on the way, and
//! between them a channel whose delay varies from 5 to 40 ticks, packet
//! by packet, and that drops one packet in five.
//!
//! The network's energy is computed here from the devices' true motion,
//! not from the guards: the work of the force held over each tick along
//! that tick's displacement, at both ports. Without the guard the
//! position-position teleoperator gives out energy it never took in, and
//! the slave rattles on the wall; with it, the network never gives out
//! more than a small share of what it took in, and the slave comes to
//! rest on the wall.

use std::collections::VecDeque;
use twoport_control::passivity::PassivityLimits;
use twoport_control::teleop::{ChannelGuard, FourChannel, Motion};
use twoport_control::{FirstDifference, Position};

const T: f64 = 1e-3;
const TICKS: usize = 6000;
const SUBSTEPS: usize = 20;

/// A device: a mass (kg) with damping (N s/m) to ground, integrated
/// finely between ticks under the held actuator force and an outside one.
struct Body {
    m: f64,
    b: f64,
    x: f64,
    v: f64,
}

impl Body {
    /// Advance a tick: `actuator_n` held (servo sign: resists +x), and
    /// `outside` the outside force (N, along +x) as a function of the
    /// body's position and velocity.
    fn tick(&mut self, actuator_n: f64, outside: impl Fn(f64, f64) -> f64) {
        let h = T / SUBSTEPS as f64;
        for _ in 0..SUBSTEPS {
            let a = (-actuator_n - self.b * self.v + outside(self.x, self.v)) / self.m;
            self.v += a * h;
            self.x += self.v * h;
        }
    }
}

/// What a side sends: its motion, its sensed force, and the energy its
/// port has put in (J).
type Packet = (Motion<f32>, f32, f32);

/// A channel whose delay varies packet by packet and that drops some:
/// the receiver holds the newest packet (by when it was sent) that has
/// arrived.
struct Link {
    in_flight: VecDeque<(usize, usize, Packet)>,
    newest: (usize, Packet),
    seed: u64,
}

impl Link {
    fn new(initial: Packet) -> Self {
        Link {
            in_flight: VecDeque::new(),
            newest: (0, initial),
            seed: 0x9e37_79b9_7f4a_7c15,
        }
    }

    fn random(&mut self) -> f64 {
        self.seed ^= self.seed << 13;
        self.seed ^= self.seed >> 7;
        self.seed ^= self.seed << 17;
        (self.seed >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Send `p` at tick `k`; what the receiver holds at tick `k`.
    fn pass(&mut self, k: usize, p: Packet) -> Packet {
        if self.random() >= 0.2 {
            let delay = 5 + (self.random() * 35.0) as usize;
            self.in_flight.push_back((k + delay, k, p));
        }
        let newest = &mut self.newest;
        self.in_flight.retain(|(arrive, sent, p)| {
            if *arrive <= k {
                if *sent >= newest.0 {
                    *newest = (*sent, *p);
                }
                false
            } else {
                true
            }
        });
        self.newest.1
    }
}

/// What a run gives: the least the network held (J: what it took in at
/// both ports less what it gave out, from the true motion), the most it
/// took in, and the slave's motion over the last second (its span, m).
struct Run {
    least_j: f64,
    most_in_j: f64,
    last_span_m: f64,
    /// Where the slave ends (m).
    slave_at_m: f64,
    /// The tick a device left the 0.5 m the simulation keeps to, if one
    /// did.
    ran_away: Option<usize>,
}

fn run(guarded: bool) -> Run {
    let law = FourChannel::<f32, 8>::position_position(2_000.0, 2.0, T as f32, 0, Position::ZERO)
        .unwrap();
    let limits = PassivityLimits::for_device(0.1, T as f32, 20.0).unwrap();
    let mut guards = [ChannelGuard::<f32>::new(limits).unwrap(); 2];
    let (mut master, mut slave) = (
        Body {
            m: 0.1,
            b: 0.05,
            x: 0.0,
            v: 0.0,
        },
        Body {
            m: 0.1,
            b: 0.05,
            x: 0.0,
            v: 0.0,
        },
    );
    let mut est = [FirstDifference::new(T as f32, Position::ZERO).unwrap(); 2];
    let rest: Packet = ((Position::ZERO, 0.0), 0.0, 0.0);
    let (mut to_slave, mut to_master) = (Link::new(rest), Link::new(rest));
    let wall = |x: f64| {
        if x > 5e-3 {
            -20_000.0 * (x - 5e-3)
        } else {
            0.0
        }
    };
    let (mut network_j, mut least_j, mut in_j) = (0.0f64, 0.0f64, 0.0f64);
    let mut last = (f64::INFINITY, f64::NEG_INFINITY);
    for k in 0..TICKS {
        if master.x.abs().max(slave.x.abs()) > 0.5 || !(master.x + slave.x).is_finite() {
            return Run {
                least_j,
                most_in_j: in_j,
                last_span_m: f64::INFINITY,
                slave_at_m: slave.x,
                ran_away: Some(k),
            };
        }
        let xs = [master.x, slave.x].map(|x| Position::from_m_f64(x).unwrap());
        let vs = [0, 1].map(|i| est[i].step(xs[i]));
        let env_n = wall(slave.x) as f32;
        let sent = [
            ((xs[0], vs[0]), 0.0, guards[0].energy_in_j()),
            ((xs[1], vs[1]), env_n, guards[1].energy_in_j()),
        ];
        let at_slave = to_slave.pass(k, sent[0]);
        let at_master = to_master.pass(k, sent[1]);
        let f = law.forces(
            (xs[0], vs[0]),
            (xs[1], vs[1]),
            0.0,
            env_n,
            (at_master.0, at_master.1),
            (at_slave.0, at_slave.1),
        );
        let mut forces = [f.master_n, f.slave_n];
        if guarded {
            forces[0] = guards[0].step(xs[0], vs[0], forces[0], at_master.2);
            forces[1] = guards[1].step(xs[1], vs[1], forces[1], at_slave.2);
        }
        let (x0, x1) = (master.x, slave.x);
        // The operator: 200 N/m and 2 N s/m to a point that moves 20 mm
        // in the first second and stays.
        let target = 0.02 * ((k as f64 * T).min(1.0));
        master.tick(f64::from(forces[0]), |x, v| 200.0 * (target - x) - 2.0 * v);
        slave.tick(f64::from(forces[1]), |x, _| wall(x));
        let took = f64::from(forces[0]) * (master.x - x0) + f64::from(forces[1]) * (slave.x - x1);
        network_j += took;
        in_j = in_j.max(network_j);
        least_j = least_j.min(network_j);
        if k >= TICKS - 1000 {
            last = (last.0.min(slave.x), last.1.max(slave.x));
        }
    }
    Run {
        least_j,
        most_in_j: in_j,
        last_span_m: last.1 - last.0,
        slave_at_m: slave.x,
        ran_away: None,
    }
}

#[test]
fn the_guard_keeps_a_varying_channel_passive() {
    let free = run(false);
    let held = run(true);
    eprintln!(
        "unguarded: least {:.3e} J, most in {:.3e} J, last span {:.3e} m, ran away {:?}; guarded: \
         least {:.3e} J, most in {:.3e} J, last span {:.3e} m, ran away {:?}",
        free.least_j,
        free.most_in_j,
        free.last_span_m,
        free.ran_away,
        held.least_j,
        held.most_in_j,
        held.last_span_m,
        held.ran_away
    );
    // Unguarded, the network gives out far more than it ever took in and
    // the slave is still rattling a second before the end.
    assert!(
        free.least_j < -10.0 * free.most_in_j.max(1e-6),
        "{}",
        free.least_j
    );
    assert!(free.last_span_m > 1e-3, "{}", free.last_span_m);
    // Guarded, it never gives out more than a tenth of what it took in,
    // and the slave rests on the wall.
    assert_eq!(held.ran_away, None);
    assert!(
        held.least_j > -0.1 * held.most_in_j,
        "{} of {}",
        held.least_j,
        held.most_in_j
    );
    assert!(held.last_span_m < 1e-4, "{}", held.last_span_m);
    // On the wall, pressed by the operator's push through the channel.
    assert!(held.slave_at_m > 5e-3, "{}", held.slave_at_m);
}
