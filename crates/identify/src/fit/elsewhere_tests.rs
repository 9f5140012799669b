//! Records twoport did not make: another program's period (4,096
//! samples), every harmonic from 0.5 to 450 Hz at 2 N rms with random
//! phases (most of them moving the handle less than the 1 µm quantum at
//! the top of the band), a chirp swept once a period, and a stepped sine.
//! Each is simulated exactly on the voice-coil handle on its centring
//! spring (`models/bench/centring.toml`), read through its CSV with the
//! excitation named, and fitted: the design within 3% of the truth's.

use super::tests::{base, impedance_k, rng};
use super::*;
use crate::log::{Excitation, Log};
use twoport_design::linalg::expm_balanced;

const T: f64 = 1e-3;

fn centring() -> DeviceModel {
    let path = format!(
        "{}/../../models/bench/centring.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    DeviceModel::load(path.as_ref()).unwrap()
}

/// The encoder's reading (m, quantised to `quantum_m`) of `model` pushed
/// toward `+x` by `force_n`, each held for a sample: the exact sampled
/// motion from rest.
fn simulate(model: &DeviceModel, force_n: &[f64], quantum_m: f64) -> Vec<f64> {
    let n = model.dof();
    let minv = model.m.clone().try_inverse().unwrap();
    let mut a = DMatrix::zeros(2 * n + 1, 2 * n + 1);
    a.view_mut((0, n), (n, n)).fill_with_identity();
    a.view_mut((n, 0), (n, n)).copy_from(&(-&minv * &model.k));
    a.view_mut((n, n), (n, n)).copy_from(&(-&minv * &model.d));
    // The push toward +x is -f_a, G's second column.
    let b = -(&minv * model.g.column(1));
    a.view_mut((n, 2 * n), (n, 1)).copy_from(&b);
    let e = expm_balanced(&(a * T)).unwrap();
    let (ad, bd) = (
        e.view((0, 0), (2 * n, 2 * n)).into_owned(),
        e.view((0, 2 * n), (2 * n, 1)).into_owned(),
    );
    // -x_a is C_v's second row applied to the positions.
    let reading = -model.c_v.row(1).into_owned();
    let mut s = DVector::zeros(2 * n);
    force_n
        .iter()
        .map(|f| {
            let x: f64 = (0..n).map(|j| reading[j] * s[j]).sum();
            s = &ad * &s + &bd * *f;
            (x / quantum_m).round() * quantum_m
        })
        .collect()
}

/// The design at 2 N s/m that the centring handle's record of `force_n`,
/// read through its CSV, gives: within 3% of the truth's.
fn closes(what: &str, force_n: Vec<f64>, excitation: Excitation, skip: usize) {
    let truth = centring();
    let position_m = simulate(&truth, &force_n, 1e-6);
    let log = Log {
        period_s: T,
        force_n,
        position_m,
        load_cell_n: None,
        excitation: Some(excitation),
    };
    let log = Log::from_csv(&log.to_csv(), "elsewhere.csv").unwrap();
    let data = Measured::from_log(&log, skip).unwrap();
    data.band_reaches(T).unwrap();
    let (fits, best) = fit_orders(&data, &base(&truth));
    let f = super::chosen(&fits, best).unwrap();
    let (got, want) = (impedance_k(&f.model, 2.0), impedance_k(&truth, 2.0));
    eprintln!("{what}: {got:.1} N/m against {want:.1}");
    assert!(
        (got / want - 1.0).abs() < 0.03,
        "{what}: {got} against {want}"
    );
}

/// Harmonics `first..=last` of a period of `period_ticks`.
fn periodic(period_ticks: usize, first: usize, last: usize) -> Excitation {
    Excitation::Periodic {
        period_ticks,
        first,
        last,
    }
}

/// 4,096 samples a period, harmonics 2 to 1,843 (0.49 to 450 Hz) at 2 N
/// rms with random phases, eight periods.
#[test]
fn another_programs_multisine_is_read_and_fitted() {
    let (period, first, last) = (4096usize, 2usize, 1843usize);
    let mut seed = 0x5eed_u64;
    let harmonics: Vec<(f64, f64)> = (first..=last)
        .map(|h| {
            (
                h as f64,
                std::f64::consts::PI * 2.0 * (rng(&mut seed) + 0.5),
            )
        })
        .collect();
    let each = 2.0 * (2.0 / harmonics.len() as f64).sqrt();
    let force: Vec<f64> = (0..8 * period)
        .map(|n| {
            harmonics
                .iter()
                .map(|(h, phase)| {
                    each * (TAU * h * (n % period) as f64 / period as f64 + phase).cos()
                })
                .sum()
        })
        .collect();
    closes(
        "random-phase multisine",
        force,
        periodic(period, first, last),
        2,
    );
}

/// A linear chirp from 0.5 to 450 Hz swept once in each 4,096-sample
/// period, 1 N, eight periods.
#[test]
fn a_chirp_swept_once_a_period_is_read_and_fitted() {
    let period = 4096usize;
    let duration = period as f64 * T;
    let (f0, f1) = (0.5, 450.0);
    let force: Vec<f64> = (0..8 * period)
        .map(|n| {
            let t = (n % period) as f64 * T;
            (TAU * (f0 * t + (f1 - f0) * t * t / (2.0 * duration))).sin()
        })
        .collect();
    let (first, last) = (
        (f0 * duration).ceil() as usize,
        (f1 * duration).floor() as usize,
    );
    closes("chirp", force, periodic(period, first, last), 2);
}

/// Forty frequencies from 1 to 450 Hz, log-spaced, each held for 3 s at
/// 1 N.
#[test]
fn a_stepped_sine_is_read_and_fitted() {
    let step = 3000usize;
    let force: Vec<f64> = (0..40)
        .flat_map(|k| {
            let hz = 450f64.powf(k as f64 / 39.0);
            (0..step).map(move |i| (TAU * hz * i as f64 * T).sin())
        })
        .collect();
    closes(
        "stepped sine",
        force,
        Excitation::Stepped { step_ticks: step },
        0,
    );
}
