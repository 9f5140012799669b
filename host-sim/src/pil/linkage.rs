//! Processor-in-the-loop on a linkage: the nonlinear arm of the device's
//! file at this end, a linkage board image (`twoport_board::linkage`) at
//! the other, joint encoder counts out and joint torque duties back each
//! tick, in lockstep.
//!
//! The run: the board boots and saves its configuration; one tick
//! disarmed; the host calibrates it at the rest pose (the joint angles,
//! in 1e-12 rad) and arms it; then, under gravity the board holds up, a
//! hand that grasps with 2 N s/m (the
//! images' least grasp) and a 300 N/m spring presses the handle 15 mm
//! down, through the board's floor 5 mm under the rest pose
//! ([`Plan::Press`]); or, hands off, the board plays an identification
//! experiment from the rest pose ([`Plan::Identify`]).

use super::{boot_and_save, zero_after_loss, Run};
use crate::engine::linkage::{CartesianHand, LinkageArm};
use crate::link::{BoardPort, LinkFaults, Session};
use crate::{Error, Sample};
use nalgebra::DMatrix;
use twoport_board::linkage::{self as image, ImageSpec};
use twoport_board::IoScale;
use twoport_design::linkage::LinkageFile;
use twoport_link::{Axes, Message, PilSensors};

/// The linkage images a PIL run drives.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
pub enum LinkageImage {
    /// The PHANToM Premium 1.5 serial arm.
    SerialArm,
    /// The Falcon-like rotary delta.
    Delta,
}

impl LinkageImage {
    /// The device file the plant integrates.
    pub fn file(self) -> Result<LinkageFile, Error> {
        let (text, name) = match self {
            LinkageImage::SerialArm => (
                include_str!("../../../models/linkages/phantom_premium_1_5.toml"),
                "phantom_premium_1_5.toml",
            ),
            LinkageImage::Delta => (
                include_str!("../../../models/linkages/falcon_like.toml"),
                "falcon_like.toml",
            ),
        };
        LinkageFile::from_toml(text, name).map_err(|e| Error::Pil(e.to_string()))
    }

    /// The board image's constants.
    pub fn spec(self) -> &'static ImageSpec {
        match self {
            LinkageImage::SerialArm => &image::PHANTOM,
            LinkageImage::Delta => &image::FALCON,
        }
    }
}

/// The hand that presses the handle down ([`Plan::Press`]): a spring to
/// an anchor below the rest pose, and a grasp.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PressingHand {
    /// How far below the rest pose the spring's anchor is (m).
    pub down_m: f64,
    /// The spring's stiffness on every axis (N/m).
    pub stiffness_npm: f64,
    /// The grasp's damping on every axis (N s/m).
    pub grasp_nspm: f64,
}

/// The hand PIL presses with.
pub const HAND: PressingHand = PressingHand {
    down_m: 0.015,
    stiffness_npm: 300.0,
    grasp_nspm: 2.0,
};

/// What the run does once the board is armed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Plan {
    /// The hand ([`HAND`]) presses the handle down through the floor.
    Press,
    /// Hands off, the board plays `experiment` from `start_ticks` after
    /// arming.
    Identify {
        /// The experiment, in the link's terms.
        experiment: twoport_link::ExperimentRequest,
        /// Ticks between arming and the experiment's start.
        start_ticks: u64,
        /// Whether the joints' Coulomb friction acts.
        friction: bool,
    },
}

/// Gravity on the arm (m/s², along `-z`).
pub const GRAVITY_MPS2: f64 = 9.81;

/// Runge-Kutta sub-steps per tick.
const SUBSTEPS: u32 = 8;

/// The arm at this end of the link and the hand on it.
struct PilArm {
    arm: LinkageArm<3>,
    hand: CartesianHand,
    io: [IoScale; 3],
    period_s: f64,
}

