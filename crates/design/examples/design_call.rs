//! The Rust side of the Python overhead: the work of
//! `twoport.design_impedance(MODEL, b=90.0)` (read the model file, build
//! the designer with the paper's human bound, design at b 90 with a 10%
//! margin), timed as `crates/python/examples/overhead.py` times the
//! Python call: 20 warm-up calls, then the median of 15 runs of 20.
//! `cargo xtask overhead` runs both in turns and gives the ratio.

use std::time::Instant;
use twoport_design::network::HumanBound;
use twoport_design::{Designer, DeviceModel};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args()
        .nth(1)
        .ok_or("usage: design_call MODEL.toml")?;
    let call = || -> Result<(), Box<dyn std::error::Error>> {
        let m = DeviceModel::load(path.as_ref())?;
        let d = Designer::new(vec![m], None, Some(HumanBound::PAPER))?;
        std::hint::black_box(d.design_impedance(Some(90.0), 0.1)?);
        Ok(())
    };
    for _ in 0..20 {
        call()?;
    }
    let mut runs = Vec::with_capacity(15);
    for _ in 0..15 {
        let t = Instant::now();
        for _ in 0..20 {
            call()?;
        }
        runs.push(t.elapsed().as_secs_f64() / 20.0);
    }
    runs.sort_by(f64::total_cmp);
    println!("median_s {:.6e}", runs[runs.len() / 2]);
    Ok(())
}
