// Made by the designer: `twoport region impedance --latency 0.005 --b-from 1 --b-to 16 --points 9 --rust`. Do not edit;
// tests/shipped_region.rs checks it against the designer.
/// What the region bounds.
pub const BOUND: Bound = Bound::MaxStiffness;
/// Coupling damping grid (N s/m).
pub const DAMPING_NSPM: [f32; 8] = [1.0, 1.4142135, 2.0, 2.828427, 4.0, 5.656854, 8.0, 11.313708];
/// The proven limit at each damping (N/m).
pub const LIMIT: [f32; 8] = [2195.8096, 2466.1243, 2792.5337, 3184.8496, 3417.6091, 3451.908, 3166.2747, 2037.4347];
/// The regulator (k_p N/m, b_p N s/m) an admittance region holds for.
pub const REGULATOR: Option<(f32, f32)> = None;
/// The latency from sampling to the force (s) the limits are proven for.
pub const LATENCY_S: f32 = 0.005;
