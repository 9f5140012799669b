//! The designer: a device in one or several poses at one sample period,
//! with or without the human bound, answering what the `twoport` command
//! line asks (a design, a check, the proven region, the counterexample
//! search) as reports that serialise to JSON and display as text.
//!
//! Each pose's sound impedance bound is computed once and shared by every
//! question; an admittance bound is computed once per regulator asked for.
//!
//! ```
//! use twoport_design::designer::Designer;
//! use twoport_design::network::HumanBound;
//! use twoport_design::DeviceModel;
//! let d = Designer::new(vec![DeviceModel::excalibur()?], None, Some(HumanBound::PAPER))?;
//! let r = d.design_impedance(Some(90.0), 0.1)?;
//! let (k, _) = r.coupling.expect("the paper's device has a design");
//! assert!((k - 51_000.0).abs() < 0.03 * 51_000.0);
//! println!("{r}");
//! # Ok::<(), twoport_design::Error>(())
//! ```

mod regulated;
mod report;
mod teleop;

pub use report::*;
pub use teleop::TeleopDesigner;

use crate::analysis::{self, Analysis, Check, GridSpec, Poses};
use crate::limit_cycle::{Friction, LimitCycle};
use crate::network::HumanBound;
use crate::{DeviceModel, Error, Plant};
use regulated::Regulated;
use std::sync::{Arc, Mutex, OnceLock};
use twoport_control::{Gains, ZTransfer};

/// One pose of the device: its model, the plant at the period, and the
/// design grid.
#[derive(Clone, Debug)]
pub struct Pose {
    /// The model.
    pub model: DeviceModel,
    /// The model discretised at the designer's period.
    pub plant: Plant,
    /// Its responses on the design grid.
    pub analysis: Analysis,
}

/// A device's poses at one period, and the bounds every question shares.
#[derive(Debug)]
pub struct Designer {
    poses: Vec<Pose>,
    human: Option<HumanBound>,
    /// Each pose's sound and paper impedance bounds.
    impedance: OnceLock<BoundPair>,
    /// The admittance display's analyses and bounds, per regulator
    /// `(k_p, b_p)` asked for.
    admittance: Mutex<Vec<Arc<Regulated>>>,
}

/// Each pose's sound bound and the paper's, at every grid point.
type BoundPair = [Vec<Vec<f64>>; 2];

/// Which of a display's bounds: the sound one, or the paper's.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Bound {
    Sound = 0,
    Paper = 1,
}

impl Designer {
    /// The device in the poses `models` (at least one), at `period_s` (the
    /// models' own, which must then agree, when `None`), with the human
    /// bound `human` (`None`: any passive human).
    pub fn new(
        models: Vec<DeviceModel>,
        period_s: Option<f64>,
        human: Option<HumanBound>,
    ) -> Result<Self, Error> {
        let first = models.first().ok_or(Error::NoPose)?;
        let period = match period_s {
            Some(p) => p,
            None => {
                if let Some(m) = models.iter().find(|m| m.period_s != first.period_s) {
                    return Err(Error::PeriodsDiffer {
                        first: (first.name.clone(), first.period_s),
                        other: (m.name.clone(), m.period_s),
                    });
                }
                first.period_s
            }
        };
        if !(period.is_finite() && period > 0.0) {
            return Err(Error::Period(period));
        }
        let mut poses = Vec::with_capacity(models.len());
        for model in models {
            let plant = Plant::new(&model, period)?;
            let analysis = Analysis::new(&plant, GridSpec::DEFAULT);
            poses.push(Pose {
                model,
                plant,
                analysis,
            });
        }
        Ok(Designer {
            poses,
            human,
            impedance: OnceLock::new(),
            admittance: Mutex::new(Vec::new()),
        })
    }

    /// The poses.
    pub fn poses(&self) -> &[Pose] {
        &self.poses
    }

    /// The human bound the proofs assume (`None`: any passive human).
    pub fn human(&self) -> Option<HumanBound> {
        self.human
    }

    /// The sample period (s).
    pub fn period_s(&self) -> f64 {
        self.poses[0].plant.period_s()
    }

