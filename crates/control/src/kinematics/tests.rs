use super::*;
use core::f64::consts::PI;

/// The Haply 2DIY's third hardware revision: l 70 mm, L 90 mm, motors
/// 38 mm apart (as the f32 parameters hold them).
fn haply() -> Pantograph {
    Pantograph::new(0.07, 0.09, 0.038).unwrap()
}
const L: f64 = 0.07f32 as f64;
const BIG_L: f64 = 0.09f32 as f64;
const D: f64 = 0.038f32 as f64;

/// Central differences of `forward`'s position, against its Jacobian.
fn assert_jacobian<K: Kinematics<f64, N>, const N: usize>(k: &K, q: [f64; N]) {
    let j = k.forward(&q).unwrap().jacobian;
    let h = 1e-6;
    for col in 0..N {
        let (mut up, mut down) = (q, q);
        up[col] += h;
        down[col] -= h;
        let (a, b) = (k.forward(&up).unwrap(), k.forward(&down).unwrap());
        for (row, jr) in j.iter().enumerate() {
            let fd = (a.position_m[row] - b.position_m[row]) / (2.0 * h);
            assert!(
                (fd - jr[col]).abs() < 1e-7,
                "J[{row}][{col}] at {q:?}: {} against {fd}",
                jr[col]
            );
        }
    }
}

#[test]
fn the_pantograph_closes_its_loop_and_its_jacobian_is_the_derivative() {
    let k = haply();
    for (a, b) in [(120.0, 60.0), (150.0, 30.0), (100.0, 80.0), (170.0, 90.0)] {
        let q = [a * PI / 180.0, b * PI / 180.0];
        let x = Kinematics::<f64, 2>::forward(&k, &q).unwrap().position_m;
        // Both distal links are L long, and the handle is above the motors.
        for (px, py) in [
            (L * q[0].cos(), L * q[0].sin()),
            (D + L * q[1].cos(), L * q[1].sin()),
        ] {
            let r = ((x[0] - px).powi(2) + (x[1] - py).powi(2)).sqrt();
            assert!((r - BIG_L).abs() < 1e-12, "{q:?}: {r}");
        }
        assert!(x[1] > L * q[0].sin().max(q[1].sin()), "{q:?}: {x:?}");
        assert_jacobian(&k, q);
    }
}

#[test]
fn a_symmetric_pantograph_holds_the_handle_on_its_axis() {
    let k = haply();
    let q = [2.0f64, PI - 2.0];
    let j = Kinematics::<f64, 2>::forward(&k, &q).unwrap();
    assert!((j.position_m[0] - D / 2.0).abs() < 1e-12, "{j:?}");
    // Equal and opposite rates move the handle straight up or down.
    let v = j.velocity_mps(&[1.0, -1.0]);
    assert!(v[0].abs() < 1e-12 && v[1].abs() > 0.01, "{v:?}");
}

#[test]
fn torques_do_the_forces_work() {
    let k = haply();
    let q = [2.2f64, 0.9];
    let j = Kinematics::<f64, 2>::forward(&k, &q).unwrap();
    let (f, rate) = ([1.5, -0.7], [0.3, -1.1]);
    let t = j.torques_nm(&f);
    let v = j.velocity_mps(&rate);
    // Power at the handle equals power at the motors.
    let handle = f[0] * v[0] + f[1] * v[1];
    let motors = t[0] * rate[0] + t[1] * rate[1];
    assert!((handle - motors).abs() < 1e-15, "{handle} vs {motors}");
}

#[test]
fn the_pantograph_faults_where_it_cannot_close_or_hold() {
    let k = haply();
    let f = |q: [f64; 2]| Kinematics::<f64, 2>::forward(&k, &q).map(|_| ());
    // Links folded outward: the distal joints 0.178 m apart, past 2L.
    let wide = Pantograph::new(0.07, 0.08, 0.038).unwrap();
    assert_eq!(
        Kinematics::<f64, 2>::forward(&wide, &[PI, 0.0]).map(|_| ()),
        Err(KinematicsFault::Unreachable)
    );
    // Distal links nearly in line: on a symmetric pose the distal joints
    // are |d - 2 l cos a| apart; put them 2L (1 - 1e-6) apart.
    let wide_at = |a: f64| Kinematics::<f64, 2>::forward(&wide, &[a, PI - a]).map(|_| ());
    let a: f64 = (0.038 - 0.16 * (1.0 - 1e-6)) / 0.14;
    let a = a.acos();
    assert_eq!(wide_at(a), Err(KinematicsFault::Singular));
    assert_eq!(wide_at(a - 0.3), Ok(()));
    assert_eq!(f([f64::NAN, 0.2]), Err(KinematicsFault::NotFinite));
    assert_eq!(f([2.0, 1.0]), Ok(()));
    // f32, as on the board, at an ordinary pose.
    let j = Kinematics::<f32, 2>::forward(&k, &[2.0, 1.0]).unwrap();
    assert!(j.position_m[1] > 0.1, "{j:?}");
}

#[test]
fn the_capstan_scales_by_its_radii() {
    // The Stanford Hapkit: r_h 89 mm, r_p 5 mm, r_s 74 mm.
    let k = Capstan::new(0.089, 0.005, 0.074).unwrap();
    let r = f64::from(0.089f32 * 0.005f32 / 0.074f32);
    assert!((r - 0.089 * 0.005 / 0.074).abs() < 1e-9);
    let j = Kinematics::<f64, 1>::forward(&k, &[2.0]).unwrap();
    assert!((j.position_m[0] - 2.0 * r).abs() < 1e-9);
    assert!((j.torques_nm(&[3.0])[0] - 3.0 * r).abs() < 1e-9);
    assert_jacobian(&k, [0.4]);
    let e = Capstan::new(0.089, 0.0, 0.074).unwrap_err();
    assert_eq!(e.name, "kinematics.r_p_m (m)");
}

