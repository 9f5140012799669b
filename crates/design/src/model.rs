//! Device models: the linear lumped-mass description of a haptic device
//! (paper eqs 3-8), read from TOML and checked before any analysis.

use nalgebra::{DMatrix, SymmetricEigen};
use serde::Deserialize;
use std::fmt;
use std::path::Path;

mod lag;

pub use lag::Lag;

/// A linear device model `M q'' + D q' + K q = G [f_h, f_a]^T`, with
/// `[v_h, -v_a]^T = C_v q'`, strain gauge `f_s = C_f q` and load-cell filter
/// `a(s) = p/(s + p)`. SI units: kg, N s/m, N/m, N, m/s, rad/s, s.
#[derive(Clone, Debug, PartialEq)]
pub struct DeviceModel {
    /// A human-readable name.
    pub name: String,
    /// Sample period `T` of the controller (s).
    pub period_s: f64,
    /// Load-cell filter pole `p` (rad/s); 235 where the device has no
    /// force sensor (unused then).
    pub load_cell_pole_rad_s: f64,
    /// Actuator peak force (N).
    pub peak_force_n: f64,
    /// Actuator continuous force (N).
    pub continuous_force_n: f64,
    /// Mass matrix `M` (n x n, kg), symmetric positive definite.
    pub m: DMatrix<f64>,
    /// Damping matrix `D` (n x n, N s/m), symmetric positive semidefinite.
    pub d: DMatrix<f64>,
    /// Stiffness matrix `K` (n x n, N/m), symmetric positive semidefinite.
    pub k: DMatrix<f64>,
    /// Input matrix `G` (n x 2): columns for `f_h` and `f_a`.
    pub g: DMatrix<f64>,
    /// Velocity output matrix `C_v` (2 x n): rows `v_h` and `-v_a`.
    pub c_v: DMatrix<f64>,
    /// Strain-gauge output matrix `C_f` (1 x n, N/m); zeros where the
    /// device has no force sensor.
    pub c_f: DMatrix<f64>,
    /// Whether the device has a force sensor (`C_f` given). Without one an
    /// admittance display cannot be built.
    pub force_sensor: bool,
    /// Measurement-to-actuation delay in whole ticks (0: the force is held
    /// from the tick that sampled the sensors).
    pub delay_samples: u32,
    /// Latency from sampling the sensors to the force's change (s), on top
    /// of `delay_samples`: the servo's own computation, a bus transfer.
    /// The force changes at `τ` after each tick's sample, inside the tick
    /// or later ([`lag`](Self::lag) splits it at a period).
    pub latency_s: f64,
    /// The actuator encoder's quantum `Δ` (m at the actuator), if known.
    pub encoder_quantum_m: Option<f64>,
    /// The Coulomb friction at the actuator `f_c` (N), if known.
    pub coulomb_friction_n: Option<f64>,
}

/// Why a model file was refused. The message names the file, and the line
/// or the field and the problem.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelError {
    /// The file (or `<input>`).
    pub source: String,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for ModelError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.source, self.message)
    }
}

impl std::error::Error for ModelError {}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawModel {
    name: Option<String>,
    period_s: f64,
    load_cell_pole_rad_s: Option<f64>,
    peak_force_n: f64,
    continuous_force_n: f64,
    #[serde(rename = "M")]
    m: Vec<Vec<f64>>,
    #[serde(rename = "D")]
    d: Vec<Vec<f64>>,
    #[serde(rename = "K")]
    k: Vec<Vec<f64>>,
    #[serde(rename = "G")]
    g: Vec<Vec<f64>>,
    #[serde(rename = "C_v")]
    c_v: Vec<Vec<f64>>,
    #[serde(rename = "C_f")]
    c_f: Option<Vec<Vec<f64>>>,
    delay_samples: Option<u32>,
    latency_s: Option<f64>,
    encoder_quantum_m: Option<f64>,
    coulomb_friction_n: Option<f64>,
}

