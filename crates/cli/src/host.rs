//! `twoport host-ve`: an impedance coupling proven against a body the
//! host simulates and moves with the handle, at the host's VE rate and
//! the link's delay, on every pose; with `--verify`, the exact two-rate
//! loop searched for a hand that makes it grow.

use crate::args::*;
use crate::run::*;
use serde::Serialize;
use std::fmt;
use twoport_design::host_ve::{
    check_host_ve, host_best_pair, host_max_stiffness, HostCheck, HostLoop,
};
use twoport_design::network::HumanBound;
use twoport_design::verify::{verify_host, HostVerdict};
use twoport_design::DeviceAxis;

/// What `host-ve` found on one pose.
#[derive(Serialize)]
struct PoseReport {
    model: String,
    check: HostCheck,
    #[serde(skip_serializing_if = "Option::is_none")]
    verify: Option<HostVerdict>,
}

/// What `host-ve` found.
#[derive(Serialize)]
struct HostVeReport {
    period_s: f64,
    ve_period_ticks: u32,
    delay_ticks: u32,
    body_mass_kg: f64,
    body_damping_nspm: f64,
    k_npm: f64,
    b_nspm: f64,
    /// Whether (k, b) was searched for (the stiffest proven) or given.
    searched: bool,
    proven: bool,
    poses: Vec<PoseReport>,
}

impl fmt::Display for HostVeReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "host VE: a body of {} kg and {} N s/m, every {} ticks of {} s, answered {} ticks after the force it reads",
            self.body_mass_kg, self.body_damping_nspm, self.ve_period_ticks, self.period_s, self.delay_ticks
        )?;
        writeln!(
            f,
            "coupling k = {:.0} N/m, b = {:.1} N s/m{}: {}",
            self.k_npm,
            self.b_nspm,
            if self.searched {
                " (the stiffest proven)"
            } else {
                ""
            },
            if self.proven {
                "PROVEN against the host's loop"
            } else {
                "NOT proven against the host's loop"
            }
        )?;
        for p in &self.poses {
            let c = &p.check;
            writeln!(
                f,
                "  {}: margin {:.3} N s/m at {:.2} Hz; the body needs at least {:.3} N s/m of damping",
                p.model, c.min_margin_nspm, c.worst_frequency_hz, c.least_damping_nspm
            )?;
            if let Some(v) = &p.verify {
                writeln!(
                    f,
                    "    verify: {} (worst radius {:.9} per host period, {:.3}/s) with a hand of {:.3e} kg, {:.3e} N/m, {:.3e} N s/m ({} loops)",
                    if v.unstable { "UNSTABLE" } else { "nothing found" },
                    v.spectral_radius,
                    v.growth_per_s,
                    v.hand.mass_kg,
                    v.hand.stiffness_npm,
                    v.hand.damping_nspm,
                    v.evaluations
                )?;
            }
        }
        Ok(())
    }
}

pub(crate) fn host_ve(a: &HostVeArgs, _: Option<&DeviceAxis>) -> Reported {
    let h = a
        .host
        .get()?
        .ok_or("--host-body: give the host body's mass (kg) and damping (N s/m), e.g. 1,10")?;
    let d = designer(&a.common, None)?;
    let t = d.period_s();
    let (n, delay) = h.ticks(1.0 / t)?;
    let host = HostLoop::new(t, n, delay, (h.body.0, h.body.1, 0.0)).map_err(|e| e.to_string())?;
    let human = (!a.common.no_human).then_some(HumanBound::PAPER);
    let poses = d.poses();
    let err = |e: twoport_design::Error| e.to_string();
    let none = || "no coupling is proven against the host's loop".to_string();
    let (k, b, searched) = match (a.k, a.b) {
        (Some(k), Some(b)) => (gain("k", k)?, gain("b", b)?, false),
        (Some(_), None) => return Err("--k: give --b with it".into()),
        (None, b) => {
            let b = match b {
                Some(b) => gain("b", b)?,
                None => {
                    let best = d
                        .design_impedance(None, 0.0)
                        .map_err(err)?
                        .coupling
                        .ok_or_else(none)?;
                    host_best_pair(&poses[0].plant, human, &host, best.1)
                        .map_err(err)?
                        .ok_or_else(none)?
                        .1
                }
            };
            let mut k = f64::INFINITY;
            for p in poses {
                let kp = host_max_stiffness(&p.plant, b, human, &host)
                    .map_err(err)?
                    .ok_or_else(none)?;
                k = k.min(kp);
            }
            (k, b, true)
        }
    };
    let mut out = Vec::new();
    for p in poses {
        let check = check_host_ve(&p.plant, k, b, human, &host).map_err(err)?;
        let verify = if a.verify {
            Some(verify_host(&p.model, t, (k, b), human, &host).map_err(err)?)
        } else {
            None
        };
        out.push(PoseReport {
            model: p.model.name.clone(),
            check,
            verify,
        });
    }
    let report = HostVeReport {
        period_s: t,
        ve_period_ticks: n,
        delay_ticks: delay,
        body_mass_kg: h.body.0,
        body_damping_nspm: h.body.1,
        k_npm: k,
        b_nspm: b,
        searched,
        proven: out.iter().all(|p| p.check.proven),
        poses: out,
    };
    reported(report)
}
