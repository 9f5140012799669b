//! Design a virtual coupling for a device model from Rust, check it, and
//! let `verify` try to break it: `cargo run --example design_coupling
//! [MODEL.toml]` (the capstan handle by default).

use twoport_control::{Gains, ImpedanceGains};
use twoport_design::analysis::{best_impedance, check_impedance, Analysis, GridSpec};
use twoport_design::network::HumanBound;
use twoport_design::verify::verify;
use twoport_design::{DeviceModel, Plant};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args().nth(1).unwrap_or_else(|| {
        concat!(env!("CARGO_MANIFEST_DIR"), "/../../models/capstan.toml").into()
    });
    let model = DeviceModel::load(path.as_ref())?;
    let plant = Plant::new(&model, model.period_s)?;
    let analysis = Analysis::new(&plant, GridSpec::DEFAULT);
    let human = Some(HumanBound::PAPER);
    let bound = analysis.impedance_bound(human);
    let (k, b) = best_impedance(&analysis, &bound).ok_or("no coupling is absolutely stable")?;
    println!("{}: k_c = {k:.0} N/m, b_c = {b:.1} N s/m", model.name);
    let c = check_impedance(&analysis, k, b, human).ok_or("not a coupling")?;
    println!(
        "  least margin {:.4} at {:.1} Hz",
        c.min_margin, c.worst_frequency_hz
    );
    let gains = Gains::from(ImpedanceGains::new(k as f32, b as f32));
    let v = verify(&model, model.period_s, &gains, human)?;
    println!(
        "  verify: worst spectral radius {:.7} ({} loops), unstable: {}",
        v.spectral_radius, v.evaluations, v.unstable
    );
    Ok(())
}
