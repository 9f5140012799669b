//! The C ABI's plain data: what a board can do, its state at one tick, and
//! the codes every call returns. Units are SI.

use twoport_host::{AxisState, BoardMode, Contact, Spec, State};

/// The most axes a board has (a three-axis device).
pub const TP_MAX_AXES: usize = 3;

/// A VE surface that is the point the coupling holds, moved by the host.
pub const TP_CONTACT_HELD: u8 = 0;
/// A VE surface solid above: free below it, the point stopped at it.
pub const TP_CONTACT_ABOVE: u8 = 1;
/// A VE surface solid below: free above it.
pub const TP_CONTACT_BELOW: u8 = 2;
/// No surface: the point follows the handle with no force.
pub const TP_CONTACT_FREE: u8 = 3;
/// `tp_board_set_ve_param`: the VE's surface or anchor (m).
pub const TP_VE_SURFACE: u8 = 0;
/// Its stiffness (N/m).
pub const TP_VE_STIFFNESS: u8 = 1;
/// Its damping (N s/m).
pub const TP_VE_DAMPING: u8 = 2;

/// The contact a C caller's code names, if it names one.
pub(crate) fn contact(c: u8) -> Option<Contact> {
    match c {
        TP_CONTACT_HELD => Some(Contact::Held),
        TP_CONTACT_ABOVE => Some(Contact::Above),
        TP_CONTACT_BELOW => Some(Contact::Below),
        TP_CONTACT_FREE => Some(Contact::Free),
        _ => None,
    }
}

/// What a call did. On anything but `TP_RESULT_OK`, `tp_last_error` says
/// why.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TpResult {
    /// Done.
    Ok = 0,
    /// The link failed: the port, the transport, the handshake.
    Link = 1,
    /// The board refused (a mode change, gains past the proven region).
    Refused = 2,
    /// An argument is wrong: NULL, another count than the board's axes,
    /// a value out of range, nothing streamed yet.
    Argument = 3,
    /// The board did not answer in time.
    Timeout = 4,
    /// The board has reset since it was opened (or another host opened
    /// it): open it again.
    Reset = 5,
    /// The board latched a fault while the call waited.
    Faulted = 6,
    /// twoport failed inside (a bug), caught at the boundary.
    Panic = 7,
}

/// What a board was doing.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TpMode {
    /// Outputs off, zero force.
    Disarmed = 0,
    /// Homing onto its stops.
    Homing = 1,
    /// The coupling running, force on.
    Armed = 2,
    /// Playing an identification experiment.
    Identifying = 3,
}

/// Which display a proven region bounds.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TpDisplay {
    /// A spring-damper coupling: `limit` is the stiffest (N/m).
    Impedance = 0,
    /// A mass-damper coupling for one regulator: `limit` is the lightest
    /// mass (kg).
    Admittance = 1,
}

/// One axis's limits and proven region.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TpAxisSpec {
    /// The force the safety layer allows for a short time (N).
    pub peak_force_n: f64,
    /// The force it allows indefinitely (N).
    pub continuous_force_n: f64,
    /// The speed past which the axis faults to zero force (m/s).
    pub max_velocity_mps: f64,
    /// The display the region bounds.
    pub display: TpDisplay,
    /// The least coupling damping proven (N s/m).
    pub b_min_nspm: f64,
    /// The greatest (N s/m).
    pub b_max_nspm: f64,
    /// The extreme coupling proven: the stiffest spring (N/m) or the
    /// lightest mass (kg) ...
    pub limit: f64,
    /// ... at this damping (N s/m).
    pub b_at_limit_nspm: f64,
    /// The admittance region's regulator stiffness (N/m; 0 for impedance).
    pub kp_npm: f64,
    /// Its damping (N s/m; 0 for impedance).
    pub bp_nspm: f64,
    /// Whether the board states the axis's travel (protocol 9) ...
    pub has_workspace: bool,
    /// ... its lowest position (m) ...
    pub workspace_lo_m: f64,
    /// ... and its highest (m).
    pub workspace_hi_m: f64,
}

/// What a board can do.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TpSpec {
    /// The servo's period (s).
    pub period_s: f64,
    /// Telemetry every this many ticks (0: none).
    pub stream_every: u32,
    /// Whether the motors turn a linkage's joints.
    pub linkage: bool,
    /// What the link carries (bytes/s; 0 where the board does not say):
    /// a stream faster than that loses frames.
    pub link_bytes_per_s: u32,
    /// The longest time since boot from sampling the sensors to writing
    /// the amplifiers' command (s), when the spec was read: the latency
    /// inside the tick. NaN where the board does not give its count's rate.
    pub worst_latency_s: f64,
    /// The latency from sampling to the force (s) the proven regions
    /// allow: a board that times its loop faults past it ("force late"),
    /// or engages its passivity layer where it has one.
    pub latency_budget_s: f64,
    /// The board's axes (1 to `TP_MAX_AXES`).
    pub axes: u8,
    /// Each axis's, the first `axes` of them.
    pub axis: [TpAxisSpec; TP_MAX_AXES],
}