/// A file's text and its name for messages.
pub(crate) fn read(path: &Path) -> Result<(String, String), ModelError> {
    let source = path.display().to_string();
    match std::fs::read_to_string(path) {
        Ok(text) => Ok((text, source)),
        Err(e) => Err(ModelError {
            source,
            message: format!("cannot read: {e}"),
        }),
    }
}

/// `text` parsed as TOML into `T`; an error names `source` and the line.
pub(crate) fn parse<T: serde::de::DeserializeOwned>(
    text: &str,
    source: &str,
) -> Result<T, ModelError> {
    toml::from_str(text).map_err(|e| {
        let at = e
            .span()
            .map(|s| {
                let line = text[..s.start.min(text.len())].matches('\n').count() + 1;
                format!("line {line}: ")
            })
            .unwrap_or_default();
        ModelError {
            source: source.to_string(),
            message: format!("{at}{}", e.message()),
        }
    })
}

/// The filter pole a model without a force sensor is given (rad/s).
pub const DEFAULT_LOAD_CELL_POLE_RAD_S: f64 = 235.0;

/// The longest measurement-to-actuation delay a model may declare (ticks).
pub const MAX_DELAY_SAMPLES: u32 = 64;

/// The longest latency a model may declare (s).
pub const MAX_LATENCY_S: f64 = 1.0;

/// Where the paper's Excalibur model lives in this repository.
pub const EXCALIBUR_PATH: &str = "models/excalibur.toml";

/// The same model built into the tools, for a run outside the repository.
const EXCALIBUR_TOML: &str = include_str!("../../../models/excalibur.toml");

impl DeviceModel {
    /// The paper's Excalibur model (the copy built into the tools).
    pub fn excalibur() -> Result<Self, ModelError> {
        Self::from_toml(EXCALIBUR_TOML, "built-in excalibur.toml")
    }

    /// Read and check `path`; the default path [`EXCALIBUR_PATH`], when the
    /// file is not there (a tool run outside the repository), gives the
    /// built-in Excalibur model.
    pub fn load_or_excalibur(path: &Path) -> Result<Self, ModelError> {
        if path == Path::new(EXCALIBUR_PATH) && !path.exists() {
            Self::excalibur()
        } else {
            Self::load(path)
        }
    }

    /// Read and check a model file.
    pub fn load(path: &Path) -> Result<Self, ModelError> {
        let (text, source) = read(path)?;
        Self::from_toml(&text, &source)
    }

