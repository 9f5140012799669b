//! The linkage images for the PC's loop are their shipped files' devices,
//! and their regions the designer's workspace proof at the PC's latency,
//! rounded down by less than 0.01 %.

use twoport_board::linkage::pc::{PcImage, LATENCY_S};
use twoport_board::linkage::{falcon_pc, haply, touch, GRASP_NSPM};
use twoport_design::linkage::{certified_design_from, least_damping, LinkageFile};

fn file(name: &str) -> LinkageFile {
    let path = format!("{}/../models/linkages/{name}", env!("CARGO_MANIFEST_DIR"));
    LinkageFile::from_toml(&std::fs::read_to_string(&path).unwrap(), &path).unwrap()
}

fn is_the_designers<const N: usize>(image: &PcImage<N>, file: LinkageFile) {
    let name = file.name.clone();
    assert_eq!(file.hardware::<N>().unwrap(), image.spec.hardware, "{name}");
    let least = least_damping(&file).unwrap();
    let claimed = f64::from(image.spec.least_damping_nspm);
    assert!(
        claimed <= least.bound && claimed >= 0.999 * least.bound,
        "{name}"
    );
    let at = LinkageFile {
        period_s: 1e-3,
        latency_s: f64::from(LATENCY_S),
        ..file
    };
    for (b, k) in image.damping_nspm.iter().zip(image.limit_npm) {
        let proof = certified_design_from(&at, &least, f64::from(*b), f64::from(GRASP_NSPM), None)
            .unwrap()
            .k_c_npm;
        let k = f64::from(k);
        assert!(
            k <= proof && k >= proof * (1.0 - 1e-4),
            "{name} at b {b}: {k} vs {proof}"
        );
    }
    let r = image.region().unwrap();
    assert_eq!(r.latency_s(), LATENCY_S);
    let c = image.coupling;
    assert!(c.k_npm <= r.limit_at(c.b_nspm).unwrap(), "{name}");
}

#[test]
fn the_pc_images_are_their_files_and_the_designers() {
    let h = file("haply_2diy.toml");
    match h.geometry {
        twoport_design::linkage::Geometry::Pantograph { l_m, big_l_m, d_m } => {
            let links = haply::HAPLY_LINKS;
            let close = |a: f32, b: f64| (f64::from(a) - b).abs() < 1e-6 * b;
            assert!(close(links.l_m, l_m) && close(links.big_l_m, big_l_m));
            assert!(close(links.d_m, d_m));
        }
        ref g => panic!("the 2DIY's file is {g:?}"),
    }
    is_the_designers(&haply::IMAGE, h);
    // (The delta's geometry is held to its file with the delta image's.)
    is_the_designers(&falcon_pc::IMAGE, file("falcon_like.toml"));
    let t = file("touch.toml");
    match t.geometry {
        twoport_design::linkage::Geometry::SerialArm { l1_m, l2_m } => {
            let arm = touch::TOUCH_ARM;
            let close = |a: f32, b: f64| (f64::from(a) - b).abs() < 1e-6 * b;
            assert!(close(arm.l1_m, l1_m) && close(arm.l2_m, l2_m));
        }
        ref g => panic!("the Touch's file is {g:?}"),
    }
    is_the_designers(&touch::IMAGE, t);
}