/// The board at one tick.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TpState {
    /// The board's tick.
    pub tick: u32,
    /// Latched fault bits (0: none; `tp_last_error` names them when a
    /// call fails on one).
    pub faults: u16,
    /// What the board was doing.
    pub mode: TpMode,
    /// The host VE update the board held.
    pub ve_seq: u32,
    /// Ticks since boot that overran their period, or came late.
    pub deadline_misses: u32,
    /// The loop's last tick, in the board's cycle count.
    pub loop_cycles: u32,
    /// The longest from sampling to the amplifiers' command since boot,
    /// in the same count.
    pub worst_latency_cycles: u32,
    /// The board's axes.
    pub axes: u8,
    /// Each axis's, the first `axes` of them.
    pub axis: [AxisState; TP_MAX_AXES],
}

impl From<&Spec> for TpSpec {
    fn from(s: &Spec) -> Self {
        let zero = TpAxisSpec {
            peak_force_n: 0.0,
            continuous_force_n: 0.0,
            max_velocity_mps: 0.0,
            display: TpDisplay::Impedance,
            b_min_nspm: 0.0,
            b_max_nspm: 0.0,
            limit: 0.0,
            b_at_limit_nspm: 0.0,
            kp_npm: 0.0,
            bp_nspm: 0.0,
            has_workspace: false,
            workspace_lo_m: 0.0,
            workspace_hi_m: 0.0,
        };
        let mut axis = [zero; TP_MAX_AXES];
        for (out, a) in axis.iter_mut().zip(s.axes.iter()) {
            let f = f64::from;
            let (lo, hi) = a.workspace_nm.unwrap_or((0, 0));
            let base = TpAxisSpec {
                peak_force_n: f(a.peak_force_n),
                continuous_force_n: f(a.continuous_force_n),
                max_velocity_mps: f(a.max_velocity_mps),
                has_workspace: a.workspace_nm.is_some(),
                workspace_lo_m: f64::from(lo) * 1e-9,
                workspace_hi_m: f64::from(hi) * 1e-9,
                ..zero
            };
            let r = &a.region;
            let ((b_min, b_max), (limit, b_at), (kp, bp)) = (
                r.b_range_nspm(),
                r.limit(),
                r.regulator().unwrap_or((0.0, 0.0)),
            );
            *out = TpAxisSpec {
                display: if r.is_impedance() {
                    TpDisplay::Impedance
                } else {
                    TpDisplay::Admittance
                },
                b_min_nspm: f(b_min),
                b_max_nspm: f(b_max),
                limit: f(limit),
                b_at_limit_nspm: f(b_at),
                kp_npm: f(kp),
                bp_nspm: f(bp),
                ..base
            };
        }
        TpSpec {
            period_s: s.period_s(),
            stream_every: s.stream_every,
            linkage: s.linkage,
            link_bytes_per_s: s.link_bytes_per_s.unwrap_or(0),
            worst_latency_s: s.worst_latency_s().unwrap_or(f64::NAN),
            latency_budget_s: f64::from(s.latency_budget_s),
            axes: s.axes.len() as u8,
            axis,
        }
    }
}

impl From<&State> for TpState {
    fn from(s: &State) -> Self {
        let mut axis = [AxisState::default(); TP_MAX_AXES];
        for (out, a) in axis.iter_mut().zip(s.axes.iter()) {
            *out = *a;
        }
        TpState {
            tick: s.tick,
            faults: s.faults,
            mode: match s.mode {
                BoardMode::Disarmed => TpMode::Disarmed,
                BoardMode::Homing => TpMode::Homing,
                BoardMode::Armed => TpMode::Armed,
                BoardMode::Identifying => TpMode::Identifying,
            },
            ve_seq: s.ve_seq,
            deadline_misses: s.deadline_misses,
            loop_cycles: s.loop_cycles,
            worst_latency_cycles: s.worst_latency_cycles,
            axes: s.axes.len() as u8,
            axis,
        }
    }
}

/// A sample's median, 99th percentile and greatest value.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TpPercentiles {
    /// The median.
    pub p50: f64,
    /// The 99th percentile.
    pub p99: f64,
    /// The greatest.
    pub max: f64,
}

impl From<twoport_host::Percentiles> for TpPercentiles {
    fn from(p: twoport_host::Percentiles) -> Self {
        TpPercentiles {
            p50: p.p50,
            p99: p.p99,
            max: p.max,
        }
    }
}

/// The servo loop's timing where it runs on this computer (over the last
/// ticks of a window): every tick's period and device exchange, and the
/// latency from a sample to its force (s).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TpLoopTiming {
    /// Ticks run.
    pub ticks: u64,
    /// Ticks that started more than 1.5 periods after the one before.
    pub late: u64,
    /// The period between ticks' starts (s).
    pub period_s: TpPercentiles,
    /// The device exchange's time (s).
    pub io_s: TpPercentiles,
    /// From the start of the exchange that read a tick's sensors to the
    /// end of the one that wrote its force (s).
    pub latency_s: TpPercentiles,
}

impl From<&twoport_host::LoopTiming> for TpLoopTiming {
    fn from(t: &twoport_host::LoopTiming) -> Self {
        TpLoopTiming {
            ticks: t.ticks,
            late: t.late,
            period_s: t.period_s.into(),
            io_s: t.io_s.into(),
            latency_s: t.latency_s.into(),
        }
    }
}
