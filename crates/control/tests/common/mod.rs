//! What the servo tests share: the test device's encoder and a wall.

#![allow(dead_code)] // each test file uses its own part

use twoport_control::ve::{Solid, UnilateralWall};
use twoport_control::{Encoder, Position};

/// The servo period (s).
pub const T: f32 = 1.0e-3;

/// A 16-bit counter, 1 µm per count.
pub fn encoder() -> Encoder {
    Encoder::new(16, 1_000_000, 0, Position::ZERO).unwrap()
}

/// The 16-bit count of `x_um` micrometres.
pub fn raw(x_um: i32) -> u32 {
    x_um as u32 & 0xFFFF
}

/// A wall of stiffness `k_npm` (N/m) and 50 N s/m at 0, solid above, the
/// probe at rest on its surface.
pub fn wall(k_npm: f32) -> UnilateralWall {
    let at = Position::ZERO;
    UnilateralWall::new(k_npm, 50.0, at, Solid::Above, T, at).unwrap()
}
