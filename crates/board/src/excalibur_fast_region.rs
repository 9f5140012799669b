// Made by the designer: `twoport region impedance --period 0.00025 --latency 25e-6 --b-from 30 --b-to 2430 --points 17 --rust`. Do not edit;
// tests/shipped_region.rs checks it against the designer.
/// What the region bounds.
pub const BOUND: Bound = Bound::MaxStiffness;
/// Coupling damping grid (N s/m).
pub const DAMPING_NSPM: [f32; 16] = [30.0, 39.48222, 51.961525, 68.38521, 90.0, 118.44666, 155.88457, 205.15564, 270.0, 355.34, 467.65372, 615.4669, 810.0, 1066.0199, 1402.9612, 1846.4008];
/// The proven limit at each damping (N/m).
pub const LIMIT: [f32; 16] = [173822.16, 191929.23, 212606.66, 236090.02, 262589.53, 292254.63, 325114.28, 360979.84, 399282.22, 438795.3, 477152.06, 509939.7, 528849.56, 517199.2, 434876.06, 22406.313];
/// The regulator (k_p N/m, b_p N s/m) an admittance region holds for.
pub const REGULATOR: Option<(f32, f32)> = None;
/// The latency from sampling to the force (s) the limits are proven for.
pub const LATENCY_S: f32 = 2.5e-5;
