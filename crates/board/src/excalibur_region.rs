// Made by the designer: `twoport region impedance --latency 25e-6 --b-from 10 --b-to 810 --points 17 --rust`. Do not edit;
// tests/shipped_region.rs checks it against the designer.
/// What the region bounds.
pub const BOUND: Bound = Bound::MaxStiffness;
/// Coupling damping grid (N s/m).
pub const DAMPING_NSPM: [f32; 11] = [10.0, 13.16074, 17.320509, 22.79507, 30.0, 39.48222, 51.961525, 68.38521, 90.0, 118.44666, 155.88457];
/// The proven limit at each damping (N/m).
pub const LIMIT: [f32; 11] = [35047.01, 37131.453, 39430.094, 41886.777, 44394.684, 46764.637, 48670.023, 49544.438, 48369.117, 43133.313, 28740.396];
/// The regulator (k_p N/m, b_p N s/m) an admittance region holds for.
pub const REGULATOR: Option<(f32, f32)> = None;
/// The latency from sampling to the force (s) the limits are proven for.
pub const LATENCY_S: f32 = 2.5e-5;
