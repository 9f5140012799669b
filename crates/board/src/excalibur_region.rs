// Made by the designer: `twoport region impedance --b-from 10 --b-to 810 --points 17 --rust`. Do not edit;
// tests/shipped_region.rs checks it against the designer.
/// What the region bounds.
pub const BOUND: Bound = Bound::MaxStiffness;
/// Coupling damping grid (N s/m).
pub const DAMPING_NSPM: [f32; 11] = [10.0, 13.16074, 17.320509, 22.79507, 30.0, 39.48222, 51.961525, 68.38521, 90.0, 118.44666, 155.88457];
/// The proven limit at each damping (N/m).
pub const LIMIT: [f32; 11] = [36381.902, 38523.586, 40895.563, 43445.605, 46072.383, 48595.11, 50700.73, 51848.332, 51073.395, 46512.723, 33736.7];
/// The regulator (k_p N/m, b_p N s/m) an admittance region holds for.
pub const REGULATOR: Option<(f32, f32)> = None;
