//! The frequency grid a design is checked on, and the device's responses
//! on it.

use crate::network::{admittance_display, design_bound, impedance_display, HumanBound};
use crate::plant::Feature;
use crate::{sampled, Plant, PlantPoint};
use std::f64::consts::PI;
use twoport_control::ZTransfer;

/// How finely to sample frequency.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridSpec {
    /// Lowest frequency (Hz).
    pub f_min_hz: f64,
    /// Log-spaced points from `f_min_hz` to Nyquist.
    pub base_points: usize,
    /// Points across each resonance (see [`grid`]): linearly spaced over
    /// its shape, this many in all.
    pub points_per_mode: usize,
    /// Points per decade of distance from each feature's centre, from a
    /// hundredth of its half-width out to its shape's edge.
    pub points_per_decade: usize,
}

impl GridSpec {
    /// The default design grid. Doubling every count moves no design result
    /// by more than 0.5% (tested). Below its lowest frequency the limit
    /// `ω -> 0` is taken analytically (see [`dc_margin`](super::dc_margin)), so starting it
    /// lower moves no result either (tested).
    pub const DEFAULT: GridSpec = GridSpec {
        f_min_hz: 0.05,
        base_points: 1500,
        points_per_mode: 300,
        points_per_decade: 24,
    };

    /// This grid started at `f_min_hz` instead, with the same density.
    pub fn from_hz(self, f_min_hz: f64) -> GridSpec {
        let decades = (f_min_hz / self.f_min_hz).log10();
        let per_decade = self.base_points as f64 / (500.0 / self.f_min_hz).log10();
        GridSpec {
            f_min_hz,
            base_points: (self.base_points as f64 - decades * per_decade)
                .round()
                .max(2.0) as usize,
            ..self
        }
    }

    /// This grid with twice the points.
    pub fn doubled(self) -> GridSpec {
        GridSpec {
            base_points: self.base_points * 2,
            points_per_mode: self.points_per_mode * 2,
            points_per_decade: self.points_per_decade * 2,
            ..self
        }
    }
}

/// Angular frequencies (rad/s), increasing, in `(0, π/T]`, ending at `π/T`.
///
/// A log grid, refined at every [`Feature`](crate::plant::Feature) of the
/// device: its free modes, its modes with the handle held (still, or by
/// the stiffest grasp), each folded into the base band, and its discrete
/// poles. Each term of a design inequality is a sum of terms
/// `r/(jω - λ)` (or their alias sums, which have the same folded poles), and
/// such a term changes by a large fraction of itself only within a few
/// half-widths `|Re λ|` of `Im λ`. So around each feature the grid places
/// points log-spaced in the distance from its centre, from 1/100 of its
/// half-width out to its shape's edge (20 half-widths, at least 2% of the
/// centre): however lightly damped, a mode is resolved on its own scale,
/// where a fixed spacing would step over a mode narrower than it.
pub fn grid(plant: &Plant, spec: GridSpec) -> Vec<f64> {
    let nyq = plant.nyquist();
    let mut lo = (2.0 * PI * spec.f_min_hz).min(nyq / 10.0);
    // Below the lowest point the limit toward DC is a series in ω², which
    // a feature folded near DC must not bend on that scale: start the grid
    // a tenth of its half-width down.
    for f in plant.features() {
        if f.omega < 2.0 * lo && f.half_width > 0.0 {
            lo = lo.min(0.1 * f.half_width);
        }
    }
    let mut w = log_grid(lo, nyq, spec.base_points);
    // (Refinements below the lowest point fall to the limit, and would
    // leave the grid without its DC pair.)
    let mut push = |x: f64| {
        if x >= lo && x <= nyq {
            w.push(x);
        }
    };
    refine(plant.features(), spec, &mut push);
    // The exact ends: Nyquist, and twice the lowest frequency for the
    // limit toward DC.
    w.push(nyq);
    w.push(2.0 * lo);
    w.sort_by(f64::total_cmp);
    w.dedup_by(|a, b| (*a - *b).abs() <= COINCIDENT * b.abs());
    w
}