impl PilArm {
    fn new(device: LinkageImage, plan: Plan) -> Result<PilArm, Error> {
        let file = device.file()?;
        let spec = device.spec();
        let mut arm =
            LinkageArm::at_rest(&file, spec.rest_rad.map(f64::from)).map_err(plant_err)?;
        // (The images hold the moving masses up: gravity acts.)
        arm.plant.gravity_mps2 = GRAVITY_MPS2;
        let (x, _) = arm.handle().map_err(plant_err)?;
        let hand = match plan {
            Plan::Press => {
                let mut anchor = x.to_vec();
                anchor[2] -= HAND.down_m;
                CartesianHand {
                    anchor_m: anchor,
                    k_npm: DMatrix::identity(3, 3) * HAND.stiffness_npm,
                    b_nspm: DMatrix::identity(3, 3) * HAND.grasp_nspm,
                }
            }
            Plan::Identify { friction, .. } => {
                arm.plant.friction = friction;
                CartesianHand::off(3)
            }
        };
        Ok(PilArm {
            arm,
            hand,
            io: image::io(spec),
            period_s: f64::from(image::PERIOD_S),
        })
    }

    /// One tick: the sensors out, the board's duties back as torques held
    /// over the period.
    fn step<P: BoardPort>(
        &mut self,
        session: &mut Session<P>,
    ) -> Result<(Sample<3>, Axes<i16>), Error> {
        let tick = session.tick_heartbeat()?;
        let sensors = PilSensors {
            tick: tick as u32,
            encoder_raw: Axes::new(self.arm.counts()).unwrap_or_default(),
            load_cell_raw: Axes::new([0; 3]).unwrap_or_default(),
            dead_man_closed: true,
            index_raw: Axes::new([None; 3]).unwrap_or_default(),
        };
        let duty = session.exchange(tick, sensors)?;
        let tau: [f64; 3] = core::array::from_fn(|i| {
            f64::from(self.io[i].force_n(duty.get(i).copied().unwrap_or(0)))
        });
        let hand = &self.hand;
        self.arm
            .step(&tau, &|x, v| hand.force(x, v), self.period_s, SUBSTEPS)
            .map_err(plant_err)?;
        let (x, _) = self.arm.handle().map_err(plant_err)?;
        let sample = Sample {
            t_s: (tick + 1) as f64 * self.period_s,
            handle_m: x,
            actuator_n: tau,
            ..Sample::default()
        };
        Ok((sample, duty))
    }
}

fn plant_err(e: Error) -> Error {
    Error::Pil(format!("the linkage plant: {e}"))
}

/// One tick recorded, with the telemetry the board sent.
fn record<P: BoardPort>(
    session: &mut Session<P>,
    arm: &mut PilArm,
    r: &mut Run<3>,
) -> Result<(), Error> {
    let (s, duty) = arm.step(session)?;
    r.samples.push(s);
    r.duties.push(duty);
    for m in session.take_messages() {
        if let Message::Telemetry(t) = m {
            r.telemetry.push(t);
        }
    }
    Ok(())
}

/// Run `device`'s image at `port` for `ticks`, the hand pressing
/// ([`Plan::Press`]).
pub fn run<P: BoardPort>(
    device: LinkageImage,
    ticks: u64,
    port: P,
    faults: LinkFaults,
) -> Result<Run<3>, Error> {
    run_plan(device, ticks, port, faults, Plan::Press)
}

/// Run `device`'s image at `port` for `ticks` under `plan`.
pub fn run_plan<P: BoardPort>(
    device: LinkageImage,
    ticks: u64,
    port: P,
    faults: LinkFaults,
    plan: Plan,
) -> Result<Run<3>, Error> {
    let mut arm = PilArm::new(device, plan)?;
    let mut session = Session::open_axes(port, faults, 3)?;
    let spec = session.spec()?;
    if !spec.linkage {
        return Err(pil_err!(
            "the board at the port drives no linkage: flash a linkage image"
        ));
    }
    let mut r = Run {
        start: Some(super::Start::Calibrate),
        spec: Some(spec),
        config: Some(boot_and_save(&mut session)?),
        ..Run::default()
    };
    record(&mut session, &mut arm, &mut r)?;
    let pico = arm.arm.zero_rad().map(|q| (q * 1e12).round() as i64);
    session.calibrate(Axes::new(pico).unwrap_or_default())?;
    session.arm()?;
    r.armed_at_tick = r.samples.len() as u64;
    if let Plan::Identify {
        experiment,
        start_ticks,
        ..
    } = plan
    {
        let at = r.armed_at_tick + start_ticks;
        while (r.samples.len() as u64) < at.min(ticks) {
            record(&mut session, &mut arm, &mut r)?;
        }
        session.identify(experiment)?;
        r.experiment = Some((experiment, r.samples.len() as u64));
    }
    while (r.samples.len() as u64) < ticks {
        record(&mut session, &mut arm, &mut r)?;
    }
    r.board_stats = session.board_stats()?;
    r.host_dropped = session.host_dropped();
    r.corrupted_sent = session.corrupted_sent;
    r.zero_after_loss_ticks = zero_after_loss(&r.duties, faults);
    Ok(r)
}

