//! A study of `verify` on tight impedance designs: random devices with
//! vibration absorbers, beating modes, flexures, a tick of delay and the
//! human bound, each designed, then searched at the design (where a
//! termination that makes the loop grow would make the proof unsound)
//! and 1% past it (where a tight design must be broken).
//!
//! ```text
//! cargo run --release -p twoport-design --example verify_past -- \
//!     [--seeds 7,11,12,13,14,15] [--count 80] [--out DIR]
//! ```
//!
//! `--out` writes each device `verify` did not break 1% past as a model
//! file, with its design in the last line. `cargo xtask verify-study`
//! runs the defaults, the study `docs/soundness.md` quotes.

use std::collections::BTreeMap;
use std::f64::consts::PI;
use std::fmt::Write as _;
use twoport_control::{Gains, ImpedanceGains};
use twoport_design::network::HumanBound;
use twoport_design::{Designer, DeviceModel};

/// A reproducible stream of uniform numbers (a 64-bit LCG).
struct Stream(u64);

impl Stream {
    fn uniform(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Log-uniform between `lo` and `hi`.
    fn log(&mut self, lo: f64, hi: f64) -> f64 {
        (lo.ln() + self.uniform() * (hi.ln() - lo.ln())).exp()
    }

    fn chance(&mut self, p: f64) -> bool {
        self.uniform() < p
    }
}

/// Masses on a line: ground dampers, and springs with dampers between
/// pairs (`(i, j, k N/m, d N s/m)`).
struct Chain {
    masses_kg: Vec<f64>,
    ground_nspm: Vec<f64>,
    links: Vec<(usize, usize, f64, f64)>,
}

impl Chain {
    fn push(&mut self, at: usize, mass_kg: f64, hz: f64, zeta: f64, ground_nspm: f64) {
        let w = 2.0 * PI * hz;
        self.masses_kg.push(mass_kg);
        self.ground_nspm.push(ground_nspm);
        let i = self.masses_kg.len() - 1;
        self.links
            .push((at, i, mass_kg * w * w, 2.0 * zeta * mass_kg * w));
    }

