//! What the board and the host say to each other. Units are SI; positions
//! are integer picometres on the wire (`twoport-control` keeps nanometres,
//! so today's boards send multiples of 1000; the wire has room for finer).

use crate::frame::Stats;
use crate::{Axes, Spec, VeParam, VeSource, VeUpdate};
use serde::{Deserialize, Serialize};

/// The protocol version both ends must share (checked by the handshake).
/// Version 4 carries every axis of a board in its frames; version 5 a
/// session number in every answer, so that a host sees a board reset;
/// version 6 lets a board refuse what its device cannot do
/// ([`ModeRefusal::Unsupported`]); version 7 runs identification
/// experiments ([`Message::Identify`]); version 8 tells a host what the
/// board can do ([`Message::GetSpec`]) and lets it set the telemetry rate
/// ([`Message::SetStream`]).
pub const PROTOCOL_VERSION: u16 = 12;

/// The session number of a board no host has shaken hands with since it
/// booted. A host opens a session with any other number, and a board
/// stamps that number on every [`ActuatorFrame`], [`Telemetry`] and
/// [`Status`] it sends: an answer stamped with another number, this one
/// after a reset, comes from a board that has rebooted since the
/// handshake, whatever the timing (protocol 5).
pub const NO_SESSION: u16 = 0;

/// Which end is speaking in a handshake.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Role {
    /// The motor-controller board.
    Board,
    /// The host (simulator, scope).
    Host,
}

/// One axis's state in a telemetry frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct AxisTelemetry {
    /// Actuator position (pm).
    pub position_pm: i64,
    /// Actuator velocity (m/s).
    pub velocity_mps: f32,
    /// Load-cell force (N).
    pub load_cell_n: f32,
    /// Force the law commanded (N).
    pub commanded_n: f32,
    /// Force sent to the amplifier after the safety layer (N).
    pub actuator_n: f32,
    /// The VE point the axis's coupling holds (pm).
    pub ve_position_pm: i64,
}

/// The board's state each telemetry period, every axis of it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Telemetry {
    /// Control tick.
    pub tick: u32,
    /// Each axis's state (protocol 4).
    pub axes: Axes<AxisTelemetry>,
    /// Latched fault bits (`twoport_control::Faults`).
    pub faults: u16,
    /// Cycles (or instructions, in QEMU) the last tick took.
    pub loop_cycles: u32,
    /// What the board is doing (protocol 3).
    pub mode: BoardMode,
    /// The last tick's stages, in the same count: reading the sensors,
    /// the law and the safety layer, driving the amplifier and queueing
    /// the answer (protocol 3).
    pub stage_cycles: [u32; 3],
    /// Ticks since boot that overran their period, or came more than half
    /// a period late (protocol 3; 0 where the host paces the ticks).
    pub deadline_misses: u32,
    /// The largest difference since boot between a tick's start-to-start
    /// time and the period, in the same count (protocol 3; 0 where the
    /// host paces the ticks).
    pub worst_jitter_cycles: u32,
    /// The longest time since boot from sampling the sensors to writing
    /// the amplifiers' command, in the same count: the latency inside the
    /// tick a proof must allow for (protocol 11).
    pub worst_latency_cycles: u32,
    /// The session the board is in ([`NO_SESSION`] after a reset;
    /// protocol 5).
    pub session: u16,
    /// The last host VE update the board took ([`VeUpdate::seq`]; 0
    /// before any; protocol 8).
    pub ve_seq: u32,
}

/// The board's state machine (protocol 3). A board boots disarmed with its
/// outputs off; any fault returns it here.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum BoardMode {
    /// Outputs off, zero force.
    #[default]
    Disarmed,
    /// Moving slowly to the hard stop to find the encoder offset.
    Homing,
    /// Running the law: force output on.
    Armed,
    /// Playing an identification experiment, telemetry every tick; back
    /// to disarmed when it ends (protocol 7).
    Identifying,
}