    /// Parse and check model text; `source` names it in errors.
    ///
    /// # Examples
    ///
    /// ```
    /// use twoport_design::DeviceModel;
    /// let rigid = "period_s = 0.001\npeak_force_n = 10.0\ncontinuous_force_n = 4.0\n\
    ///              M = [[0.25]]\nD = [[2.0]]\nK = [[0.0]]\nG = [[1.0, -1.0]]\nC_v = [[1.0], [-1.0]]\n";
    /// let m = DeviceModel::from_toml(rigid, "capstan.toml")?;
    /// assert!(!m.force_sensor); // no C_f: no load cell
    /// let bad = DeviceModel::from_toml(&rigid.replace("0.25", "-0.25"), "capstan.toml");
    /// assert!(bad.unwrap_err().to_string().contains("M is not positive definite"));
    /// # Ok::<(), twoport_design::ModelError>(())
    /// ```
    pub fn from_toml(text: &str, source: &str) -> Result<Self, ModelError> {
        let err = |message: String| ModelError {
            source: source.to_string(),
            message,
        };
        let raw: RawModel = parse(text, source)?;
        let n = raw.m.len();
        if n == 0 {
            return Err(err(
                "M is empty: the model needs at least one coordinate".into()
            ));
        }
        let pole = match (&raw.c_f, raw.load_cell_pole_rad_s) {
            (Some(_), None) => {
                return Err(err(
                    "C_f is given but load_cell_pole_rad_s is not: a force sensor needs its filter pole"
                        .into(),
                ))
            }
            (_, Some(p)) => scalar("load_cell_pole_rad_s", p).map_err(&err)?,
            (None, None) => DEFAULT_LOAD_CELL_POLE_RAD_S,
        };
        let c_f = match &raw.c_f {
            Some(rows) => matrix("C_f", rows, 1, n, n).map_err(&err)?,
            None => DMatrix::zeros(1, n),
        };
        let model = DeviceModel {
            name: raw.name.unwrap_or_else(|| source.to_string()),
            period_s: scalar("period_s", raw.period_s).map_err(&err)?,
            load_cell_pole_rad_s: pole,
            peak_force_n: scalar("peak_force_n", raw.peak_force_n).map_err(&err)?,
            continuous_force_n: scalar("continuous_force_n", raw.continuous_force_n)
                .map_err(&err)?,
            m: matrix("M", &raw.m, n, n, n).map_err(&err)?,
            d: matrix("D", &raw.d, n, n, n).map_err(&err)?,
            k: matrix("K", &raw.k, n, n, n).map_err(&err)?,
            g: matrix("G", &raw.g, n, 2, n).map_err(&err)?,
            c_v: matrix("C_v", &raw.c_v, 2, n, n).map_err(&err)?,
            c_f,
            force_sensor: raw.c_f.is_some(),
            delay_samples: match raw.delay_samples {
                Some(d) if d > MAX_DELAY_SAMPLES => {
                    return Err(err(format!(
                        "delay_samples = {d}: at most {MAX_DELAY_SAMPLES} ticks"
                    )))
                }
                d => d.unwrap_or(0),
            },
            latency_s: match raw.latency_s {
                None => 0.0,
                Some(l) if l.is_finite() && (0.0..=MAX_LATENCY_S).contains(&l) => l,
                Some(l) => {
                    return Err(err(format!(
                        "latency_s = {l}: must be a time from 0 to {MAX_LATENCY_S} s"
                    )))
                }
            },
            encoder_quantum_m: raw
                .encoder_quantum_m
                .map(|v| scalar("encoder_quantum_m", v))
                .transpose()
                .map_err(&err)?,
            coulomb_friction_n: raw
                .coulomb_friction_n
                .map(|v| crate::field::non_negative("coulomb_friction_n", v))
                .transpose()
                .map_err(&err)?,
        };
        model.check().map_err(err)?;
        Ok(model)
    }

    /// The model as model-file text that [`from_toml`](Self::from_toml)
    /// reads back to the same model (every number in Rust's shortest
    /// round-trip form), after the comment lines `header`.
    pub fn to_toml(&self, header: &str) -> String {
        use std::fmt::Write;
        let mut out = String::new();
        for line in header.lines() {
            let _ = writeln!(out, "# {line}");
        }
        let rows = |a: &DMatrix<f64>| -> String {
            let body: Vec<String> = (0..a.nrows())
                .map(|i| {
                    let row: Vec<String> =
                        (0..a.ncols()).map(|j| format!("{:?}", a[(i, j)])).collect();
                    format!("  [{}],", row.join(", "))
                })
                .collect();
            format!("[\n{}\n]", body.join("\n"))
        };
        let _ = writeln!(out, "name = {:?}", self.name);
        let _ = writeln!(out, "period_s = {:?}", self.period_s);
        if self.force_sensor {
            let _ = writeln!(
                out,
                "load_cell_pole_rad_s = {:?}",
                self.load_cell_pole_rad_s
            );
        }
        let _ = writeln!(out, "peak_force_n = {:?}", self.peak_force_n);
        let _ = writeln!(out, "continuous_force_n = {:?}", self.continuous_force_n);
        if self.delay_samples > 0 {
            let _ = writeln!(out, "delay_samples = {}", self.delay_samples);
        }
        if self.latency_s > 0.0 {
            let _ = writeln!(out, "latency_s = {:?}", self.latency_s);
        }
        if let Some(q) = self.encoder_quantum_m {
            let _ = writeln!(out, "encoder_quantum_m = {q:?}");
        }
        if let Some(c) = self.coulomb_friction_n {
            let _ = writeln!(out, "coulomb_friction_n = {c:?}");
        }
        for (name, a) in [
            ("M", &self.m),
            ("D", &self.d),
            ("K", &self.k),
            ("G", &self.g),
            ("C_v", &self.c_v),
        ] {
            let _ = writeln!(out, "\n{name} = {}", rows(a));
        }
        if self.force_sensor {
            let _ = writeln!(out, "\nC_f = {}", rows(&self.c_f));
        }
        out
    }