    /// `M`, `D` and `K` as TOML matrices.
    fn matrices(&self) -> [String; 3] {
        let n = self.masses_kg.len();
        let mut m = vec![vec![0.0; n]; n];
        let mut d = vec![vec![0.0; n]; n];
        let mut k = vec![vec![0.0; n]; n];
        for i in 0..n {
            m[i][i] = self.masses_kg[i];
            d[i][i] = self.ground_nspm[i];
        }
        for &(a, b, kl, dl) in &self.links {
            for (mat, v) in [(&mut k, kl), (&mut d, dl)] {
                mat[a][a] += v;
                mat[b][b] += v;
                mat[a][b] -= v;
                mat[b][a] -= v;
            }
        }
        [m, d, k].map(|a| toml_matrix(&a))
    }
}

fn toml_matrix(a: &[Vec<f64>]) -> String {
    let rows: Vec<String> = a
        .iter()
        .map(|r| {
            let v: Vec<String> = r.iter().map(|x| format!("{x:e}")).collect();
            format!("[{}]", v.join(", "))
        })
        .collect();
    format!("[{}]", rows.join(", "))
}

/// One random device as a model file: a body of 30 g to 1 kg, half the
/// time on a flexure (80 Hz to 3 kHz) to a handle; one absorber of 2 to
/// 30 % (or two that beat, 1 to 20 % apart) at 20 to 300 Hz with damping
/// ratios 1e-4 to 0.1, on the body or the handle; the encoder at either
/// end; a quarter of them one tick late.
fn device(r: &mut Stream) -> String {
    let body_kg = r.log(0.03, 1.0);
    let mut chain = Chain {
        masses_kg: vec![body_kg],
        ground_nspm: vec![r.log(0.1, 20.0)],
        links: Vec::new(),
    };
    let flexure = r.chance(0.5);
    if flexure {
        let (handle_kg, hz, zeta) = (
            body_kg * r.log(0.05, 1.0),
            r.log(80.0, 3000.0),
            r.log(0.005, 0.2),
        );
        let ground = r.log(0.01, 5.0);
        chain.push(0, handle_kg, hz, zeta, ground);
    }
    let carrier = usize::from(flexure && r.chance(0.5));
    let beating = r.chance(0.4);
    let first_hz = r.log(20.0, 300.0);
    let second_hz = beating.then(|| first_hz * (1.0 + r.log(0.01, 0.2)));
    for hz in std::iter::once(first_hz).chain(second_hz) {
        let mass = chain.masses_kg[carrier] * r.log(0.02, 0.3);
        let zeta = r.log(1e-4, 0.1);
        chain.push(carrier, mass, hz, zeta, 0.0);
    }
    let n = chain.masses_kg.len();
    let handle = usize::from(flexure);
    let encoder = usize::from(flexure && r.chance(0.5));
    let mut g = vec![vec![0.0; 2]; n];
    g[handle][0] = 1.0;
    g[0][1] = -1.0;
    let mut c_v = vec![vec![0.0; n]; 2];
    c_v[0][handle] = 1.0;
    c_v[1][encoder] = -1.0;
    let delay = u8::from(r.chance(0.25));
    let [m, d, k] = chain.matrices();
    format!(
        "name = \"study device\"\nperiod_s = 0.001\ndelay_samples = {delay}\n\
         peak_force_n = 100.0\ncontinuous_force_n = 50.0\n\
         M = {m}\nD = {d}\nK = {k}\nG = {}\nC_v = {}\n",
        toml_matrix(&g),
        toml_matrix(&c_v)
    )
}

/// What `verify` did with one design.
#[derive(Default)]
struct Tally {
    designs: usize,
    /// Broken at the design: the proof would be unsound.
    at_design: usize,
    /// Broken 1% past by the search (growth).
    grown: usize,
    /// Broken 1% past by a constructed pole, by the hand's hanging masses.
    constructed: BTreeMap<usize, usize>,
    missed: Vec<String>,
}

struct Options {
    seeds: Vec<u64>,
    count: usize,
    out: Option<std::path::PathBuf>,
}

fn options() -> Result<Options, String> {
    let mut o = Options {
        seeds: vec![7, 11, 12, 13, 14, 15],
        count: 80,
        out: None,
    };
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut it = args.iter();
    while let Some(a) = it.next() {
        let value = it.next().ok_or(format!("{a} needs a value"))?;
        match a.as_str() {
            "--seeds" => {
                o.seeds = value
                    .split(',')
                    .map(|s| s.parse().map_err(|e| format!("--seeds {s}: {e}")))
                    .collect::<Result<_, _>>()?;
            }
            "--count" => o.count = value.parse().map_err(|e| format!("--count {value}: {e}"))?,
            "--out" => o.out = Some(value.into()),
            _ => return Err(format!("unknown argument {a}: --seeds, --count, --out")),
        }
    }
    Ok(o)
}

fn study(seed: u64, count: usize, out: &Option<std::path::PathBuf>, tally: &mut Tally) {
    let mut r = Stream(seed);
    for i in 0..count {
        let text = device(&mut r);
        let human = r.chance(0.5).then_some(HumanBound::PAPER);
        let b = r.chance(0.5).then(|| r.log(0.1, 50.0));
        let model = DeviceModel::from_toml(&text, "study").expect("a study device is valid");
        let d = Designer::new(vec![model], None, human).expect("one pose");
        let Some((k, b)) = d.design_impedance(b, 0.0).ok().and_then(|x| x.coupling) else {
            continue;
        };
        tally.designs += 1;
        let gains = |k: f64| Gains::from(ImpedanceGains::new(k as f32, b as f32));
        let at = d.verify(&gains(k)).expect("verify").verdict;
        let pole_out = at
            .constructed
            .as_ref()
            .is_some_and(|c| c.spectral_radius > 1.0 + 1e-9);
        if at.unstable || pole_out {
            tally.at_design += 1;
            println!("seed {seed} #{i}: broken at the design {k} N/m, b {b}: {at:?}");
        }
        let past = d.verify(&gains(1.01 * k)).expect("verify").verdict;
        let pole = past
            .constructed
            .as_ref()
            .filter(|c| c.spectral_radius >= 1.0 - 1e-9);
        match (past.unstable, pole) {
            (_, Some(c)) => {
                *tally
                    .constructed
                    .entry(c.termination.hand.hanging.len())
                    .or_default() += 1
            }
            (true, None) => tally.grown += 1,
            (false, None) => {
                let line = format!("seed {seed} #{i}: human {} k {k} b {b}", human.is_some());
                if let Some(dir) = out {
                    let path = dir.join(format!("missed_{seed}_{i}.toml"));
                    let _ = std::fs::write(&path, format!("{text}# {line}\n"));
                }
                tally.missed.push(line);
            }
        }
    }
}

fn main() -> std::process::ExitCode {
    let o = match options() {
        Ok(o) => o,
        Err(e) => {
            eprintln!("verify_past: {e}");
            return std::process::ExitCode::FAILURE;
        }
    };
    let mut tally = Tally::default();
    for seed in &o.seeds {
        study(*seed, o.count, &o.out, &mut tally);
    }
    let mut report = String::new();
    let _ = writeln!(report, "designs: {}", tally.designs);
    let _ = writeln!(report, "broken at the design: {}", tally.at_design);
    let _ = writeln!(report, "1% past, grown in the search: {}", tally.grown);
    for (masses, n) in &tally.constructed {
        let _ = writeln!(
            report,
            "1% past, a pole constructed with {masses} hanging masses: {n}"
        );
    }
    let _ = writeln!(report, "1% past, not broken: {}", tally.missed.len());
    for m in &tally.missed {
        let _ = writeln!(report, "  {m}");
    }
    print!("{report}");
    std::process::ExitCode::SUCCESS
}