/// What the host asked the state machine for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum ModeRequest {
    /// [`Message::Arm`].
    Arm,
    /// [`Message::Home`].
    Home,
    /// [`Message::Calibrate`].
    Calibrate,
    /// [`Message::SaveConfig`].
    SaveConfig,
    /// [`Message::Identify`] (protocol 7).
    Identify,
    /// [`Message::SetVe`] (protocol 8).
    SetVe,
    /// [`Message::SetVeParam`] (protocol 9).
    SetVeParam,
}

/// Why the board would not change mode.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum ModeRefusal {
    /// The encoder offset is unknown: home or calibrate first.
    NotCalibrated,
    /// The gains in force are outside the proven region.
    GainsNotProven,
    /// The dead-man switch is open (or no sensor reading has come yet).
    DeadManOpen,
    /// Faults are latched (their bits): clear them first.
    Faulted {
        /// The latched fault bits.
        faults: u16,
    },
    /// Only a disarmed board may do this.
    NotDisarmed {
        /// The mode it is in.
        mode: BoardMode,
    },
    /// The position is beyond the board's range (±2.147 m).
    OutOfRange,
    /// The configuration could not be written to flash.
    FlashFailed,
    /// The request gave another number of axes than the board's.
    WrongAxisCount {
        /// The board's axes.
        axes: u8,
    },
    /// This board's device cannot do it: a linkage has no homing run (it
    /// is calibrated at a known pose instead) (protocol 6).
    Unsupported,
    /// Only an armed board may do this (protocol 7).
    NotArmed {
        /// The mode it is in.
        mode: BoardMode,
    },
    /// The experiment asked for cannot be played: an axis the board does
    /// not have, a band past Nyquist, a peak past the axis's force limit,
    /// no period, or a hold outside the axis's proven region (protocol 7).
    BadExperiment,
    /// A host VE's deadline must be at least one tick (protocol 8).
    BadDeadline,
    /// The board's VE has no such parameter on that axis, or the value is
    /// out of its range (protocol 9).
    BadVeParam,
}

/// Where the configuration in force came from (protocol 3).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum ConfigSource {
    /// A valid record read from flash (or just written there).
    Stored {
        /// The record's sequence number (each save adds one).
        seq: u32,
    },
    /// The image's safe defaults, because of `why`.
    Defaults {
        /// Why no stored record is in force.
        why: ConfigFallback,
    },
}

/// Why a board runs its built-in defaults instead of a stored record.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum ConfigFallback {
    /// No record was ever written (the flash is erased).
    Missing,
    /// Both copies fail their check (CRC, length or encoding).
    Corrupt,
    /// The newest record is of an older format than this image reads.
    OlderVersion {
        /// The record's format version.
        found: u16,
    },
    /// The newest record is of a newer format than this image reads.
    NewerVersion {
        /// The record's format version.
        found: u16,
    },
    /// The record decodes but a value is out of its range.
    Invalid,
    /// The stored gains are outside the region this image proves stable.
    NotProven,
    /// The flash could not be read.
    Unreadable,
    /// The record holds another number of axes than this board has.
    WrongAxes {
        /// The axes the record holds.
        found: u8,
    },
}

/// The board's state, sent on request and whenever it changes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Status {
    /// Where the state machine is.
    pub mode: BoardMode,
    /// Whether the encoder offset is known (homed or calibrated).
    pub calibrated: bool,
    /// Latched fault bits (`twoport_control::Faults`).
    pub faults: u16,
    /// The first fault to latch, alone (0: none).
    pub first_fault: u16,
    /// The session the board is in ([`NO_SESSION`] after a reset;
    /// protocol 5).
    pub session: u16,
}

/// Coupling (and regulator) gains: the servo's own type, encoded as
/// it is.
pub use twoport_control::Gains;

/// Why the board refused gains, and for which axis.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct AxisRefusal {
    /// The axis whose gains were refused (0 is x).
    pub axis: u8,
    /// Why.
    pub why: Refusal,
}

