//! Processor in the loop for a teleoperator: two boards, each running its
//! device's coupling against a point the host holds, and the host as the
//! channel between them.
//!
//! Each board runs the impedance display with the host's VE (protocol 8)
//! held rigidly ([`Contact::Held`]) and moved in one tick: its coupling
//! `k (x - x_p) + b (v - v_p)` against the other device's position, which
//! the host reads from the counts it sent that board `d` ticks before.
//! That is the control crate's position-position teleoperator
//! ([`FourChannel::position_position`](twoport_control::teleop::FourChannel::position_position))
//! across a channel `d` ticks long, the law the designer proves: the
//! coupling's point moves by the other's backward difference, as the
//! law's delayed velocity does.

use super::{boot_and_save, check_scene, record_read, zero_after_loss, Run};
use crate::engine::teleop::{SideSpec, TeleopScene};
use crate::link::{BoardPort, LinkFaults, Session};
use crate::{Error, Simulation};
use twoport_board::excalibur;
use twoport_control::{Encoder, Position};
use twoport_design::verify::TeleopLaw;
use twoport_link::{Axes, Contact, Gains, VeSource};

/// The gains each board runs: the law's spring (N/m) and damper (N s/m),
/// the same on both sides (position-position), refused otherwise.
pub fn pair_gains(scene: &TeleopScene) -> Result<(f32, f32), Error> {
    let g = match scene.law {
        TeleopLaw::FourChannel(g) => g,
        TeleopLaw::Wave(_) => {
            return Err(Error::Pil(
                "a PIL pair runs position-position: each board's coupling holds it to the \
                 other's motion; the wave channel is not a board's law"
                    .into(),
            ))
        }
    };
    let symmetric = g.k_m_npm == g.k_s_npm && g.b_m_nspm == g.b_s_nspm;
    let forces = [g.b_local_nspm, g.c2, g.c3, g.c5, g.c6];
    if !symmetric || forces.iter().any(|&c| c != 0.0) {
        return Err(Error::Pil(
            "a PIL pair runs position-position: law.gains with k_m_npm = k_s_npm, \
             b_m_nspm = b_s_nspm and no other gain"
                .into(),
        ));
    }
    let c = &scene.channel;
    if !c.is_constant() || c.delay_ticks == 0 {
        return Err(Error::Pil(
            "a PIL pair's channel is the host: channel.delay_ticks of at least 1, \
             no jitter, drops or guard"
                .into(),
        ));
    }
    Ok((g.k_m_npm, g.b_m_nspm))
}

/// One side of a pair in progress: its plant, its board, its record and
/// the positions its board has read (pm).
struct Side<P: BoardPort> {
    sim: Simulation,
    session: Session<P>,
    run: Run,
    encoder: Encoder,
    read_pm: Vec<i64>,
    seq: u32,
}

impl<P: BoardPort> Side<P> {
    fn open(
        scene: &TeleopScene,
        (name, spec): (&str, &SideSpec),
        port: P,
        faults: LinkFaults,
    ) -> Result<Self, Error> {
        let side = scene.side(spec, name);
        check_scene(&side).map_err(|e| pil_err!("{name}: {e}"))?;
        let sim = Simulation::new(side)?;
        let mut session = Session::open(port, faults)?;
        let board = session.spec()?;
        if (board.period_s() - scene.period()).abs() > 1e-9 {
            return Err(pil_err!(
                "the {name}'s board runs every {} s and the scene every {} s: set period_s to the board's",
                board.period_s(),
                scene.period()
            ));
        }
        let run = Run {
            start: Some(super::Start::Calibrate),
            spec: Some(board),
            config: Some(boot_and_save(&mut session)?),
            ..Run::default()
        };
        let scale = excalibur::ENCODER;
        let encoder = Encoder::new(scale.bits, scale.pm_per_count, 0, Position::ZERO)
            .map_err(|e| pil_err!("the board's encoder: {e:?}"))?;
        Ok(Side {
            sim,
            session,
            run,
            encoder,
            read_pm: Vec::new(),
            seq: 0,
        })
    }