    /// The device with a rigid mass of `kg` clamped on its handle: `M +
    /// kg g gᵀ`, `g` the handle force's column of `G`. What a bench adds
    /// when it loads the handle with a known mass to see the handle's side
    /// of the device from the actuator. Refused, with the reason, for a
    /// mass that is not finite and positive, or a handle whose velocity
    /// output (`C_v`'s first row) is not its force's column (a mass there
    /// would not be where the handle is read).
    pub fn with_handle_mass(&self, kg: f64) -> Result<DeviceModel, ModelError> {
        let err = |message: String| ModelError {
            source: self.name.clone(),
            message,
        };
        if !(kg.is_finite() && kg > 0.0) {
            return Err(err(format!(
                "the handle's added mass {kg} kg must be finite and positive"
            )));
        }
        let g = self.g.column(0).into_owned();
        let v = self.c_v.row(0).transpose();
        if (&g - &v).amax() > 1e-12 * g.amax().max(1.0) {
            return Err(err(
                "the handle's velocity (C_v's first row) is not where its force enters \
                 (G's first column): a mass cannot be clamped there"
                    .into(),
            ));
        }
        let mut loaded = self.clone();
        loaded.m += &g * g.transpose() * kg;
        Ok(loaded)
    }

    /// The delay at sample period `period_s` (s): `delay_samples` and the
    /// latency's whole ticks, and what is left of it as a fraction of a
    /// tick ([`Lag::of`]).
    pub fn lag(&self, period_s: f64) -> Lag {
        let l = Lag::of(self.latency_s, period_s);
        Lag {
            ticks: self.delay_samples + l.ticks,
            ..l
        }
    }

    /// Number of coordinates `n`.
    pub fn dof(&self) -> usize {
        self.m.nrows()
    }

    /// The encoder quantum and Coulomb friction, where the model gives
    /// both (a missing friction is none).
    pub fn friction(&self) -> Option<crate::limit_cycle::Friction> {
        let rigid =
            self.dof() == 1 && self.k[(0, 0)] == 0.0 && self.lag(self.period_s) == Lag::NONE;
        self.encoder_quantum_m
            .map(|q| crate::limit_cycle::Friction {
                encoder_quantum_m: q,
                coulomb_friction_n: self.coulomb_friction_n.unwrap_or(0.0),
                rigid_damping_nspm: rigid.then(|| self.d[(0, 0)]),
            })
    }

    /// The physical checks: symmetry, definiteness, limits.
    fn check(&self) -> Result<(), String> {
        if self.continuous_force_n > self.peak_force_n {
            return Err(format!(
                "continuous_force_n = {} exceeds peak_force_n = {}",
                self.continuous_force_n, self.peak_force_n
            ));
        }
        for (name, a) in [("M", &self.m), ("D", &self.d), ("K", &self.k)] {
            symmetric(name, a)?;
        }
        if self.m.clone().cholesky().is_none() {
            let low = SymmetricEigen::new(self.m.clone()).eigenvalues.min();
            return Err(format!(
                "M is not positive definite: smallest eigenvalue {low:e} kg"
            ));
        }
        semidefinite("D", &self.d, "N s/m")?;
        semidefinite("K", &self.k, "N/m")?;
        Ok(())
    }
}

