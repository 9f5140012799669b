//! Cross builds: the control crates for the M4F, the firmware workspace's
//! QEMU images, and the STM32F405 image's variants.

use crate::toolchain::{Toolchain, TARGET};
use crate::{cross_target_dir, root, run};
use std::path::PathBuf;
use std::process::Command;

pub(crate) fn thumb() -> Result<(), String> {
    let tc = Toolchain::detect()?;
    run(
        &format!(
            "build twoport-control, -link and -board for {TARGET} ({})",
            tc.describe()
        ),
        &mut tc.build(
            &root(),
            &cross_target_dir("thumbv7em-control"),
            &[
                "-p",
                "twoport-control",
                "-p",
                "twoport-link",
                "-p",
                "twoport-board",
            ],
        ),
    )
}

/// Build the firmware workspace; returns the folder holding the ELF files.
pub(crate) fn firmware() -> Result<PathBuf, String> {
    let tc = Toolchain::detect()?;
    let dir = cross_target_dir("firmware");
    run(
        &format!("build firmware: QEMU images ({})", tc.describe()),
        &mut tc.build(&root().join("firmware"), &dir, &[]),
    )?;
    let out = dir.join(TARGET).join("release");
    // With RTT logging first, copied aside, then the plain image last, so
    // that `twoport-stm32f405` is the plain one.
    stm32f405_variant("defmt", "twoport-stm32f405-defmt")?;
    stm32f405_variant("xyz", "twoport-stm32f405-xyz")?;
    run(
        &format!("build firmware: STM32F405 image ({})", tc.describe()),
        &mut tc.build(&root().join("firmware/stm32f405"), &dir, &[]),
    )?;
    // Flash and RAM of each image (text + data in flash; data + bss in RAM).
    let size = Command::new("arm-none-eabi-size")
        .args([
            "twoport-stm32f405",
            "twoport-stm32f405-defmt",
            "twoport-stm32f405-xyz",
            "twoport-an386",
            "twoport-probe",
        ])
        .current_dir(&out)
        .output();
    if let Ok(o) = size {
        eprint!("{}", String::from_utf8_lossy(&o.stdout));
    }
    Ok(out)
}

/// The an386 image built with the passivity layer; returns its ELF. It
/// shares the firmware's target folder, so only the image's own crate is
/// rebuilt (the feature is its alone), and is copied aside, because the
/// next plain build writes the same file.
pub(crate) fn passivity_image() -> Result<PathBuf, String> {
    an386_image_with("passivity")
}

/// The an386 image built with `feature`; returns its ELF, copied aside as
/// `twoport-an386-<feature>`.
pub(crate) fn an386_image_with(feature: &str) -> Result<PathBuf, String> {
    let tc = Toolchain::detect()?;
    let dir = cross_target_dir("firmware");
    run(
        &format!("build firmware: the {feature} image ({})", tc.describe()),
        &mut tc.build(
            &root().join("firmware"),
            &dir,
            &["-p", "twoport-an386", "--features", feature],
        ),
    )?;
    let out = dir.join(TARGET).join("release");
    let elf = out.join(format!("twoport-an386-{feature}"));
    std::fs::copy(out.join("twoport-an386"), &elf)
        .map_err(|e| format!("copy the {feature} image: {e}"))?;
    Ok(elf)
}

/// The STM32F405 image's `qemu` build (three-axis with `xyz`), for QEMU's
/// netduinoplus2; returns its ELF.
pub(crate) fn stm32f405_qemu_image(xyz: bool) -> Result<PathBuf, String> {
    match xyz {
        true => stm32f405_variant("qemu,xyz", "twoport-stm32f405-qemu-xyz"),
        false => stm32f405_variant("qemu", "twoport-stm32f405-qemu"),
    }
}

/// The STM32F405 image built with `features`, its ELF copied aside as
/// `name` (the next build overwrites the plain one); returns that copy.
pub(crate) fn stm32f405_variant(features: &str, name: &str) -> Result<PathBuf, String> {
    let tc = Toolchain::detect()?;
    let dir = cross_target_dir("firmware");
    run(
        &format!(
            "build firmware: the STM32F405 image, {features} ({})",
            tc.describe()
        ),
        &mut tc.build(
            &root().join("firmware/stm32f405"),
            &dir,
            &["--features", features],
        ),
    )?;
    let out = dir.join(TARGET).join("release");
    let elf = out.join(name);
    std::fs::copy(out.join("twoport-stm32f405"), &elf)
        .map_err(|e| format!("copy the {features} image: {e}"))?;
    Ok(elf)
}
