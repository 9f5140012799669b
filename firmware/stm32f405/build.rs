//! Put memory.x where cortex-m-rt's link.x finds it.
use std::{env, fs, path::PathBuf};

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    fs::copy("memory.x", out.join("memory.x")).expect("copy memory.x to OUT_DIR");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed=memory.x");
    // defmt's linker script, only where its feature is on.
    if env::var_os("CARGO_FEATURE_DEFMT").is_some() {
        if env::var_os("CARGO_FEATURE_QEMU").is_some() {
            panic!("the defmt feature is for the hardware image: QEMU builds log by semihosting");
        }
        println!("cargo:rustc-link-arg=-Tdefmt.x");
    }
}
