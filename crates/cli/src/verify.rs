//! `twoport verify`: the counterexample search, over every pose.

use crate::args::*;
use crate::run::*;
use twoport_control::{AdmittanceGains as Adm, Gains, ImpedanceGains as Imp};
use twoport_design::DeviceAxis;

pub(crate) fn verify(
    d: &Display<ImpedanceGains, AdmittanceGains>,
    axis: Option<&DeviceAxis>,
) -> Reported {
    if let Display::Impedance(ImpedanceGains {
        min_grasp: Some(g), ..
    }) = d
    {
        return Err(format!(
            "--min-grasp {g}: a grasp's least damping is searched on linkage devices (--device LINKAGE) only"
        ));
    }
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
    reported(
        designer(common, axis)?
            .verify(&gains)
            .map_err(|e| e.to_string())?,
    )
}

/// `verify impedance --device LINKAGE`: the search on the exact discrete
/// loop of the linearised linkage, at the binding pose of the workspace
/// design under the same hand assumption and at every tenth pose.
pub(crate) fn verify_linkage(a: &ImpedanceGains) -> Reported {
    use twoport_design::linkage::{
        certified_design, verify_linkage, HandAssumption, PoseDynamics, DESIGN_GRID,
    };
    use twoport_design::network::HumanBound;
    let file = linkage_file(&a.common)?;
    let (k, b) = (gain("k", a.k)?, gain("b", a.b)?);
    let grasp = match a.min_grasp {
        Some(g) if !(g.is_finite() && g >= 0.0) => {
            return Err(format!(
                "--min-grasp {g}: must be a finite damping >= 0 N s/m"
            ))
        }
        g => g.unwrap_or(0.0),
    };
    let human = (!a.common.no_human && a.min_grasp.is_none()).then_some(HumanBound::PAPER);
    // The certificate's binding pose leads, then the corners of the box
    // that binds it, then every tenth pose of a grid.
    let d = certified_design(&file, 0.0, grasp, human).map_err(|e| e.to_string())?;
    let mut sample: Vec<PoseDynamics> = vec![d.binding.pose.clone()];
    if let Some(c) = &d.certificate {
        let n = c.binding_box_rad.len();
        for bits in 0..1usize << n {
            let q: Vec<f64> = (0..n)
                .map(|i| c.binding_box_rad[i][(bits >> i) & 1])
                .collect();
            if file.within_limits(&q) {
                sample.extend(file.pose(&q).ok());
            }
        }
    }
    sample.extend(file.workspace(DESIGN_GRID).into_iter().step_by(10));
    let sample: Vec<&PoseDynamics> = sample.iter().collect();
    let assumption = HandAssumption {
        min_grasp_nspm: grasp,
        human,
    };
    let v = verify_linkage(&sample, &assumption, (k, b), (file.period_s, file.lag()))
        .ok_or("no pose could be searched")?;
    reported(v)
}