/// Why the board refused an axis's gains.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Refusal {
    /// A gain is NaN or infinite.
    NotFinite,
    /// A gain is negative (or zero where it must be positive).
    OutOfRange,
    /// Outside the region the designer proved absolutely stable; the bound
    /// at the asked damping is given (N/m for a stiffness, kg for a mass).
    NotProvenStable {
        /// The proven limit.
        limit: f32,
    },
    /// Gains for the other display type.
    WrongDisplay,
    /// Not one set of gains per axis of the board (protocol 4).
    WrongAxisCount {
        /// The board's axes.
        axes: u8,
    },
}

/// The board's answer to `SetGains`: every axis's gains change, or none.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum GainsReply {
    /// In force from the next tick, one per axis.
    Accepted(Axes<Gains>),
    /// Not applied; the old gains stay on every axis.
    Refused(AxisRefusal),
}

/// Processor-in-the-loop: the simulated sensors for one tick (host to
/// board), every axis sampled at one instant.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct PilSensors {
    /// Tick this frame is for.
    pub tick: u32,
    /// Each axis's raw encoder counter.
    pub encoder_raw: Axes<u32>,
    /// Each axis's raw load-cell ADC reading (counts).
    pub load_cell_raw: Axes<i32>,
    /// Dead-man switch closed (one for the device).
    pub dead_man_closed: bool,
    /// The encoder count each axis's index pulse latched this tick, if it
    /// passed (protocol 3).
    pub index_raw: Axes<Option<u32>>,
}

/// Processor-in-the-loop: the actuator command for one tick (board to
/// host), every axis updated together.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct ActuatorFrame {
    /// Tick this command answers.
    pub tick: u32,
    /// Each axis's signed PWM duty, full scale ±32767 = ± peak force.
    pub duty: Axes<i16>,
    /// The session the board is in ([`NO_SESSION`] after a reset;
    /// protocol 5).
    pub session: u16,
}

/// An identification experiment (protocol 7): a periodic multisine force
/// of harmonics `first..=last` of `period_ticks`, each of `amplitude_n`
/// (the host finds it for the peak it wants: a board does not scan a
/// period), on one axis for `periods` periods, every axis held where it
/// stood by a spring-damper of `hold_k_npm` (N/m) and `hold_b_nspm`
/// (N s/m), which must lie in the axis's proven region.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ExperimentRequest {
    /// The axis excited.
    pub axis: u8,
    /// The multisine's period (ticks).
    pub period_ticks: u32,
    /// Its lowest harmonic.
    pub first: u32,
    /// Its highest harmonic (below half the period).
    pub last: u32,
    /// Each harmonic's amplitude (N).
    pub amplitude_n: f32,
    /// The peak the host found for it (N): the board refuses one past the
    /// axis's continuous force, or below the multisine's rms.
    pub peak_n: f32,
    /// Periods played.
    pub periods: u32,
    /// The hold's stiffness (N/m).
    pub hold_k_npm: f32,
    /// The hold's damping (N s/m).
    pub hold_b_nspm: f32,
}