/// Points around each of `features`, as [`grid`] places them.
fn refine(features: &[Feature], spec: GridSpec, push: &mut impl FnMut(f64)) {
    for f in features {
        let (c, beta) = (f.omega, f.half_width.max(1e-12 * f.omega));
        let edge = (20.0 * beta).max(0.02 * c);
        // Linear over the shape, as the eye would sample it.
        let k = spec.points_per_mode.max(2);
        for i in 0..k {
            push(c - edge + 2.0 * edge * i as f64 / (k - 1) as f64);
        }
        // Log in the distance from the centre, down to 1/100 half-width.
        push(c);
        let per = spec.points_per_decade.max(1) as f64;
        let mut j = 0.0;
        loop {
            let u = 0.01 * beta * 10f64.powf(j / per);
            if u > edge {
                break;
            }
            push(c - u);
            push(c + u);
            j += 1.0;
        }
    }
}

/// Angular frequencies (rad/s), increasing, in `(0, π/T]`: the points
/// [`grid`] would place around `features` alone (the admittance display's
/// regulated poles, which depend on the regulator), or none.
pub fn feature_grid(plant: &Plant, features: &[Feature], spec: GridSpec) -> Vec<f64> {
    let nyq = plant.nyquist();
    let mut w = Vec::new();
    refine(features, spec, &mut |x: f64| {
        if x > 0.0 && x <= nyq {
            w.push(x);
        }
    });
    w.sort_by(f64::total_cmp);
    w.dedup_by(|a, b| (*a - *b).abs() <= COINCIDENT * b.abs());
    w
}

/// Grid points closer than this (relative) are one: two refinements that
/// land 1e-11 apart would give [`least`](super::least)'s parabola a
/// divided difference of rounding noise. A mode with a damping ratio of
/// 1e-6 is still a thousand points wide.
pub(super) const COINCIDENT: f64 = 1e-9;

/// The relative difference of `X_aa^d` in f64 and in double-double under
/// which a grid point near DC keeps its f64 terms.
const PRECISE_AGREEMENT: f64 = 1e-11;

/// The device's responses on a grid, ready for design and checks.
#[derive(Clone, Debug)]
pub struct Analysis {
    /// The per-frequency plant terms.
    pub points: Vec<PlantPoint>,
    /// The sample period (s).
    pub period_s: f64,
    /// The device, for the alias sums of the sampled-data bounds.
    plant: Plant,
    /// The index of twice the lowest frequency, where the grid has it: with
    /// the lowest, the pair the limit toward DC is taken from.
    pub(super) dc_pair: Option<usize>,
    /// The device's terms at each point's aliases, shared by every bound.
    aliases: sampled::AliasCache,
}

impl Analysis {
    /// Evaluate `plant` on the grid `spec`.
    ///
    /// # Examples
    ///
    /// ```
    /// use twoport_design::analysis::{max_stiffness, Analysis, GridSpec};
    /// use twoport_design::network::HumanBound;
    /// use twoport_design::{DeviceModel, Plant};
    /// let m = DeviceModel::excalibur()?;
    /// let a = Analysis::new(&Plant::new(&m, 1e-3)?, GridSpec::DEFAULT);
    /// let k = max_stiffness(&a, &a.impedance_bound(Some(HumanBound::PAPER)), 90.0).unwrap();
    /// assert!((k - 51_000.0).abs() < 0.03 * 51_000.0); // the paper's design
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn new(plant: &Plant, spec: GridSpec) -> Self {
        Analysis::from_points(plant, plant.response(&grid(plant, spec)))
    }

