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

/// A mechanical network: mass, damping and stiffness matrices (kg, N s/m,
/// N/m), each symmetric positive semidefinite; a hand is one attached at
/// the handle.
struct Network {
    m: DMatrix<f64>,
    d: DMatrix<f64>,
    k: DMatrix<f64>,
}

/// The spectral radius of the loop at `pose` with `hand`, coupling `(k, b)`:
/// the hand's matrices add to the handle's.
fn radius(pose: &PoseDynamics, hand: &Network, (kc, bc): (f64, f64), t: f64) -> f64 {
    let network = Network {
        m: &pose.mass_kg + &hand.m,
        d: &pose.damping_nspm + &hand.d,
        k: hand.k.clone(),
    };
    sampled_radius(&network, pose.q_rad.len(), (kc, bc), t)
}

/// The spectral radius of the sampled loop around a mechanical network
/// `M q'' + D q' + K q = E f` whose first `n` coordinates are the handle's
/// position, where the coupling's force acts: the network and the force
/// held over each tick discretised together, `exp([[A, B], [0, 0]] T)`,
/// and `f_n = -k_c x_n - b_c (x_n - x_{n-1})/T`. The state is
/// `[q, q', x_prev]`.
fn sampled_radius(network: &Network, n: usize, (kc, bc): (f64, f64), t: f64) -> f64 {
    let q = network.m.nrows();
    let minv = network.m.clone().try_inverse().unwrap();
    let mut big = DMatrix::zeros(2 * q + n, 2 * q + n);
    big.view_mut((0, q), (q, q))
        .copy_from(&DMatrix::identity(q, q));
    big.view_mut((q, 0), (q, q))
        .copy_from(&(-&minv * &network.k));
    big.view_mut((q, q), (q, q))
        .copy_from(&(-&minv * &network.d));
    big.view_mut((q, 2 * q), (q, n))
        .copy_from(&minv.columns(0, n));
    let e = expm_balanced(&(big * t)).unwrap();
    let ad = e.view((0, 0), (2 * q, 2 * q)).into_owned();
    let bd = e.view((0, 2 * q), (2 * q, n)).into_owned();
    let mut gain = DMatrix::zeros(n, 2 * q + n);
    for j in 0..n {
        gain[(j, j)] = -(kc + bc / t);
        gain[(j, 2 * q + j)] = bc / t;
    }
    let mut cl = DMatrix::zeros(2 * q + n, 2 * q + n);
    let top = &ad * DMatrix::identity(2 * q, 2 * q + n) + &bd * gain;
    cl.view_mut((0, 0), (2 * q, 2 * q + n)).copy_from(&top);
    for j in 0..n {
        cl[(2 * q + j, j)] = 1.0;
    }
    twoport_design::linalg::eigenvalues(&cl)
        .unwrap()
        .iter()
        .map(|z| z.norm())
        .fold(0.0, f64::max)
}

/// Two nodes joined by `series` (each with `own` to ground): the matrix
/// `[[a + s, -s], [-s, b + s]]` a spring or a damper between them adds.
fn joined(a: &DMatrix<f64>, b: &DMatrix<f64>, series: &DMatrix<f64>) -> DMatrix<f64> {
    let n = a.nrows();
    let mut m = DMatrix::zeros(2 * n, 2 * n);
    m.view_mut((0, 0), (n, n)).copy_from(&(a + series));
    m.view_mut((0, n), (n, n)).copy_from(&(-series));
    m.view_mut((n, 0), (n, n)).copy_from(&(-series));
    m.view_mut((n, n), (n, n)).copy_from(&(b + series));
    m
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
fn holding(x: &[f64], stiffness: f64) -> Network {
    let n = x.len();
    let x = DVector::from_column_slice(x);
    let k = (DMatrix::identity(n, n) - &x * x.transpose()) * stiffness;
    Network {
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
                    let hand = Network {
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
/// handle. The node behind `Z_max` gets 0.1 g in every direction, so that
/// it has dynamics of its own.
fn radius_bounded(
    pose: &PoseDynamics,
    inner: &Network,
    grasp: f64,
    (kc, bc): (f64, f64),
    t: f64,
) -> f64 {
    let n = pose.q_rad.len();
    let bound = twoport_design::network::HumanBound::PAPER;
    let i = DMatrix::<f64>::identity(n, n);
    let zero = DMatrix::zeros(n, n);
    let network = Network {
        m: joined(&pose.mass_kg, &(&inner.m + &i * 1e-4), &zero),
        d: joined(
            &(&pose.damping_nspm + &i * grasp),
            &inner.d,
            &(&i * bound.damping_nspm),
        ),
        k: joined(&zero, &inner.k, &(&i * bound.stiffness_npm)),
    };
    sampled_radius(&network, n, (kc, bc), t)
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
                    let inner = Network {
                        m: psd(n, (-3.0, 0.0), &mut seed),
                        d: psd(n, (-3.0, 3.0), &mut seed),
                        k: psd(n, (0.0, 6.0), &mut seed),
                    };
                    let r = radius_bounded(pose, &inner, grasp, (FACTOR * d.k_c_npm, 0.0), t);
                    assert!(r < 1.0 + 1e-9, "{name}, grasp {grasp}: radius {r}");
                }
            }
            let none = Network {
                m: DMatrix::zeros(n, n),
                d: DMatrix::zeros(n, n),
                k: DMatrix::zeros(n, n),
            };
            let past = radius(
                &d.binding.pose,
                &Network {
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
