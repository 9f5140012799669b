//! Any text as a device model: a clear error or a model the designer can
//! prepare, never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;
use twoport_design::{DeviceModel, Plant};

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(model) = DeviceModel::from_toml(text, "fuzz") {
        if model.dof() <= 8 {
            let _ = Plant::new(&model, model.period_s);
        }
    }
});