    /// The device's name: its model's, or its poses'.
    pub fn name(&self) -> String {
        match self.poses.as_slice() {
            [p] => p.model.name.clone(),
            ps => {
                // A set from identification has dozens: name a few.
                const NAMED: usize = 4;
                let names: Vec<&str> = ps.iter().map(|p| p.model.name.as_str()).collect();
                let listed = if names.len() > NAMED + 1 {
                    format!(
                        "{}; and {} more",
                        names[..NAMED].join("; "),
                        names.len() - NAMED
                    )
                } else {
                    names.join("; ")
                };
                format!("{} poses ({listed})", ps.len())
            }
        }
    }

    /// What every report's heading says of the device.
    fn context(&self, display: DisplayKind) -> Context {
        Context {
            display,
            device: self.name(),
            period_s: self.period_s(),
            human_model: self.human.is_some(),
            latency_s: self
                .poses
                .iter()
                .map(|p| p.model.latency_s)
                .fold(f64::INFINITY, f64::min),
        }
    }

    /// An admittance display needs a force sensor in every pose.
    fn force_sensor(&self) -> Result<(), Error> {
        match self.poses.iter().find(|p| !p.model.force_sensor) {
            Some(p) => Err(Error::NoForceSensor(p.model.name.clone())),
            None => Ok(()),
        }
    }

    fn impedance_bounds(&self, which: Bound) -> &[Vec<f64>] {
        &self.impedance.get_or_init(|| {
            let each = |paper: bool| {
                self.poses
                    .iter()
                    .map(|p| {
                        if paper {
                            p.analysis.paper_impedance_bound(self.human)
                        } else {
                            p.analysis.impedance_bound(self.human)
                        }
                    })
                    .collect()
            };
            [each(false), each(true)]
        })[which as usize]
    }

    /// The analyses and bounds for the regulator `(k_p, b_p)` (its
    /// transfer function `k`), built the first time they are asked for.
    fn regulated(&self, kp: (f64, f64), k: &ZTransfer) -> Arc<Regulated> {
        let mut cache = self.admittance.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(r) = cache.iter().find(|r| r.kp == kp) {
            return r.clone();
        }
        let r = Arc::new(Regulated::new(&self.poses, kp, k, self.human));
        cache.push(r.clone());
        r
    }

