//! `twoport verify`: the counterexample search, over every pose.

use crate::args::*;
use crate::session::*;
use serde_json::json;
use twoport_design::DeviceModel;

pub(crate) fn verify(d: &Display<ImpedanceGains, AdmittanceGains>) -> Result<(), String> {
    use twoport_control::{AdmittanceGains as Adm, Gains, ImpedanceGains as Imp};
    use twoport_design::verify;
    // The board's f32 gains: the laws are built from them either way.
    let (common, gains) = match d {
        Display::Impedance(g) => (
            &g.common,
            Gains::from(Imp::new(gain("k", g.k)? as f32, gain("b", g.b)? as f32)),
        ),
        Display::Admittance(g) => {
            if !(g.m.is_finite() && g.m > 0.0) {
                return Err(format!("--m {}: must be a finite mass > 0 kg", g.m));
            }
            (
                &g.common,
                Gains::from(Adm::new(
                    gain("kp", g.kp)? as f32,
                    gain("bp", g.bp)? as f32,
                    g.m as f32,
                    gain("b", g.b)? as f32,
                )),
            )
        }
    };
    let s = Session::open(common)?;
    if matches!(gains, Gains::Admittance(_)) {
        s.force_sensor()?;
    }
    let (period, human) = (s.period(), s.human);
    let mut worst: Option<(verify::Verdict, &DeviceModel)> = None;
    let mut evaluations = 0;
    for p in &s.poses {
        let v = verify::verify(
            &p.model,
            period,
            &gains,
            human,
            p.model.delay_samples as usize,
        )
        .map_err(|e| format!("{}: {e}", p.model.name))?;
        evaluations += v.evaluations;
        if worst
            .as_ref()
            .is_none_or(|w| (v.unstable, v.spectral_radius) > (w.0.unstable, w.0.spectral_radius))
        {
            worst = Some((v, &p.model));
        }
    }
    let (mut v, model) = worst.ok_or("no pose to verify")?;
    v.evaluations = evaluations;
    let display = match d {
        Display::Impedance(_) => "impedance",
        Display::Admittance(_) => "admittance",
    };
    let mut out = serde_json::to_value(v).map_err(|e| e.to_string())?;
    out["display"] = json!(display);
    if s.poses.len() > 1 {
        out["worst_pose"] = json!(model.name);
    }
    out["human_model"] = json!(human.is_some());
    out["period_s"] = json!(period);
    if common.json {
        println!("{out}");
    } else {
        println!(
            "{display} display, {} at T = {} ms: {} closed loops searched",
            s.name(),
            period * 1e3,
            v.evaluations
        );
        let verdict = if v.unstable {
            "UNSTABLE: a passive termination breaks these gains"
        } else {
            "no counterexample found"
        };
        let growth = if v.growth_per_s > 0.0 {
            format!("grows by e every {:.3e} s", 1.0 / v.growth_per_s)
        } else {
            format!("decays by e every {:.3e} s", -1.0 / v.growth_per_s)
        };
        println!(
            "  {verdict}; worst spectral radius 1 {:+.3e} at {:.2} Hz ({growth})",
            v.spectral_radius - 1.0,
            v.frequency_hz
        );
        println!(
            "  worst termination: {}",
            serde_json::to_string(&v.termination).unwrap_or_default()
        );
    }
    Ok(())
}