use crate::field::positive as scalar;

/// `name` as an `r x c` matrix; `n` is the model's coordinate count (from
/// `M`), named in the error.
fn matrix(
    name: &str,
    rows: &[Vec<f64>],
    r: usize,
    c: usize,
    n: usize,
) -> Result<DMatrix<f64>, String> {
    if rows.len() != r {
        return Err(format!(
            "{name} must be {r} x {c} (n = {n} from M), but has {} rows",
            rows.len()
        ));
    }
    for (i, row) in rows.iter().enumerate() {
        if row.len() != c {
            return Err(format!(
                "{name} must be {r} x {c}, but row {i} has {} entries",
                row.len()
            ));
        }
        for (j, v) in row.iter().enumerate() {
            if !v.is_finite() {
                return Err(format!("{name}[{i}][{j}] = {v} is not finite"));
            }
        }
    }
    Ok(DMatrix::from_fn(r, c, |i, j| rows[i][j]))
}

fn symmetric(name: &str, a: &DMatrix<f64>) -> Result<(), String> {
    for i in 0..a.nrows() {
        for j in i + 1..a.ncols() {
            let (x, y) = (a[(i, j)], a[(j, i)]);
            if (x - y).abs() > 1e-12 * x.abs().max(y.abs()) {
                return Err(format!(
                    "{name} is not symmetric: {name}[{i}][{j}] = {x} but {name}[{j}][{i}] = {y}"
                ));
            }
        }
    }
    Ok(())
}

/// Positive semidefinite up to the rounding of the printed digits: an
/// eigenvalue below `-1e-6` times the largest is a real negative one.
fn semidefinite(name: &str, a: &DMatrix<f64>, unit: &str) -> Result<(), String> {
    let e = SymmetricEigen::new(a.clone()).eigenvalues;
    let (low, high) = (e.min(), e.max().abs().max(f64::MIN_POSITIVE));
    if low < -1e-6 * high {
        return Err(format!(
            "{name} is not positive semidefinite: eigenvalue {low:e} {unit} (largest {high:e})"
        ));
    }
    Ok(())
}

/// A rigid one-coordinate device of mass `m` (kg) and damping `b` (N s/m),
/// handle at the actuator, no force sensor, at 1 kHz: the device the
/// design crate's unit tests check closed forms on.
#[cfg(test)]
pub(crate) fn rigid_for_tests(m: f64, b: f64) -> DeviceModel {
    DeviceModel::from_toml(
        &format!(
            "period_s = 0.001\npeak_force_n = 50.0\ncontinuous_force_n = 20.0\n\
             M = [[{m}]]\nD = [[{b}]]\nK = [[0.0]]\nG = [[1.0, -1.0]]\nC_v = [[1.0], [-1.0]]\n"
        ),
        "rigid",
    )
    .expect("a valid rigid model")
}