    /// Each pose's analysis beside its bound.
    fn with<'a>(&'a self, bounds: &'a [Vec<f64>]) -> Vec<(&'a Analysis, &'a [f64])> {
        self.poses
            .iter()
            .zip(bounds)
            .map(|(p, b)| (&p.analysis, b.as_slice()))
            .collect()
    }

    /// The regulated device's worst pole radius over the poses.
    fn regulated_pole_radius(&self, k: &ZTransfer) -> f64 {
        self.poses
            .iter()
            .map(|p| p.plant.regulated_pole_radius(k))
            .fold(0.0, f64::max)
    }

    /// The check over every pose: stable where every pose is, with the
    /// least margin and the pose that has it (the paper's figures likewise).
    fn worst_check(&self, check: impl Fn(&Pose) -> Option<Check>) -> Option<(Check, &str)> {
        self.worst_of(self.poses.iter().map(|p| (p, &p.analysis)), |p, _| check(p))
    }

    /// [`Self::worst_check`] over `analyses` (a pose's grid, or more
    /// points of it).
    fn worst_of<'a>(
        &'a self,
        analyses: impl Iterator<Item = (&'a Pose, &'a Analysis)>,
        check: impl Fn(&Pose, &Analysis) -> Option<Check>,
    ) -> Option<(Check, &'a str)> {
        let mut all = Vec::new();
        for (p, a) in analyses {
            all.push((check(p, a)?, p.model.name.as_str()));
        }
        let least = |key: fn(&Check) -> f64| {
            all.iter()
                .copied()
                .min_by(|a, b| key(&a.0).total_cmp(&key(&b.0)))
        };
        let (mut c, name) = least(|c| c.min_margin)?;
        let (paper, _) = least(|c| c.paper.min_margin)?;
        c.absolutely_stable = all.iter().all(|x| x.0.absolutely_stable);
        c.regulator_pole_radius = all
            .iter()
            .map(|x| x.0.regulator_pole_radius)
            .fold(0.0, f64::max);
        c.paper = paper.paper;
        c.paper.absolutely_stable = all.iter().all(|x| x.0.paper.absolutely_stable);
        Some((c, name))
    }

    /// Where a design binds, from its worst check: the frequency, the pose
    /// (with several), and the lightly damped mode there, if one is.
    fn binding(&self, worst: Option<(Check, &str)>) -> Option<Binds> {
        worst.map(|(c, name)| Binds {
            frequency_hz: c.worst_frequency_hz,
            pose: self.pose_name(name),
            limited_by: self.light_mode_at(c.worst_frequency_hz),
        })
    }

    /// The lightly damped mode (damping ratio below 1e-3) of any pose
    /// within three of its half-widths of `hz`, if one is: what a design
    /// that binds at `hz` is limited by.
    fn light_mode_at(&self, hz: f64) -> Option<LightMode> {
        let w = 2.0 * std::f64::consts::PI * hz;
        self.poses
            .iter()
            .flat_map(|p| p.plant.features().iter())
            .filter(|f| f.half_width < 1e-3 * f.omega)
            .filter(|f| (f.omega - w).abs() <= 3.0 * f.half_width + 1e-3 * f.omega)
            .min_by(|a, b| a.half_width.total_cmp(&b.half_width))
            .map(|f| LightMode {
                frequency_hz: f.omega / (2.0 * std::f64::consts::PI),
                damping_ratio: f.half_width / f.omega,
            })
    }

    /// The pose a check binds in, where there are several.
    fn pose_name(&self, name: &str) -> Option<String> {
        (self.poses.len() > 1).then(|| name.to_string())
    }

    fn impedance_on(&self, poses: &Poses, b: Option<f64>) -> Option<(f64, f64)> {
        match b {
            Some(b) => analysis::max_stiffness_poses(poses, b).map(|k| (k, b)),
            None => analysis::best_impedance_poses(poses),
        }
    }

    fn admittance_on(&self, poses: &Poses, radius: f64, b: Option<f64>) -> Option<(f64, f64)> {
        if radius >= 1.0 {
            return None;
        }
        match b {
            Some(b) => analysis::min_mass_poses(poses, b).map(|m| (m, b)),
            None => analysis::best_admittance_poses(poses),
        }
    }

    /// Why no coupling `what` meets `bounds`: the limit toward DC, or the
    /// range searched.
    fn infeasible(&self, bounds: &[Vec<f64>], what: Infeasible, b: Option<f64>) -> String {
        let (name, bound_unit, range, unit) = match what {
            Infeasible::Stiffness => ("stiffness", "m/(N s)", analysis::K_RANGE, "N/m"),
            Infeasible::Mass(_) => ("mass", "N s/m", analysis::M_RANGE, "kg"),
        };
        let (lo, hi) = range.into_inner();
        if let Some(limit) = self
            .with(bounds)
            .iter()
            .find_map(|(a, b)| analysis::low_frequency_obstacle(a, b))
        {
            return format!(
                "no finite coupling {name} is absolutely stable: toward DC the bound stays positive (its limit is {limit:.4e} {bound_unit}), while the coupling's real part goes to zero as the frequency does"
            );
        }
        // Where even the most cautious gain of the search fails (the
        // softest stiffness, the heaviest mass) at the damping asked for,
        // or the search's least.
        let b_c = b.unwrap_or(*analysis::B_RANGE.start());
        let worst = match what {
            Infeasible::Stiffness => {
                self.worst_check(|p| analysis::check_impedance(&p.analysis, lo, b_c, self.human))
            }
            Infeasible::Mass(kp) => self.worst_check(|p| {
                analysis::check_admittance(&p.plant, &p.analysis, kp, (hi, b_c), self.human)
            }),
        };
        let at = b
            .map(|b| format!(" at b_c = {b} N s/m"))
            .unwrap_or_default();
        let cautious = match what {
            Infeasible::Stiffness => format!("{lo} N/m"),
            Infeasible::Mass(_) => format!("{hi} kg"),
        };
        match worst {
            Some((c, pose)) => format!(
                "no coupling {name} from {lo} to {hi} {unit} meets the bound{at}: even {cautious} (b_c = {b_c} N s/m) fails, least at {:.2} Hz{}",
                c.worst_frequency_hz,
                self.pose_name(pose)
                    .map(|p| format!(" in pose {p}"))
                    .unwrap_or_default()
            ),
            None => format!("no coupling {name} from {lo} to {hi} {unit} meets the bound{at}"),
        }
    }

    /// The impedance display's boundary coupling stiffness at damping `b`
    /// (N s/m), or the best `(k, b)` pair without it, and the gain
    /// `margin` (a fraction) inside it.
    pub fn design_impedance(&self, b: Option<f64>, margin: f64) -> Result<Design, Error> {
        let margin = fraction(margin)?;
        if let Some(b) = b {
            gain("b", b)?;
        }
        let sound = self.impedance_bounds(Bound::Sound);
        let coupling = self.impedance_on(&self.with(sound), b);
        let paper = self.impedance_on(&self.with(self.impedance_bounds(Bound::Paper)), b);
        let binding = self.binding(coupling.and_then(|(k, b)| {
            self.worst_check(|p| analysis::check_impedance(&p.analysis, k, b, self.human))
        }));
        let message = coupling
            .is_none()
            .then(|| self.infeasible(sound, Infeasible::Stiffness, b));
        let mut d = Design::new(
            self.context(DisplayKind::Impedance),
            Limit::Stiffness,
            [coupling, paper],
            b.is_some(),
            margin,
            binding,
            message,
        );
        d.refuse_if_useless();
        d.limit_cycle = d
            .recommended()
            .zip(d.coupling)
            .and_then(|(k, (_, b))| self.limit_cycle(k, b, true));
        Ok(d)
    }

    /// The admittance display's boundary coupling mass at damping `b` (N
    /// s/m), or the best `(m, b)` pair without it, for the regulator
    /// `(k_p, b_p)` (the impedance design's best pair when `None`, the
    /// paper's eq 30), and the gain `margin` inside it.
    pub fn design_admittance(
        &self,
        regulator: Option<(f64, f64)>,
        b: Option<f64>,
        margin: f64,
    ) -> Result<Design, Error> {
        let margin = fraction(margin)?;
        self.force_sensor()?;
        if let Some(b) = b {
            gain("b", b)?;
        }
        let (kp, bp) = match regulator {
            Some((kp, bp)) => (gain("kp", kp)?, gain("bp", bp)?),
            None => self
                .impedance_on(&self.with(self.impedance_bounds(Bound::Sound)), None)
                .ok_or(Error::NoRegulator)?,
        };
        let k = analysis::regulator_tf(kp, bp, self.period_s())?;
        let radius = self.regulated_pole_radius(&k);
        let reg = self.regulated((kp, bp), &k);
        let coupling = self.admittance_on(&reg.with(&self.poses, Bound::Sound), radius, b);
        let paper = self.admittance_on(&reg.with(&self.poses, Bound::Paper), radius, b);
        let binding = self.binding(coupling.and_then(|(m, b)| {
            self.worst_of(reg.analyses(&self.poses), |p, a| {
                analysis::check_admittance(&p.plant, a, (kp, bp), (m, b), self.human)
            })
        }));
        let sound = reg.grid_bounds(Bound::Sound);
        let message = match coupling {
            Some(_) => None,
            None if radius >= 1.0 => Some(format!(
                "the regulator k_p = {kp}, b_p = {bp} does not stabilise the device (pole radius {radius:.4})"
            )),
            None => Some(self.infeasible(sound, Infeasible::Mass((kp, bp)), b)),
        };
        let mut d = Design::new(
            self.context(DisplayKind::Admittance),
            Limit::Mass,
            [coupling, paper],
            b.is_some(),
            margin,
            binding,
            message,
        );
        d.regulator = Some(Regulator {
            kp,
            bp,
            pole_radius: radius,
        });
        d.limit_cycle = self.limit_cycle(kp, bp, false);
        Ok(d)
    }

    /// Whether the impedance coupling `k` (N/m), `b` (N s/m) is proven, by
    /// how much, and how far inside the boundary at its damping.
    pub fn check_impedance(&self, k: f64, b: f64) -> Result<CheckReport, Error> {
        let (k, b) = (gain("k", k)?, gain("b", b)?);
        let (c, pose) = self
            .worst_check(|p| analysis::check_impedance(&p.analysis, k, b, self.human))
            .ok_or(Error::Coupling(format!(
                "k {k} N/m, b {b} N s/m: not a valid coupling (k T + b must be > 0)"
            )))?;
        let boundary = self
            .impedance_on(&self.with(self.impedance_bounds(Bound::Sound)), Some(b))
            .map(|(k, _)| k);
        let mut r = CheckReport::new(
            self.context(DisplayKind::Impedance),
            Gains::from(twoport_control::ImpedanceGains::new(k as f32, b as f32)),
            (k, b, None),
            &c,
            self.pose_name(pose),
            boundary,
        );
        r.limit_cycle = self.limit_cycle(k, b, true);
        Ok(r)
    }

    /// Whether the admittance design (regulator `(k_p, b_p)`, coupling
    /// mass `m` (kg) and damping `b`) is proven, by how much, and how far
    /// above the boundary at its damping.
    pub fn check_admittance(
        &self,
        (kp, bp): (f64, f64),
        m: f64,
        b: f64,
    ) -> Result<CheckReport, Error> {
        self.force_sensor()?;
        let kp = (gain("kp", kp)?, gain("bp", bp)?);
        let b = gain("b", b)?;
        if !(m.is_finite() && m > 0.0) {
            return Err(Error::Coupling(format!(
                "m {m}: must be a finite mass > 0 kg"
            )));
        }
        let k = analysis::regulator_tf(kp.0, kp.1, self.period_s())?;
        let reg = self.regulated(kp, &k);
        let (c, pose) = self
            .worst_of(reg.analyses(&self.poses), |p, a| {
                analysis::check_admittance(&p.plant, a, kp, (m, b), self.human)
            })
            .ok_or(Error::Coupling(
                "b must be > 0 N s/m for the admittance coupling".into(),
            ))?;
        let boundary = self
            .admittance_on(
                &reg.with(&self.poses, Bound::Sound),
                c.regulator_pole_radius,
                Some(b),
            )
            .map(|(m, _)| m);
        let mut r = CheckReport::new(
            self.context(DisplayKind::Admittance),
            Gains::from(twoport_control::AdmittanceGains::new(
                kp.0 as f32,
                kp.1 as f32,
                m as f32,
                b as f32,
            )),
            (m, b, Some(kp)),
            &c,
            self.pose_name(pose),
            boundary,
        );
        r.limit_cycle = self.limit_cycle(kp.0, kp.1, false);
        Ok(r)
    }

    /// The quantisation's limit cycles for a law of stiffness `k` and
    /// damping `b` on the encoder (the impedance coupling, or the
    /// admittance display's regulator), where the model gives a quantum.
    fn limit_cycle(&self, k: f64, b: f64, impedance: bool) -> Option<LimitCycle> {
        let pose = self.poses.first()?;
        let friction = pose.model.friction()?;
        // With several poses the device is not one rigid body everywhere.
        let friction = Friction {
            rigid_damping_nspm: friction
                .rigid_damping_nspm
                .filter(|_| self.poses.len() == 1),
            ..friction
        };
        Some(LimitCycle::new(&friction, k, b, self.period_s(), impedance))
    }

    /// The impedance display's proven region: the greatest stiffness at
    /// each of `points` log-spaced dampings over `range` (N s/m).
    pub fn region_impedance(
        &self,
        range: (f64, f64),
        points: usize,
    ) -> Result<RegionReport, Error> {
        let range = region_range(range, points)?;
        let rows = analysis::region_impedance(
            &self.with(self.impedance_bounds(Bound::Sound)),
            range,
            points,
        );
        Ok(RegionReport {
            context: self.context(DisplayKind::Impedance),
            bound: RegionBound::MaxStiffness,
            rows,
            regulator: None,
        })
    }

    /// The admittance display's proven region for the regulator `(k_p,
    /// b_p)`: the least mass at each of `points` log-spaced dampings.
    pub fn region_admittance(
        &self,
        (kp, bp): (f64, f64),
        range: (f64, f64),
        points: usize,
    ) -> Result<RegionReport, Error> {
        let range = region_range(range, points)?;
        self.force_sensor()?;
        let (kp, bp) = (gain("kp", kp)?, gain("bp", bp)?);
        let k = analysis::regulator_tf(kp, bp, self.period_s())?;
        let reg = self.regulated((kp, bp), &k);
        Ok(RegionReport {
            context: self.context(DisplayKind::Admittance),
            bound: RegionBound::MinMass,
            rows: analysis::region_admittance(&reg.with(&self.poses, Bound::Sound), range, points),
            regulator: Some((kp, bp)),
        })
    }

    /// Search every pose for a passive hand and VE that make the exact
    /// sampled loop unstable at `gains`; the worst pose's verdict, with the
    /// closed loops searched over all of them.
    pub fn verify(&self, gains: &Gains) -> Result<VerifyReport, Error> {
        let display = match gains {
            Gains::Impedance(_) => DisplayKind::Impedance,
            Gains::Admittance(_) => {
                self.force_sensor()?;
                DisplayKind::Admittance
            }
        };
        let mut worst: Option<(crate::verify::Verdict, &str)> = None;
        let mut evaluations = 0;
        for p in &self.poses {
            let v = crate::verify::verify_near(
                &p.model,
                self.period_s(),
                gains,
                self.human,
                &self.binding_hz(p, gains),
            )?;
            evaluations += v.evaluations;
            let worse = worst.as_ref().is_none_or(|w| {
                (v.unstable, v.spectral_radius) > (w.0.unstable, w.0.spectral_radius)
            });
            if worse {
                worst = Some((v, &p.model.name));
            }
        }
        let (mut verdict, pose) = worst.ok_or(Error::NoPose)?;
        verdict.evaluations = evaluations;
        Ok(VerifyReport {
            context: self.context(display),
            verdict,
            worst_pose: self.pose_name(pose),
        })
    }
}

