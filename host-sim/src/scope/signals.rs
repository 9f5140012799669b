//! The signals the scope records: the simulation's, and a board's from
//! its telemetry.

use crate::Sample;
use twoport_link::Telemetry;

/// A simulated signal the scope records.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Signal {
    /// Handle position (m).
    HandlePosition,
    /// Handle velocity (m/s).
    HandleVelocity,
    /// Human force on the handle (N).
    HumanForce,
    /// Force the law commanded (N).
    CommandedForce,
    /// Force the actuator delivered (N).
    ActuatorForce,
    /// VE position (m).
    VePosition,
    /// VE force (N).
    VeForce,
    /// Coupling force (N).
    CouplingForce,
    /// Energy the human put in (J).
    EnergyIn,
    /// Energy stored in the device (J).
    EnergyStored,
    /// Energy the passivity layer saw its element take in (J).
    LayerEnergy,
    /// What the passivity layer added: damping (N s/m) or conductance
    /// (m/(N s)).
    LayerAdded,
}

impl Signal {
    /// Every signal, in ring order.
    pub const ALL: [Signal; 12] = [
        Signal::HandlePosition,
        Signal::HandleVelocity,
        Signal::HumanForce,
        Signal::CommandedForce,
        Signal::ActuatorForce,
        Signal::VePosition,
        Signal::VeForce,
        Signal::CouplingForce,
        Signal::EnergyIn,
        Signal::EnergyStored,
        Signal::LayerEnergy,
        Signal::LayerAdded,
    ];

    /// Legend text with unit.
    pub fn name(self) -> &'static str {
        match self {
            Signal::HandlePosition => "handle position (m)",
            Signal::HandleVelocity => "handle velocity (m/s)",
            Signal::HumanForce => "human force (N)",
            Signal::CommandedForce => "commanded force (N)",
            Signal::ActuatorForce => "actuator force (N)",
            Signal::VePosition => "VE position (m)",
            Signal::VeForce => "VE force (N)",
            Signal::CouplingForce => "coupling force (N)",
            Signal::EnergyIn => "energy in from the human (J)",
            Signal::EnergyStored => "energy stored in the device (J)",
            Signal::LayerEnergy => "energy the passivity layer saw taken in (J)",
            Signal::LayerAdded => "damping the passivity layer added (N s/m, or m/(N s) at a VE)",
        }
    }

    /// Its value on axis `axis` (a total for the energies).
    pub(crate) fn of<const N: usize>(self, s: &Sample<N>, axis: usize) -> f64 {
        let at = |v: &[f64; N]| v.get(axis).copied().unwrap_or(f64::NAN);
        match self {
            Signal::HandlePosition => at(&s.handle_m),
            Signal::HandleVelocity => at(&s.handle_mps),
            Signal::HumanForce => at(&s.human_n),
            Signal::CommandedForce => at(&s.commanded_n),
            Signal::ActuatorForce => at(&s.actuator_n),
            Signal::VePosition => at(&s.ve_m),
            Signal::VeForce => at(&s.ve_n),
            Signal::CouplingForce => at(&s.coupling_n),
            Signal::EnergyIn => s.energy_in_j,
            Signal::EnergyStored => s.energy_stored_j,
            Signal::LayerEnergy => at(&s.layer_energy_j),
            Signal::LayerAdded => at(&s.layer_added),
        }
    }

    pub(crate) fn index(self) -> usize {
        Signal::ALL.iter().position(|s| *s == self).unwrap_or(0)
    }
}

/// A signal from the board's telemetry.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BoardSignal {
    /// Actuator position from the encoder (m).
    Position,
    /// Force the board's law commanded (N).
    Commanded,
    /// Force sent to the amplifier (N).
    Actuator,
    /// The board's VE position (m).
    VePosition,
    /// The whole tick (cycles, or instructions in QEMU).
    LoopCycles,
    /// Reading the sensors (cycles).
    SenseCycles,
    /// The law and the safety layer (cycles).
    LawCycles,
    /// Driving the amplifier and queueing the answer (cycles).
    DriveCycles,
}

impl BoardSignal {
    /// Every board signal, in ring order.
    pub const ALL: [BoardSignal; 8] = [
        BoardSignal::Position,
        BoardSignal::Commanded,
        BoardSignal::Actuator,
        BoardSignal::VePosition,
        BoardSignal::LoopCycles,
        BoardSignal::SenseCycles,
        BoardSignal::LawCycles,
        BoardSignal::DriveCycles,
    ];

    /// The loop-timing signals, plotted together.
    pub const TIMING: [BoardSignal; 4] = [
        BoardSignal::LoopCycles,
        BoardSignal::SenseCycles,
        BoardSignal::LawCycles,
        BoardSignal::DriveCycles,
    ];

    /// Legend text with unit.
    pub fn name(self) -> &'static str {
        match self {
            BoardSignal::Position => "board: position (m)",
            BoardSignal::Commanded => "board: commanded force (N)",
            BoardSignal::Actuator => "board: actuator force (N)",
            BoardSignal::VePosition => "board: VE position (m)",
            BoardSignal::LoopCycles => "board: tick (cycles)",
            BoardSignal::SenseCycles => "board: sensors (cycles)",
            BoardSignal::LawCycles => "board: law + safety (cycles)",
            BoardSignal::DriveCycles => "board: drive + answer (cycles)",
        }
    }

    pub(crate) fn of(self, t: &Telemetry) -> f64 {
        match self {
            BoardSignal::Position => t.axes[0].position_pm as f64 * 1e-12,
            BoardSignal::Commanded => t.axes[0].commanded_n as f64,
            BoardSignal::Actuator => t.axes[0].actuator_n as f64,
            BoardSignal::VePosition => t.axes[0].ve_position_pm as f64 * 1e-12,
            BoardSignal::LoopCycles => t.loop_cycles as f64,
            BoardSignal::SenseCycles => t.stage_cycles[0] as f64,
            BoardSignal::LawCycles => t.stage_cycles[1] as f64,
            BoardSignal::DriveCycles => t.stage_cycles[2] as f64,
        }
    }
}