/// Every message.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Message {
    /// Handshake request with the sender's protocol version.
    Hello {
        /// Sender's version.
        version: u16,
        /// Sender's role.
        role: Role,
        /// How many axes the sender drives (protocol 4).
        axes: u8,
        /// The session the host opens: any number but [`NO_SESSION`]
        /// (protocol 5).
        session: u16,
    },
    /// Handshake answer.
    HelloAck {
        /// Answerer's version.
        version: u16,
        /// Whether the versions and the axis counts match.
        accepted: bool,
        /// How many axes the answerer has (protocol 4).
        axes: u8,
        /// The session the board is in from now on: the `Hello`'s when
        /// accepted, its old one otherwise (protocol 5).
        session: u16,
    },
    /// The host is alive (feeds the board's link watchdog).
    Heartbeat,
    /// Board state.
    Telemetry(Telemetry),
    /// Ask for the gains in force.
    GetGains,
    /// The gains in force, one per axis.
    Gains(Axes<Gains>),
    /// Ask for new gains, one per axis.
    SetGains(Axes<Gains>),
    /// Answer to `SetGains`.
    GainsReply(GainsReply),
    /// Latched faults (and the first one).
    FaultReport {
        /// All latched fault bits.
        faults: u16,
        /// The first fault's bit.
        first: u16,
    },
    /// Clear latched faults.
    ClearFaults,
    /// Arm: outputs on and the law running. Needs the dead-man closed,
    /// proven gains, a calibrated encoder and no fault (protocol 3).
    Arm,
    /// Disarm: outputs off (protocol 3).
    Disarm,
    /// Home: find the encoder offset on the hard stop (protocol 3).
    Home,
    /// Calibrate where the device stands now: each axis is at its
    /// `position_pm` (a jig, or a simulator that knows). Disarmed only
    /// (protocol 3; per axis since 4).
    Calibrate {
        /// Each axis's position now (pm).
        position_pm: Axes<i64>,
    },
    /// Ask for the state machine's [`Status`] (protocol 3).
    GetStatus,
    /// The board's state (protocol 3).
    Status(Status),
    /// Store the configuration in force (gains, calibration, limits) in
    /// flash. Disarmed only: writing flash stalls the processor (protocol 3).
    SaveConfig,
    /// Ask where the configuration in force came from (protocol 3).
    GetConfig,
    /// Where the configuration in force came from: sent at boot, on
    /// request and after a save (protocol 3).
    Config(ConfigSource),
    /// A mode change the board refused (protocol 3).
    ModeRefused {
        /// What was asked.
        asked: ModeRequest,
        /// Why not.
        why: ModeRefusal,
    },
    /// PIL sensors in.
    Sensors(PilSensors),
    /// PIL actuator out.
    Actuator(ActuatorFrame),
    /// Ask for the board's link counters (protocol 2).
    GetStats,
    /// The board's link counters (protocol 2).
    Stats(LinkStats),
    /// Play an identification experiment: an armed board, calibrated, its
    /// dead-man switch closed and no fault latched, switches to
    /// [`BoardMode::Identifying`] and sends telemetry every tick until it ends
    /// (protocol 7).
    Identify(ExperimentRequest),
    /// Ask for the board's [`Spec`] (protocol 8).
    GetSpec,
    /// What the board can do and what it will accept (protocol 8).
    Spec(Spec),
    /// Send telemetry every `every_ticks` ticks from now on (0: none
    /// outside an experiment), in any mode (protocol 8).
    SetStream {
        /// Ticks between telemetry frames.
        every_ticks: u32,
    },
    /// The telemetry rate in force, in answer to
    /// [`SetStream`](Message::SetStream) (protocol 8).
    Stream {
        /// Ticks between telemetry frames (0: none).
        every_ticks: u32,
    },
    /// Run the VE on the board or on the host: disarmed only (protocol 8).
    SetVe(VeSource),
    /// The VE source in force, in answer to [`SetVe`](Message::SetVe)
    /// (protocol 8).
    Ve(VeSource),
    /// The host VE's points (protocol 8); no answer: the telemetry's
    /// `ve_seq` says which update the board holds.
    VeUpdate(VeUpdate),
    /// Set one parameter of the board's own VE on `axis`: disarmed only
    /// (protocol 9).
    SetVeParam {
        /// The axis (0 is x).
        axis: u8,
        /// What to set, and to what.
        param: VeParam,
    },
    /// The parameter in force, in answer to
    /// [`SetVeParam`](Message::SetVeParam) (protocol 9).
    VeParamSet {
        /// The axis.
        axis: u8,
        /// What was set.
        param: VeParam,
    },
}

/// The board's view of the link.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct LinkStats {
    /// What the board's decoder received and dropped.
    pub rx: Stats,
    /// Outgoing frames the board dropped because its queue was full.
    pub tx_dropped: u32,
}