/// The shipped one-axis models (`models/*.toml`), for the design crate's
/// unit tests that must hold on every device the project ships.
#[cfg(test)]
pub(crate) fn shipped_for_tests() -> Vec<DeviceModel> {
    [
        include_str!("../../../models/excalibur.toml"),
        include_str!("../../../models/capstan.toml"),
        include_str!("../../../models/two_mass.toml"),
    ]
    .into_iter()
    .map(|text| DeviceModel::from_toml(text, "shipped model").expect("a shipped model is valid"))
    .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    const EXCALIBUR: &str = include_str!("../../../models/excalibur.toml");

    /// Every shipped model written out reads back to itself.
    #[test]
    fn a_written_model_reads_back_the_same() {
        for m in shipped_for_tests() {
            let back = DeviceModel::from_toml(&m.to_toml("written\nback"), "written").unwrap();
            assert_eq!(back, m);
        }
    }

    /// A mass on the handle adds to the handle's coordinate alone: the
    /// whole device weighs that much more (its rigid-body mass seen through
    /// `G`'s handle column), and a handle not read where it is pushed, or a
    /// mass that is no mass, is refused.
    #[test]
    fn a_mass_clamps_on_the_handle() {
        let m = DeviceModel::from_toml(EXCALIBUR, "excalibur.toml").unwrap();
        let loaded = m.with_handle_mass(0.5).unwrap();
        let diff = &loaded.m - &m.m;
        assert!((diff[(4, 4)] - 0.5).abs() < 1e-15);
        assert_eq!(diff.abs().sum(), diff[(4, 4)]);
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let e = m.with_handle_mass(bad).unwrap_err().to_string();
            assert!(e.contains("finite and positive"), "{e}");
        }
        let mut apart = m.clone();
        apart.c_v[(0, 4)] = 0.0;
        apart.c_v[(0, 3)] = 1.0;
        let e = apart.with_handle_mass(0.5).unwrap_err().to_string();
        assert!(e.contains("not where its force enters"), "{e}");
    }

    #[test]
    fn excalibur_loads() {
        let m = DeviceModel::from_toml(EXCALIBUR, "excalibur.toml").unwrap();
        assert_eq!(m.dof(), 5);
        assert_eq!(m.m[(2, 3)], 0.2799);
        assert_eq!(m.k[(2, 2)], 5.3954e7);
        assert_eq!(m.c_f[(0, 4)], 5.3236e7);
    }

    #[test]
    fn the_encoder_and_friction_are_optional_and_checked() {
        let m = DeviceModel::from_toml(EXCALIBUR, "x.toml").unwrap();
        assert_eq!(m.friction(), None);
        let with = |extra: &str| DeviceModel::from_toml(&format!("{extra}\n{EXCALIBUR}"), "x.toml");
        let f = with("encoder_quantum_m = 1e-6")
            .unwrap()
            .friction()
            .unwrap();
        assert_eq!((f.encoder_quantum_m, f.coulomb_friction_n), (1e-6, 0.0));
        // Five coordinates: not one rigid body.
        assert_eq!(f.rigid_damping_nspm, None);
        let e = with("encoder_quantum_m = 0.0").unwrap_err().to_string();
        assert_eq!(e, "x.toml: encoder_quantum_m = 0 must be finite and > 0");
        let e = with("encoder_quantum_m = 1e-6\ncoulomb_friction_n = -1.0")
            .unwrap_err()
            .to_string();
        assert_eq!(e, "x.toml: coulomb_friction_n = -1 must be finite and >= 0");
    }

    fn broken(from: &str, to: &str) -> String {
        assert!(EXCALIBUR.contains(from), "{from}");
        DeviceModel::from_toml(&EXCALIBUR.replacen(from, to, 1), "x.toml")
            .unwrap_err()
            .to_string()
    }

    #[test]
    fn errors_name_the_field_and_the_problem() {
        assert_eq!(
            broken(
                "[0.0,    0.0,    0.2799, 0.3343",
                "[0.0,    0.0,    0.28, 0.3343"
            ),
            "x.toml: M is not symmetric: M[2][3] = 0.2799 but M[3][2] = 0.28"
        );
        assert!(broken("0.9271", "-0.9271").contains("M is not positive definite"));
        assert!(broken("5.3236e7, 5.3236e7]", "5.3236e7]")
            .contains("C_f must be 1 x 5, but row 0 has 4 entries"));
        assert!(broken("period_s = 0.001", "period_s = -1")
            .contains("period_s = -1 must be finite and > 0"));
        assert!(broken("[ 8.5600,", "[ -80.5600,").contains("D is not positive semidefinite"));
        assert!(broken("period_s = 0.001", "period_s = nan").contains("period_s = NaN"));
        let e = broken("C_v = [", "C_w = [");
        assert!(e.contains("line ") && e.contains("C_w"), "{e}");
        let e = broken(
            "load_cell_pole_rad_s = 235.0",
            "load_cell_pole_rad_s = \"fast\"",
        );
        let line = EXCALIBUR
            .lines()
            .position(|l| l.starts_with("load_cell_pole_rad_s"))
            .unwrap()
            + 1;
        assert!(e.contains(&format!("line {line}: invalid type")), "{e}");
        let e = broken("C_f = [", "delay_samples = -1\nC_f = [");
        assert!(
            e.contains("delay_samples") || e.contains("invalid value"),
            "{e}"
        );
        assert!(broken("C_f = [", "delay_samples = 65\nC_f = [").contains("at most 64"));
        let e = broken("load_cell_pole_rad_s = 235.0\n", "");
        assert!(e.contains("needs its filter pole"), "{e}");
    }

    /// `latency_s` is read, checked, written back, and split at a period
    /// into whole ticks (on top of `delay_samples`) and a fraction, a
    /// period's rounding never leaving `0.999...` of a tick.
    #[test]
    fn a_latency_is_read_and_split_at_a_period() {
        let rigid = "period_s = 0.001\npeak_force_n = 5.0\ncontinuous_force_n = 2.0\n\
                     M = [[0.01]]\nD = [[0.5]]\nK = [[0.0]]\nG = [[1.0, -1.0]]\n\
                     C_v = [[1.0], [-1.0]]\n";
        let with = |l: &str| DeviceModel::from_toml(&format!("{rigid}latency_s = {l}\n"), "r");
        let m = with("2.5e-4").unwrap();
        assert_eq!(m.latency_s, 2.5e-4);
        assert_eq!(
            m.lag(1e-3),
            Lag {
                ticks: 0,
                fraction: 0.25
            }
        );
        assert_eq!(m.lag(1e-4).ticks, 2);
        assert!((m.lag(1e-4).fraction - 0.5).abs() < 1e-12);
        let back = DeviceModel::from_toml(&m.to_toml(""), "r").unwrap();
        assert_eq!(back, m);
        // 3e-4 / 1e-4 is 2.9999999999999996 in f64: three whole ticks.
        let d = DeviceModel::from_toml(
            &format!("{rigid}latency_s = 3e-4\ndelay_samples = 1\n"),
            "r",
        )
        .unwrap();
        assert_eq!(
            d.lag(1e-4),
            Lag {
                ticks: 4,
                fraction: 0.0
            }
        );
        for bad in ["-1e-4", "nan", "2.0"] {
            let e = with(bad).unwrap_err().to_string();
            assert!(e.contains("latency_s"), "{bad}: {e}");
        }
        assert_eq!(
            DeviceModel::from_toml(rigid, "r").unwrap().lag(1e-3),
            Lag::NONE
        );
    }

    /// A model without `C_f` has no force sensor; `delay_samples` defaults
    /// to 0; a one-coordinate model's shape errors name n = 1.
    #[test]
    fn optional_force_sensor_and_delay() {
        let rigid = "period_s = 0.001\npeak_force_n = 5.0\ncontinuous_force_n = 2.0\n\
                     M = [[0.01]]\nD = [[0.5]]\nK = [[0.0]]\nG = [[1.0, -1.0]]\n\
                     C_v = [[1.0], [-1.0]]\n";
        let m = DeviceModel::from_toml(rigid, "r").unwrap();
        assert!(!m.force_sensor);
        assert_eq!(m.delay_samples, 0);
        assert_eq!(m.c_f, DMatrix::zeros(1, 1));
        let d = DeviceModel::from_toml(&format!("{rigid}delay_samples = 3\n"), "r").unwrap();
        assert_eq!(d.delay_samples, 3);
        assert!(DeviceModel::excalibur().unwrap().force_sensor);
        let e = DeviceModel::from_toml(&rigid.replace("[[1.0], [-1.0]]", "[[1.0]]"), "r")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("C_v must be 2 x 1 (n = 1 from M), but has 1 rows"),
            "{e}"
        );
    }
}
