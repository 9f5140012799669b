//! The three-axis Excalibur image: every axis the x axis's region and
//! coupling (the paper designs the worst-case axis, x, and uses it for y
//! and z), and the building-block world with the blocks of [`BLOCKS`] on
//! the floor. The world's contacts take longer than one wall's: the region
//! is the designer's for a latency of up to 200 µs, which the slowest
//! board the image runs on (the an386's 25 MHz core) needs. The
//! processor-in-the-loop scene that drives it is
//! `scenes/xyz/pil_blocks.toml`.

use super::{safety, BuildError, ENCODER, PERIOD_S, TELEMETRY_EVERY};
use crate::io::IoScale;
use crate::Board;
use twoport_control::homing::HomingConfig;
use twoport_control::servo::Servo;
use twoport_control::world::vbb::{Block, Vbb, VbbConfig};
use twoport_control::{Encoder, ImpedanceGains, ParamError, Position};

crate::region::shipped_region!(
    /// The x axis's proven region (impedance display, paper human bound,
    /// T = 1 ms, latency 200 µs).
    "../excalibur_xyz_region.rs"
);

/// The coupling on every axis: 90% of the stiffest the region proves at
/// the paper's damping (31,847 N/m at 90 N s/m).
pub const COUPLING: ImpedanceGains = ImpedanceGains::new(28_500.0, 90.0);

/// The blocks the image's world starts with: lowest corner (m), size (m),
/// mass (kg). A 30 mm cube in reach of the start, a 20 mm one beside it,
/// and a 30 x 30 x 20 mm brick across the workspace.
pub const BLOCKS: [([f32; 3], [f32; 3], f32); 3] = [
    ([0.04, -0.015, 0.0], [0.03, 0.03, 0.03], 0.1),
    ([-0.06, 0.02, 0.0], [0.02, 0.02, 0.02], 0.05),
    ([0.0, 0.08, 0.0], [0.03, 0.03, 0.02], 0.08),
];

/// Homing: each axis creeps gently toward its low end onto a stop at the
/// workspace's lowest corner (x and y at -150 mm, z at the floor).
pub const HOMING: [HomingConfig; 3] = [
    HomingConfig::gentle(Position::from_nm(-150_000_000), PERIOD_S),
    HomingConfig::gentle(Position::from_nm(-150_000_000), PERIOD_S),
    HomingConfig::gentle(Position::ZERO, PERIOD_S),
];

/// The world's capacity: the blocks above.
pub const MAX_BLOCKS: usize = BLOCKS.len();

/// The image's world type.
pub type XyzWorld = Vbb<f32, MAX_BLOCKS>;

/// The image's servo type.
pub type XyzServo = Servo<XyzWorld, f32, 3>;

/// The image's board type.
pub type XyzBoard = Board<Servo<XyzWorld, f32, 3>, REGION_POINTS, 3>;

/// The image's world, its cursor at rest at the workspace's centre, 10 mm
/// above the floor.
pub fn world() -> Result<XyzWorld, BuildError> {
    let block =
        |(at, size, mass): ([f32; 3], [f32; 3], f32)| Block::new(at, size, mass).ok_or(BLOCK);
    let mut blocks = [block(BLOCKS[0])?; MAX_BLOCKS];
    for (b, spec) in blocks.iter_mut().zip(BLOCKS) {
        *b = block(spec)?;
    }
    Ok(Vbb::new(VbbConfig::excalibur(PERIOD_S), &blocks)?)
}

/// A block out of the world's range: a constant above is wrong.
const BLOCK: BuildError = BuildError::Param(ParamError {
    name: "excalibur::xyz::BLOCKS",
    value: 0.0,
    problem: "a block lies out of the world's range",
});

/// The three-axis servo: the impedance display on the world, disabled
/// until the host enables it.
pub fn servo() -> Result<XyzServo, BuildError> {
    let enc = Encoder::new(ENCODER.bits, ENCODER.pm_per_count, 0, Position::ZERO)?;
    Ok(Servo::new(
        [COUPLING.into(); 3],
        [enc; 3],
        [safety(); 3],
        world()?,
    )?)
}

/// The whole three-axis board: the region on every axis, the same
/// I/O scaling on each, and [`HOMING`]. It reads its own sensors; the
/// processor-in-the-loop images add `.with_pil(true)`.
pub fn board() -> Result<XyzBoard, BuildError> {
    let region = proven_region()?;
    // The world's walls are the travel it states.
    let [lo, hi] = VbbConfig::excalibur(PERIOD_S).workspace;
    Ok(Board::new(servo()?, [region; 3], TELEMETRY_EVERY)
        .with_io([IoScale::EXCALIBUR; 3])
        .with_homing(HOMING)
        .with_workspace(core::array::from_fn(|i| (lo[i], hi[i]))))
}
