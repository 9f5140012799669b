// Made by the designer: `twoport region impedance --latency 50e-6 --b-from 10 --b-to 810 --points 17 --rust`. Do not edit;
// tests/shipped_region.rs checks it against the designer.
/// What the region bounds.
pub const BOUND: Bound = Bound::MaxStiffness;
/// Coupling damping grid (N s/m).
pub const DAMPING_NSPM: [f32; 11] = [10.0, 13.16074, 17.320509, 22.79507, 30.0, 39.48222, 51.961525, 68.38521, 90.0, 118.44666, 155.88457];
/// The proven limit at each damping (N/m).
pub const LIMIT: [f32; 11] = [33796.594, 35825.42, 38052.902, 40419.082, 42811.652, 45033.094, 46742.69, 47347.625, 45770.9, 39833.86, 23556.451];
/// The regulator (k_p N/m, b_p N s/m) an admittance region holds for.
pub const REGULATOR: Option<(f32, f32)> = None;
/// The latency from sampling to the force (s) the limits are proven for.
pub const LATENCY_S: f32 = 5e-5;
