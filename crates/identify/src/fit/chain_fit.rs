//! The fit of a chain of masses: started from Cauer's ladder, free or
//! held to the frame, its dampers first, then every parameter.

use super::body::{ground_shown, rigid_estimate};
use super::chain::{self, Chain, ModelBase};
use super::features::features;
use super::{finish, ladder, lm, residuals, Fit, Form, Measured};
use crate::frf::Frf;
use nalgebra::DVector;
use std::f64::consts::TAU;

/// Fit a chain of `modes` modes, held to the frame at mass `ground_at`
/// if given, or `None` where the measurement shows fewer resonances or
/// the search finds no model. A load cell, if measured, is the chain's
/// last spring: a flexure in the band.
pub fn fit_chain(
    data: &Measured,
    base: &ModelBase,
    modes: usize,
    ground_at: Option<usize>,
) -> Option<Fit> {
    if ground_at.is_some_and(|at| at > modes) {
        return None;
    }
    let x = &data.position;
    let (k_g, m_t, d_t) = match ground_at {
        None => {
            let (m, d) = rigid_estimate(x, base.period_s)?;
            (0.0, m, d)
        }
        Some(_) => ground_shown(x, base.period_s)?,
    };
    // At low frequency the load cell reads the force that accelerates the
    // handle's mass, `-sign m_h/m_t` of the push (the acceleration per
    // push has a positive real part, whatever the damping).
    let sign = match &data.load_cell {
        Some(lc) if lc.response.iter().take(5).map(|h| h.re).sum::<f64>() > 0.0 => -1.0,
        _ => 1.0,
    };
    let ground = ground_at.map(|at| chain::Ground { at, npm: k_g });
    let start = if modes == 0 {
        Chain {
            masses_kg: vec![m_t],
            springs_npm: vec![],
            links_nspm: vec![],
            actuator_nspm: d_t,
            handle_nspm: 0.0,
            load_cell_sign: 1.0,
            ground,
        }
    } else {
        let (l, ground) = ladder_start(x, modes, ground_at, k_g, m_t)?;
        let links = (0..l.springs_npm.len())
            .map(|i| {
                let (a, b) = (l.masses_kg[i], l.masses_kg[i + 1]);
                2.0 * 0.03 * (l.springs_npm[i] * a * b / (a + b)).sqrt()
            })
            .collect();
        // The damping to ground starts at the actuator: at the handle it
        // would show in a load cell at low frequency, where the handle's
        // mass alone does.
        Chain {
            masses_kg: l.masses_kg,
            springs_npm: l.springs_npm,
            links_nspm: links,
            actuator_nspm: d_t,
            handle_nspm: 1e-3 * d_t,
            load_cell_sign: sign,
            ground,
        }
    };
    let masses = start.masses_kg.len();
    let model = |p: &DVector<f64>| Chain::from_log(masses, ground_at, p, sign).model(base);
    // With the encoder alone nothing shows where along the chain the
    // damping to ground acts, and a damper started near zero stays there
    // (its logarithm's gradient is as small): it is started also shared
    // in proportion to the masses, and the better fit kept.
    let mut starts = vec![start.clone()];
    if data.load_cell.is_none() && masses > 1 {
        let share = start.masses_kg[masses - 1] / start.masses_kg.iter().sum::<f64>();
        starts.push(Chain {
            actuator_nspm: d_t * (1.0 - share),
            handle_nspm: d_t * share,
            ..start
        });
    }
    // First the dampers alone, the frequencies held where the ladder put
    // them (a guessed damping is what a start gets most wrong), then all.
    let fixed = masses + (masses - 1);
    let dampers = masses.min(2) + (masses - 1);
    starts
        .iter()
        .filter_map(|c| {
            let p0 = c.to_log();
            let damped = lm::minimise(
                |d| {
                    let mut p = p0.clone();
                    p.rows_mut(fixed, d.len()).copy_from(d);
                    model(&p).and_then(|m| residuals(&m, data, &[]))
                },
                p0.rows(fixed, dampers).into_owned(),
                50,
            )?;
            let mut p1 = p0.clone();
            p1.rows_mut(fixed, damped.p.len()).copy_from(&damped.p);
            finish(data, base, p1, model, |p| {
                Form::Chain(Chain::from_log(masses, ground_at, p, sign))
            })
        })
        .min_by(|a, b| a.chi2.total_cmp(&b.chi2))
}

/// The chain's masses and springs from the record's features: free or
/// held at the actuator, the free chain's ladder (the spring taken out of
/// the record's dynamic stiffness); held further along, the ladder held at
/// its far end, the spring moved to `ground_at`. `k_g` and `m_t` are the
/// low harmonics' spring (N/m) and mass (kg).
fn ladder_start(
    x: &Frf,
    modes: usize,
    ground_at: Option<usize>,
    k_g: f64,
    m_t: f64,
) -> Option<(ladder::Ladder, Option<chain::Ground>)> {
    let ground = ground_at.map(|at| chain::Ground { at, npm: k_g });
    let w = |i: &usize| TAU * x.freq_hz[*i];
    let (l, ground) = match ground_at {
        // Held at the actuator: the free chain's features, the spring
        // taken out of the record's dynamic stiffness.
        None | Some(0) => {
            let free;
            let x = if k_g > 0.0 {
                free = Frf {
                    response: x.response.iter().map(|h| 1.0 / (1.0 / h - k_g)).collect(),
                    ..x.clone()
                };
                &free
            } else {
                x
            };
            let (anti, res) = features(x, modes)?;
            let anti: Vec<f64> = anti.iter().map(w).collect();
            let res: Vec<f64> = res.iter().map(w).collect();
            (ladder::synthesise(m_t, &anti, &res)?, ground)
        }
        // Held further along: the record's own resonances (one more
        // than the modes: the chain's on the spring) give the chain
        // held at the handle, and a spring held nearer the actuator
        // starts there too.
        Some(at) => {
            let (anti, res) = features(x, modes + 1)?;
            let anti: Vec<f64> = anti[1..].iter().map(w).collect();
            let res: Vec<f64> = res.iter().map(w).collect();
            let (l, end) = ladder::synthesise_held(k_g, &anti, &res)?;
            (l, Some(chain::Ground { at, npm: end }))
        }
    };
    Some((l, ground))
}