impl Designer {
    /// Where the proof binds at `gains` in `pose`: the frequency of the
    /// least margin on its grid (and the regulated loop's extra points, on
    /// the admittance display); none where the gains cannot be checked.
    fn binding_hz(&self, pose: &Pose, gains: &Gains) -> Vec<f64> {
        let check = match *gains {
            Gains::Impedance(g) => analysis::check_impedance(
                &pose.analysis,
                f64::from(g.k_npm),
                f64::from(g.b_nspm),
                self.human,
            ),
            Gains::Admittance(g) => {
                let kp = (f64::from(g.kp_npm), f64::from(g.bp_nspm));
                let Ok(k) = analysis::regulator_tf(kp.0, kp.1, self.period_s()) else {
                    return Vec::new();
                };
                let reg = self.regulated(kp, &k);
                let at = (f64::from(g.m_kg), f64::from(g.b_nspm));
                return reg
                    .analyses(&self.poses)
                    .filter(|(p, _)| std::ptr::eq(*p, pose))
                    .filter_map(|(p, a)| {
                        analysis::check_admittance(&p.plant, a, kp, at, self.human)
                    })
                    .map(|c| c.worst_frequency_hz)
                    .collect();
            }
        };
        check.map(|c| c.worst_frequency_hz).into_iter().collect()
    }
}

/// What an infeasible design could not find: a stiffness, or a mass for
/// the regulator `(k_p, b_p)`.
#[derive(Clone, Copy)]
enum Infeasible {
    Stiffness,
    Mass((f64, f64)),
}

/// A gain checked for sign and finiteness before any analysis.
fn gain(name: &'static str, v: f64) -> Result<f64, Error> {
    (v.is_finite() && v >= 0.0)
        .then_some(v)
        .ok_or(Error::Gain { name, value: v })
}

/// A design margin: a fraction from 0 to 0.9.
fn fraction(v: f64) -> Result<f64, Error> {
    (0.0..=0.9)
        .contains(&v)
        .then_some(v)
        .ok_or(Error::Margin(v))
}

/// A region's damping range and point count, checked.
fn region_range((lo, hi): (f64, f64), points: usize) -> Result<(f64, f64), Error> {
    let (lo, hi) = (gain("b_from", lo)?, gain("b_to", hi)?);
    if lo > 0.0 && hi > lo && (2..=1000).contains(&points) {
        Ok((lo, hi))
    } else {
        Err(Error::RegionGrid)
    }
}
