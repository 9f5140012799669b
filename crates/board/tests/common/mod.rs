//! What the board's test files share: a three-point proven region and a
//! board on a bilateral constraint at the origin.

use twoport_board::{Board, Bound, Region};
use twoport_control::ve::BilateralConstraint;
use twoport_control::{Encoder, ImpedanceGains, Position, SafetyConfig, Servo};

/// The Excalibur's limits with a 50-tick link watchdog and the dead-man
/// switch required.
// (Each test file builds `common` anew; not every one uses this.)
#[allow(dead_code)]
pub fn safety() -> SafetyConfig {
    SafetyConfig {
        heartbeat_timeout_ticks: 50,
        require_dead_man: true,
        ..SafetyConfig::excalibur()
    }
}

/// The board every test drives.
pub type TestBoard = Board<Servo<BilateralConstraint>, 3>;

/// A proven region of three damping points (N s/m) and their largest
/// stiffness (N/m).
pub fn region() -> Region<3> {
    Region::new(
        Bound::MaxStiffness,
        [30.0, 60.0, 90.0],
        [46_000.0, 51_400.0, 51_000.0],
        None,
    )
    .unwrap()
}

/// An impedance display at `k_npm` (N/m) and 90 N s/m on a 16-bit, 1 µm
/// encoder, with `safety`'s limits and telemetry every `telemetry_every`
/// ticks (0: none).
pub fn board(k_npm: f32, safety: SafetyConfig, telemetry_every: u32) -> TestBoard {
    board_in(region(), k_npm, safety, telemetry_every)
}

/// [`board`] accepting the gains of `region`.
pub fn board_in(
    region: Region<3>,
    k_npm: f32,
    safety: SafetyConfig,
    telemetry_every: u32,
) -> TestBoard {
    let enc = Encoder::new(16, 1_000_000, 0, Position::ZERO).unwrap();
    let s = Servo::new(
        [ImpedanceGains::new(k_npm, 90.0).into()],
        [enc],
        [safety],
        BilateralConstraint::new(Position::ZERO),
    )
    .unwrap();
    Board::new(s, [region], telemetry_every)
}

/// The host's sensor frame for tick `tick`: the encoder at `raw`, the
/// dead-man closed.
// (Not every test file sends one.)
#[allow(dead_code)]
pub fn sensors(tick: u32, raw: u32) -> twoport_link::Message {
    twoport_link::Message::Sensors(twoport_link::PilSensors {
        tick,
        encoder_raw: twoport_link::Axes::one(raw),
        load_cell_raw: twoport_link::Axes::one(0),
        dead_man_closed: true,
        index_raw: twoport_link::Axes::one(None),
    })
}
