//! The linkage proof checked by something independent of it: the exact
//! discrete closed loop of the linearised N-DOF linkage (device and hand
//! discretised together under the zero-order hold, the coupling
//! `k_c + b_c (1 - z^-1)/T` to a bilateral VE), with random passive
//! N-port hands (mass, damper and spring matrices that couple the
//! directions), at the binding pose and at others.

use nalgebra::{DMatrix, DVector};
use twoport_design::linalg::expm_balanced;
use twoport_design::linkage::{workspace_design, workspace_poses, LinkageFile, PoseDynamics};

/// Where the random hands are tried: just inside the design.
const FACTOR: f64 = 0.999;
fn shipped(file: &str) -> LinkageFile {
    let path = format!(
        "{}/../../models/linkages/{file}",
        env!("CARGO_MANIFEST_DIR")
    );
    LinkageFile::load(std::path::Path::new(&path)).unwrap()
}

/// A hand: mass, damping and stiffness matrices (kg, N s/m, N/m), each
/// symmetric positive semidefinite, attached at the handle.
struct Hand {
    m: DMatrix<f64>,
    d: DMatrix<f64>,
    k: DMatrix<f64>,
}

/// The spectral radius of the loop at `pose` with `hand`, coupling `(k, b)`.
fn radius(pose: &PoseDynamics, hand: &Hand, (kc, bc): (f64, f64), t: f64) -> f64 {
    let n = pose.q_rad.len();
    let m = &pose.mass_kg + &hand.m;
    let minv = m.try_inverse().unwrap();
    let d = &pose.damping_nspm + &hand.d;
    // [x; v]' = A [x; v] + B f, then the hold: exp([[A, B], [0, 0]] T).
    let mut big = DMatrix::zeros(3 * n, 3 * n);
    let a_vx = -&minv * &hand.k;
    let a_vv = -&minv * d;
    for i in 0..n {
        big[(i, n + i)] = 1.0;
        for j in 0..n {
            big[(n + i, j)] = a_vx[(i, j)];
            big[(n + i, n + j)] = a_vv[(i, j)];
            big[(n + i, 2 * n + j)] = minv[(i, j)];
        }
    }
    let e = expm_balanced(&(big * t)).unwrap();
    let ad = e.view((0, 0), (2 * n, 2 * n)).into_owned();
    let bd = e.view((0, 2 * n), (2 * n, n)).into_owned();
    // f_n = -k x_n - b (x_n - x_{n-1})/T; the state is [x, v, x_prev].
    let mut cl = DMatrix::zeros(3 * n, 3 * n);
    let mut gain = DMatrix::zeros(n, 3 * n);
    for i in 0..n {
        gain[(i, i)] = -(kc + bc / t);
        gain[(i, 2 * n + i)] = bc / t;
    }
    let top = &ad * DMatrix::identity(2 * n, 3 * n) + &bd * gain;
    cl.view_mut((0, 0), (2 * n, 3 * n)).copy_from(&top);
    for i in 0..n {
        cl[(2 * n + i, i)] = 1.0;
    }
    twoport_design::linalg::eigenvalues(&cl)
        .unwrap()
        .iter()
        .map(|z| z.norm())
        .fold(0.0, f64::max)
}

fn rng(seed: &mut u64) -> f64 {
    *seed ^= *seed << 13;
    *seed ^= *seed >> 7;
    *seed ^= *seed << 17;
    (*seed >> 11) as f64 / (1u64 << 53) as f64
}

/// A random symmetric positive semidefinite matrix of scale 10^(lo..hi).
fn psd(n: usize, (lo, hi): (f64, f64), seed: &mut u64) -> DMatrix<f64> {
    let a = DMatrix::from_fn(n, n, |_, _| rng(seed) - 0.5);
    let scale = 10f64.powf(lo + (hi - lo) * rng(seed));
    &a * a.transpose() * scale
}

/// Hands that hold every direction but `x` stiffly, with nothing along it.
fn holding(x: &[f64], stiffness: f64) -> Hand {
    let n = x.len();
    let x = DVector::from_column_slice(x);
    let k = (DMatrix::identity(n, n) - &x * x.transpose()) * stiffness;
    Hand {
        m: DMatrix::zeros(n, n),
        d: DMatrix::zeros(n, n),
        k,
    }
}

/// At the design (0.1 % inside it) no random passive N-port hand makes the
/// loop grow, at the binding pose and at every tenth pose; 20 % past it
/// the hand that holds every other direction does, at the binding pose.
/// Hands off, and for a 2 N s/m least grasp (the hands' damping then
/// includes it).
#[test]
fn random_n_port_hands_do_not_break_the_workspace_design() {
    let mut seed = 0x0123_4567_89ab_cdefu64;
    for name in [
        "phantom_premium_1_5.toml",
        "falcon_like.toml",
        "haply_2diy.toml",
    ] {
        let l = shipped(name);
        let poses = workspace_poses(&l, 7);
        for grasp in [0.0, 2.0] {
            let d = workspace_design(&l, &poses, 0.0, grasp).unwrap();
            let n = d.binding.direction.len();
            let t = l.period_s;
            let mut checked = 0;
            for pose in std::iter::once(&d.binding.pose).chain(poses.iter().step_by(10)) {
                for _ in 0..20 {
                    let hand = Hand {
                        m: psd(n, (-4.0, 0.0), &mut seed),
                        d: psd(n, (-3.0, 2.0), &mut seed) + DMatrix::identity(n, n) * grasp,
                        k: psd(n, (0.0, 7.0), &mut seed),
                    };
                    let r = radius(pose, &hand, (FACTOR * d.k_c_npm, 0.0), t);
                    assert!(r < 1.0 + 1e-9, "{name}, grasp {grasp}: radius {r}");
                    checked += 1;
                }
            }
            assert!(checked >= 60, "{name}: {checked}");
            let mut hold = holding(&d.binding.direction, 1e6);
            hold.d += DMatrix::identity(n, n) * grasp;
            let past = radius(&d.binding.pose, &hold, (1.2 * d.k_c_npm, 0.0), t);
            assert!(
                past > 1.0 + 1e-10,
                "{name}, grasp {grasp}: 20 % past, radius {past}"
            );
            let at = radius(&d.binding.pose, &hold, (0.999 * d.k_c_npm, 0.0), t);
            assert!(
                at < 1.0,
                "{name}, grasp {grasp}: the holding hand at the design: {at}"
            );
        }
    }
}

