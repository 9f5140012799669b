//! The poses a command works on: each model's plant and analysis, the
//! bounds over all of them, and how a run prints.

use crate::args::*;
use serde_json::{json, Value};
use twoport_control::ZTransfer;
use twoport_design::design::{self, Analysis, GridSpec};
use twoport_design::twoport::HumanBound;
use twoport_design::{DeviceModel, Plant};

/// One pose of the device: its model, the plant at the period, and the
/// design grid.
pub(crate) struct Pose {
    pub(crate) model: DeviceModel,
    pub(crate) plant: Plant,
    pub(crate) analysis: Analysis,
}

/// The poses a command works on.
pub(crate) struct Session {
    pub(crate) poses: Vec<Pose>,
    pub(crate) human: Option<HumanBound>,
    pub(crate) json: bool,
    pub(crate) axis: Option<AxisRun>,
}

impl Session {
    pub(crate) fn open(c: &Common) -> Result<Self, String> {
        let models = match &c.axis {
            Some(a) => a.models.clone(),
            None => {
                let mut models = Vec::with_capacity(c.model.len());
                for path in &c.model {
                    let m = DeviceModel::load_or_excalibur(path).map_err(|e| e.to_string())?;
                    models.push((path.clone(), m));
                }
                models
            }
        };
        let period = match c.period {
            Some(p) => p,
            None => {
                let (p0, m0) = &models[0];
                for (p, m) in &models[1..] {
                    if m.period_s != m0.period_s {
                        return Err(format!(
                            "{} has period_s = {} but {} has {}: poses share one board, give --period",
                            p.display(),
                            m.period_s,
                            p0.display(),
                            m0.period_s
                        ));
                    }
                }
                m0.period_s
            }
        };
        if !(period.is_finite() && period > 0.0) {
            return Err(format!(
                "--period {period}: must be a positive number of seconds"
            ));
        }
        let mut poses = Vec::with_capacity(models.len());
        for (path, model) in models {
            let plant =
                Plant::new(&model, period).map_err(|e| format!("{}: {e}", path.display()))?;
            let analysis = Analysis::new(&plant, GridSpec::DEFAULT);
            poses.push(Pose {
                model,
                plant,
                analysis,
            });
        }
        Ok(Session {
            poses,
            human: (!c.no_human).then_some(HumanBound::PAPER),
            json: c.json,
            axis: c.axis.clone(),
        })
    }

    /// The one pose of a command that takes one.
    pub(crate) fn single(&self, command: &str) -> Result<&Pose, String> {
        match self.poses.as_slice() {
            [p] => Ok(p),
            _ => Err(format!("{command} takes one --model")),
        }
    }

    pub(crate) fn period(&self) -> f64 {
        self.poses[0].plant.period_s()
    }

    /// The device's name: its model's, or its poses'.
    pub(crate) fn name(&self) -> String {
        match self.poses.as_slice() {
            [p] => p.model.name.clone(),
            ps => format!(
                "{} poses ({})",
                ps.len(),
                ps.iter()
                    .map(|p| p.model.name.as_str())
                    .collect::<Vec<_>>()
                    .join("; ")
            ),
        }
    }

    /// An admittance display needs a force sensor in every pose.
    pub(crate) fn force_sensor(&self) -> Result<(), String> {
        match self.poses.iter().find(|p| !p.model.force_sensor) {
            Some(p) => Err(no_force_sensor(&p.model)),
            None => Ok(()),
        }
    }

    pub(crate) fn impedance_bounds(&self, paper: bool) -> Vec<Vec<f64>> {
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
    }

    pub(crate) fn admittance_bounds(&self, kp: &ZTransfer, paper: bool) -> Vec<Vec<f64>> {
        self.poses
            .iter()
            .map(|p| {
                if paper {
                    p.analysis.paper_admittance_bound(kp, self.human)
                } else {
                    p.analysis.admittance_bound(kp, self.human)
                }
            })
            .collect()
    }

    /// Each pose's analysis beside its bound.
    pub(crate) fn with<'a>(&'a self, bounds: &'a [Vec<f64>]) -> Vec<(&'a Analysis, &'a [f64])> {
        self.poses
            .iter()
            .zip(bounds)
            .map(|(p, b)| (&p.analysis, b.as_slice()))
            .collect()
    }

    /// The regulated device's worst pole radius over the poses.
    pub(crate) fn regulated_pole_radius(&self, kp: &ZTransfer) -> f64 {
        self.poses
            .iter()
            .map(|p| p.plant.regulated_pole_radius(kp))
            .fold(0.0, f64::max)
    }

    /// The check over every pose: stable where every pose is, with the
    /// least margin and the pose that has it (the paper's figures likewise).
    pub(crate) fn worst_check(
        &self,
        check: impl Fn(&Pose) -> Option<design::Check>,
    ) -> Option<(design::Check, &str)> {
        let mut all = Vec::with_capacity(self.poses.len());
        for p in &self.poses {
            all.push((check(p)?, p.model.name.as_str()));
        }
        let least = |key: fn(&design::Check) -> f64| {
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

    pub(crate) fn human_text(&self) -> &'static str {
        if self.human.is_some() {
            "human bound Z_max = 300 + 1000/s"
        } else {
            "no human bound (any passive human)"
        }
    }

    pub(crate) fn header(&self, display: &str) {
        println!(
            "{display} display, {} at T = {} ms, {}",
            self.name(),
            self.period() * 1e3,
            self.human_text()
        );
    }

    pub(crate) fn emit(&self, mut v: Value, text: impl FnOnce()) {
        match (&self.axis, self.json) {
            (Some(a), true) => {
                v["axis"] = json!(a.name);
                a.out.borrow_mut().push(v);
            }
            (None, true) => println!("{v}"),
            (_, false) => text(),
        }
    }
}

/// Why an admittance display cannot be built for `model`.
pub(crate) fn no_force_sensor(model: &DeviceModel) -> String {
    format!(
        "{}: the model has no force sensor (no C_f), and an admittance display needs one to measure the hand's force; design an impedance display instead",
        model.name
    )
}