    /// One tick, recorded, and the position the board read (pm).
    fn tick(&mut self) -> Result<(), Error> {
        let (_, raw) = record_read(&mut self.session, &mut self.sim, &mut self.run)?;
        let at = self
            .encoder
            .update(raw[0])
            .map_err(|e| pil_err!("the counts sent: {e:?}"))?;
        self.read_pm.push(at.nm() as i64 * 1000);
        Ok(())
    }

    /// Calibrated at rest at 0, the coupling `(k, b)` set, the VE handed
    /// to the host (each update reached in one tick), armed.
    fn arm(&mut self, (k, b): (f32, f32), deadline_ticks: u32) -> Result<(), Error> {
        self.session.calibrate(Axes::one(0))?;
        let gains = Gains::impedance(k, b);
        self.session
            .set_gains(Axes::one(gains))
            .map_err(|e| pil_err!("law.gains ({k} N/m, {b} N s/m): {e}"))?;
        self.session.set_ve(VeSource::Host {
            ramp_ticks: 1,
            deadline_ticks,
        })?;
        self.session.arm()?;
        self.run.armed_at_tick = self.run.samples.len() as u64;
        Ok(())
    }

    /// Send the board the other side's position (pm) as its held point,
    /// before this tick's sensors.
    fn hold_at(&mut self, pm: i64) -> Result<(), Error> {
        self.seq += 1;
        self.session
            .ve_update(self.seq, Axes::one(pm), Axes::one(Contact::Held))?;
        Ok(())
    }
}

/// A pair's run: each side's record, master first, and the position
/// each board read each tick (pm).
#[derive(Clone, Debug)]
pub struct PairRun {
    /// The master's run and the slave's.
    pub runs: [Run; 2],
    /// What each board read from its encoder each tick (pm), master
    /// first: what the host sent the other.
    pub read_pm: [Vec<i64>; 2],
}

/// Run the teleoperation `scene` for `ticks` with its master's board at
/// `master` and its slave's at `slave`: both calibrated and armed after
/// one tick, then each tick each board sent the other's position as it
/// read it `delay_ticks` before.
pub fn run_pair<P: BoardPort>(
    scene: &TeleopScene,
    ticks: u64,
    [master, slave]: [P; 2],
    faults: LinkFaults,
) -> Result<PairRun, Error> {
    let gains = pair_gains(scene)?;
    let d = scene.channel.delay_ticks;
    let [m, s] = scene.sides();
    let mut sides = [
        Side::open(scene, m, master, faults)?,
        Side::open(scene, s, slave, faults)?,
    ];
    for s in &mut sides {
        s.tick()?;
    }
    // An update every tick: the board may serve one for a few more.
    let deadline = (d as u32).saturating_add(10);
    for s in &mut sides {
        s.arm(gains, deadline)?;
    }
    for t in 1..ticks as usize {
        // What each board reads this tick: the other's count of `d`
        // ticks before (its rest before the run's first).
        let sent: [i64; 2] =
            core::array::from_fn(|i| t.checked_sub(d).map_or(0, |k| sides[1 - i].read_pm[k]));
        for (s, pm) in sides.iter_mut().zip(sent) {
            s.hold_at(pm)?;
            s.tick()?;
        }
    }
    let [mut m, mut s] = sides.map(|mut s| {
        s.run.ve_updates_sent = s.seq;
        s
    });
    for side in [&mut m, &mut s] {
        side.run.board_stats = side.session.board_stats()?;
        side.run.host_dropped = side.session.host_dropped();
        side.run.corrupted_sent = side.session.corrupted_sent;
        side.run.zero_after_loss_ticks = zero_after_loss(&side.run.duties, faults);
    }
    Ok(PairRun {
        runs: [m.run, s.run],
        read_pm: [m.read_pm, s.read_pm],
    })
}
