// Made by the designer: `twoport region impedance --period 0.00025 --b-from 30 --b-to 2430 --points 17 --rust`. Do not edit;
// tests/shipped_region.rs checks it against the designer.
/// What the region bounds.
pub const BOUND: Bound = Bound::MaxStiffness;
/// Coupling damping grid (N s/m).
pub const DAMPING_NSPM: [f32; 16] = [30.0, 39.48222, 51.961525, 68.38521, 90.0, 118.44666, 155.88457, 205.15564, 270.0, 355.34, 467.65372, 615.4669, 810.0, 1066.0199, 1402.9612, 1846.4008];
/// The proven limit at each damping (N/m).
pub const LIMIT: [f32; 16] = [195363.52, 215159.98, 237836.7, 263676.97, 292950.5, 325880.88, 362594.16, 403031.3, 446804.6, 492956.53, 539545.06, 582898.94, 616177.4, 626234.44, 585120.75, 412481.38];
/// The regulator (k_p N/m, b_p N s/m) an admittance region holds for.
pub const REGULATOR: Option<(f32, f32)> = None;