#[test]
fn a_cartesian_device_is_the_identity() {
    let j = Kinematics::<f64, 3>::forward(&Cartesian, &[0.1, -0.2, 0.3]).unwrap();
    assert_eq!(j.position_m, [0.1, -0.2, 0.3]);
    assert_eq!(j.torques_nm(&[1.0, 2.0, 3.0]), [1.0, 2.0, 3.0]);
}

/// The PHANToM Premium 1.5's links: l1 215 mm, l2 170 mm.
fn phantom() -> SerialArm {
    SerialArm::new(0.215, 0.17).unwrap()
}

#[test]
fn the_serial_arm_is_its_published_forward_map_and_its_derivative() {
    let k = phantom();
    let (l1, l2) = (0.215f32 as f64, 0.17f32 as f64);
    for q in [
        [0.0, 0.0, 0.0],
        [0.3, 0.2, 0.5],
        [-0.8, 0.6, 1.2],
        [1.2, -0.4, 0.1],
    ] {
        let j = Kinematics::<f64, 3>::forward(&k, &q).unwrap();
        let reach = l1 * q[1].cos() + l2 * q[2].sin();
        let x = [
            q[0].cos() * reach,
            q[0].sin() * reach,
            l1 * q[1].sin() - l2 * q[2].cos(),
        ];
        for (got, want) in j.position_m.iter().zip(x) {
            assert!((got - want).abs() < 1e-12, "{q:?}");
        }
        assert_jacobian(&k, q);
    }
}

#[test]
fn the_serial_arm_faults_on_its_axis_and_with_its_links_folded() {
    let k = phantom();
    let f = |q: [f64; 3]| Kinematics::<f64, 3>::forward(&k, &q).map(|_| ());
    // The handle on the base's axis: l1 cos q2 + l2 sin q3 = 0.
    let q3 = -(0.215f64 * 1.2f64.cos() / 0.17).asin();
    assert_eq!(f([0.3, 1.2, q3]), Err(KinematicsFault::Singular));
    // The forearm along the upper arm: cos(q2 - q3) = 0.
    let q2 = 0.2;
    assert_eq!(
        f([0.3, q2, q2 + core::f64::consts::FRAC_PI_2]),
        Err(KinematicsFault::Singular)
    );
    assert_eq!(f([0.3, q2, q2 + 1.0]), Ok(()));
}

/// A delta of about the Falcon's size: base 40 mm, effector 20 mm, upper
/// arms 60 mm, parallelograms 102.5 mm.
fn delta() -> Delta {
    Delta::new(0.04, 0.02, 0.06, 0.1025).unwrap()
}

#[test]
fn the_delta_closes_every_leg_and_its_jacobian_is_the_derivative() {
    let k = delta();
    let (r, a, b) = ((0.04f32 - 0.02f32) as f64, 0.06f32 as f64, 0.1025f32 as f64);
    for q in [
        [0.5, 0.5, 0.5],
        [0.2, 0.6, 0.4],
        [0.9, 0.3, 0.1],
        [-0.2, 0.4, 0.7],
    ] {
        let j = Kinematics::<f64, 3>::forward(&k, &q).unwrap();
        let p = j.position_m;
        assert!(p[2] < 0.0, "{q:?}: {p:?}");
        for (i, phi) in [0.0f64, 120.0, 240.0].iter().enumerate() {
            let (c, s) = (phi.to_radians().cos(), phi.to_radians().sin());
            let radial = r + a * q[i].cos();
            let e = [c * radial, s * radial, -a * q[i].sin()];
            let len =
                ((p[0] - e[0]).powi(2) + (p[1] - e[1]).powi(2) + (p[2] - e[2]).powi(2)).sqrt();
            assert!((len - b).abs() < 1e-9, "{q:?} leg {i}: {len}");
        }
        assert_jacobian(&k, q);
    }
    // Equal angles: the effector on the axis.
    let p = Kinematics::<f64, 3>::forward(&k, &[0.4, 0.4, 0.4])
        .unwrap()
        .position_m;
    assert!(p[0].abs() < 1e-6 && p[1].abs() < 1e-6, "{p:?}");
    // f32, as on the board.
    let j32 = Kinematics::<f32, 3>::forward(&k, &[0.5, 0.5, 0.5]).unwrap();
    let j64 = Kinematics::<f64, 3>::forward(&k, &[0.5, 0.5, 0.5]).unwrap();
    for i in 0..3 {
        let err = (f64::from(j32.position_m[i]) - j64.position_m[i]).abs();
        assert!(err < 2e-7, "axis {i}: {err}");
    }
}

#[test]
fn the_delta_faults_where_its_legs_cannot_meet() {
    let k = delta();
    let f = |q: [f64; 3]| Kinematics::<f64, 3>::forward(&k, &q).map(|_| ());
    // Short parallelograms on level arms: the elbows 139 mm apart, more
    // than two parallelograms reach.
    let short = Delta::new(0.04, 0.02, 0.06, 0.03).unwrap();
    let at = Kinematics::<f64, 3>::forward(&short, &[0.0, 0.0, 0.0]).map(|_| ());
    assert_eq!(at, Err(KinematicsFault::Unreachable));
    assert_eq!(f([0.5, 0.5, 0.5]), Ok(()));
    assert_eq!(
        f([f64::INFINITY, 0.4, 0.4]),
        Err(KinematicsFault::NotFinite)
    );
    assert_eq!(
        Delta::new(0.04, 0.02, 0.0, 0.1).unwrap_err().name,
        "kinematics.upper_m (m)"
    );
}