/// [`run_plan`] against `device`'s image in-process.
pub fn run_local(
    device: LinkageImage,
    ticks: u64,
    faults: LinkFaults,
    plan: Plan,
) -> Result<Run<3>, Error> {
    use crate::link::{LocalDelta, LocalSerialArm};
    match device {
        LinkageImage::SerialArm => {
            run_plan(device, ticks, LocalSerialArm::serial_arm()?, faults, plan)
        }
        LinkageImage::Delta => run_plan(device, ticks, LocalDelta::delta()?, faults, plan),
    }
}

/// The sines a linkage's joint losses are fitted to
/// (`twoport_identify::pose::losses`): one sine on each Cartesian axis at
/// each level, hands off from the calibration pose, the board's hold on
/// every axis.
#[derive(Clone, Debug, PartialEq)]
pub struct Sines {
    /// The sine's frequency (Hz), a whole number of ticks a period.
    pub hz: f64,
    /// Periods played at each level.
    pub periods: u32,
    /// Each level's peak force (N), lowest first.
    pub levels_n: Vec<f64>,
    /// The hold's stiffness (N/m) and damping (N s/m).
    pub hold: (f64, f64),
    /// Whether the joints' Coulomb friction acts.
    pub friction: bool,
}

/// Ticks from arming to a sine's start.
const SINE_START_TICKS: u64 = 300;

impl Sines {
    /// The experiment on `axis` at `level_n` (N).
    pub fn spec(&self, axis: u8, level_n: f64) -> crate::engine::scene::IdentifySpec {
        crate::engine::scene::IdentifySpec {
            axis,
            start_s: SINE_START_TICKS as f64 * f64::from(image::PERIOD_S),
            period_s: 1.0 / self.hz,
            band_hz: [self.hz, self.hz],
            peak_n: level_n,
            periods: self.periods,
            hold_k_npm: self.hold.0,
            hold_b_nspm: self.hold.1,
        }
    }

    /// Every level's records on `device`'s image in-process:
    /// `[level][pushed axis][recorded axis]`, each run from the arm at
    /// rest at the calibration pose and stopped at the sine's last period
    /// (the board then disarms, and the arm would fall).
    pub fn play(
        &self,
        device: LinkageImage,
    ) -> Result<Vec<Vec<Vec<twoport_identify::log::Log>>>, Error> {
        let tick = f64::from(image::PERIOD_S);
        self.levels_n
            .iter()
            .map(|&level| {
                (0..3u8)
                    .map(|axis| {
                        let experiment = self.spec(axis, level).experiment(tick)?;
                        let plan = Plan::Identify {
                            experiment,
                            start_ticks: SINE_START_TICKS,
                            friction: self.friction,
                        };
                        let played =
                            u64::from(experiment.periods) * u64::from(experiment.period_ticks);
                        let r = run_local(
                            device,
                            1 + SINE_START_TICKS + played,
                            LinkFaults::default(),
                            plan,
                        )?;
                        r.experiment_axes().unwrap_or_else(|| {
                            Err(pil_err!(
                                "{device:?}: the board played no sine on axis {axis} at {level} N"
                            ))
                        })
                    })
                    .collect()
            })
            .collect()
    }
}