    /// `model` at its own period on the default grid: where most designs
    /// start. The error names what the model's dynamics refused.
    pub fn of(model: &crate::DeviceModel) -> Result<Self, crate::Error> {
        Plant::new(model, model.period_s).map(|p| Analysis::new(&p, GridSpec::DEFAULT))
    }

    /// The paper's Excalibur (the built-in model) at 1 ms on the default
    /// grid.
    pub fn excalibur() -> Self {
        let m = crate::DeviceModel::excalibur().expect("the built-in Excalibur model is valid");
        Analysis::of(&m).expect("the built-in Excalibur model discretises")
    }

    /// Evaluate `plant` on the given angular frequencies (rad/s).
    pub fn on(plant: &Plant, omegas: &[f64]) -> Self {
        Analysis::from_points(plant, plant.response(omegas))
    }

    fn from_points(plant: &Plant, mut points: Vec<PlantPoint>) -> Self {
        let dc_pair = points.first().and_then(|p1| {
            points
                .iter()
                .position(|p| (p.omega - 2.0 * p1.omega).abs() <= 1e-12 * p.omega)
        });
        // Toward DC the sampled terms grow as the rigid body's double pole
        // at z = 1, and the design inequality is their small difference.
        // A stiff device's exponential holds that pole in f64 only to its
        // largest entries' rounding: upward from the lowest point, each
        // point is taken again in double-double until the two agree.
        if dc_pair.is_some() {
            let mut work = plant.scratch();
            for p in points.iter_mut() {
                let Some(q) = plant.at_precise(p.omega, &mut work) else {
                    break;
                };
                let agree = (p.xaa_d - q.xaa_d).norm() <= PRECISE_AGREEMENT * q.xaa_d.norm();
                *p = q;
                if agree {
                    break;
                }
            }
        }
        Analysis {
            aliases: sampled::AliasCache::new(points.len()),
            points,
            period_s: plant.period_s(),
            plant: plant.clone(),
            dc_pair,
        }
    }

    /// The device this analysis is of.
    pub fn plant(&self) -> &Plant {
        &self.plant
    }

    /// The device's alias terms at each point, shared by every bound.
    pub(crate) fn aliases(&self) -> &sampled::AliasCache {
        &self.aliases
    }

    /// The impedance-display bound on `Re(1/Z_cI)` at each grid point,
    /// sound for the sampled-data loop (aliasing at the handle port
    /// included, see [`crate::sampled`]): what designs and checks use.
    pub fn impedance_bound(&self, human: Option<HumanBound>) -> Vec<f64> {
        sampled::impedance_bound_with(&self.plant, &self.points, human, &self.aliases)
    }

    /// The admittance-display bound on `Re Z_cA` at each grid point, for
    /// the regulator `kp`, sound for the sampled-data loop.
    pub fn admittance_bound(&self, kp: &ZTransfer, human: Option<HumanBound>) -> Vec<f64> {
        sampled::admittance_bound_with(&self.plant, &self.points, kp, human, &self.aliases)
    }

    /// The paper's impedance-display bound (eq 25 as corrected): the handle
    /// port's cross terms as continuous transfer functions times the hold,
    /// aliasing neglected. Reported beside the sound one, never used alone
    /// to prove.
    pub fn paper_impedance_bound(&self, human: Option<HumanBound>) -> Vec<f64> {
        self.points
            .iter()
            .map(|p| design_bound(&impedance_display(p, human)))
            .collect()
    }

    /// The paper's admittance-display bound (eq 28), aliasing neglected.
    pub fn paper_admittance_bound(&self, kp: &ZTransfer, human: Option<HumanBound>) -> Vec<f64> {
        self.points
            .iter()
            .map(|p| design_bound(&admittance_display(p, kp, human)))
            .collect()
    }
}

/// `n` (at least 2) log-spaced values from `lo` to `hi`, both included.
pub fn log_grid(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    let n = n.max(2);
    (0..n)
        .map(|i| lo * (hi / lo).powf(i as f64 / (n - 1) as f64))
        .collect()
}