/// The spectral radius of the loop at `pose` with a hand bounded by the
/// paper's `Z_max = b_z + k_z/s`: that spring and damper (isotropic) in
/// series with the passive N-port `inner` (mass, damping and stiffness to
/// ground at the node between them), and a grasp damper `grasp` at the
/// handle. State `[x, v, y, w, x_prev]`.
fn radius_bounded(
    pose: &PoseDynamics,
    inner: &Hand,
    grasp: f64,
    (kc, bc): (f64, f64),
    t: f64,
) -> f64 {
    let n = pose.q_rad.len();
    let (bz, kz) = (
        twoport_design::network::HumanBound::PAPER.damping_nspm,
        twoport_design::network::HumanBound::PAPER.stiffness_npm,
    );
    let i = DMatrix::<f64>::identity(n, n);
    let minv = pose.mass_kg.clone().try_inverse().unwrap();
    let mpinv = (&inner.m + &i * 1e-4).try_inverse().unwrap();
    let d = &pose.damping_nspm + &i * grasp;
    // [x, v, y, w]' = A [..] + B f.
    let mut big = DMatrix::zeros(5 * n, 5 * n);
    let mut put = |r: usize, c: usize, m: &DMatrix<f64>| {
        big.view_mut((r * n, c * n), (n, n)).copy_from(m);
    };
    put(0, 1, &i);
    put(1, 0, &(-&minv * kz));
    put(1, 1, &(-&minv * (&d + &i * bz)));
    put(1, 2, &(&minv * kz));
    put(1, 3, &(&minv * bz));
    put(1, 4, &minv);
    put(2, 3, &i);
    put(3, 0, &(&mpinv * kz));
    put(3, 1, &(&mpinv * bz));
    put(3, 2, &(-&mpinv * (&inner.k + &i * kz)));
    put(3, 3, &(-&mpinv * (&inner.d + &i * bz)));
    let e = expm_balanced(&(big * t)).unwrap();
    let ad = e.view((0, 0), (4 * n, 4 * n)).into_owned();
    let bd = e.view((0, 4 * n), (4 * n, n)).into_owned();
    let mut gain = DMatrix::zeros(n, 5 * n);
    for j in 0..n {
        gain[(j, j)] = -(kc + bc / t);
        gain[(j, 4 * n + j)] = bc / t;
    }
    let mut cl = DMatrix::zeros(5 * n, 5 * n);
    let top = &ad * DMatrix::identity(4 * n, 5 * n) + &bd * gain;
    cl.view_mut((0, 0), (4 * n, 5 * n)).copy_from(&top);
    for j in 0..n {
        cl[(4 * n + j, j)] = 1.0;
    }
    twoport_design::linalg::eigenvalues(&cl)
        .unwrap()
        .iter()
        .map(|z| z.norm())
        .fold(0.0, f64::max)
}

/// Under the paper's bound on the grasp: 0.1 % inside the bounded design,
/// no random hand no stiffer than `Z_max` (its spring and damper in series
/// with a random passive N-port) makes the loop grow, at the binding pose
/// and at every tenth pose; 20 % past it, the bare handle does (the hand
/// the bound cannot rule out: none), with or without a 2 N s/m grasp.
#[test]
fn hands_under_the_papers_bound_do_not_break_the_bounded_design() {
    use twoport_design::linkage::bounded_workspace_design;
    let mut seed = 0x0005_eed0_fa11_u64;
    for name in [
        "phantom_premium_1_5.toml",
        "falcon_like.toml",
        "haply_2diy.toml",
        "hapkit.toml",
    ] {
        let l = shipped(name);
        let poses = workspace_poses(&l, 7);
        for grasp in [0.0, 2.0] {
            let d = bounded_workspace_design(
                &l,
                &poses,
                0.0,
                grasp,
                twoport_design::network::HumanBound::PAPER,
            )
            .unwrap();
            let n = d.binding.direction.len();
            let t = l.period_s;
            for pose in std::iter::once(&d.binding.pose).chain(poses.iter().step_by(10)) {
                for _ in 0..10 {
                    let inner = Hand {
                        m: psd(n, (-3.0, 0.0), &mut seed),
                        d: psd(n, (-3.0, 3.0), &mut seed),
                        k: psd(n, (0.0, 6.0), &mut seed),
                    };
                    let r = radius_bounded(pose, &inner, grasp, (FACTOR * d.k_c_npm, 0.0), t);
                    assert!(r < 1.0 + 1e-9, "{name}, grasp {grasp}: radius {r}");
                }
            }
            let none = Hand {
                m: DMatrix::zeros(n, n),
                d: DMatrix::zeros(n, n),
                k: DMatrix::zeros(n, n),
            };
            let past = radius(
                &d.binding.pose,
                &Hand {
                    d: DMatrix::identity(n, n) * grasp,
                    ..none
                },
                (1.2 * d.k_c_npm, 0.0),
                t,
            );
            assert!(
                past > 1.0 + 1e-10,
                "{name}, grasp {grasp}: 20 % past, bare: {past}"
            );
        }
    }
}
