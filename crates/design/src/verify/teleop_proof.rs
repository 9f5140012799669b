//! The proof's own worst operator and environment, built and run: where
//! the teleoperator's proof fails at a frequency, the hands that zero its
//! determinant there, each realised at the base band as a lumped mass,
//! spring or damper, and the exact loop checked with them. A sweep of
//! lumped terminations misses what the proof finds by a few per cent on
//! flexible devices; these hands are where to look.

use super::teleop::{teleop_radius, verify_teleop, TeleopTermination, TeleopVerdict, Teleoperator};
use super::{Hand, Radius};
use crate::analysis::{closing_hands, teleop_slack, TeleopAnalysis};
use num_complex::Complex64;
use twoport_control::teleop::TeleopTransfer;

/// How many of the proof's worst local minima are built.
const MINIMA: usize = 6;

/// A lumped hand with admittance `y` (m/s per N) at `omega` (rad/s):
/// the real part a damper, the imaginary a mass or a spring; a handle
/// held still (`y` = 0) a stiff spring.
fn realise(y: Complex64, omega: f64) -> Hand {
    if y.norm() < 1e-12 {
        return Hand {
            stiffness_npm: 1e8,
            ..Hand::OFF
        };
    }
    let z = 1.0 / y;
    Hand {
        mass_kg: z.im.max(0.0) / omega,
        stiffness_npm: (-z.im).max(0.0) * omega,
        damping_nspm: z.re.max(0.0),
        ..Hand::OFF
    }
}

/// [`verify_teleop`]'s sweep and the proof's closing hands at its worst
/// local minima (each and its neighbours): the worst of both. Any
/// operator the sweep builds is passive and what it finds is real, as for
/// the sweep alone.
pub fn verify_teleop_near_proof(
    ta: &TeleopAnalysis,
    law: &TeleopTransfer,
) -> Result<TeleopVerdict, String> {
    let t = Teleoperator {
        master: ta.master(),
        slave: ta.slave(),
        law: *law,
    };
    let mut verdict = verify_teleop(&t)?;
    let slack = teleop_slack(ta, law, None).map_err(|e| e.to_string())?;
    // (Nyquist, the grid's last point, is a minimum where it binds.)
    let n = slack.len();
    let mut minima: Vec<usize> = (0..n)
        .filter(|&i| {
            slack[i] < 0.0
                && (i == 0 || slack[i] <= slack[i - 1])
                && (i + 1 == n || slack[i] <= slack[i + 1])
        })
        .collect();
    minima.sort_by(|a, b| slack[*a].total_cmp(&slack[*b]));
    let omegas: Vec<f64> = ta.omegas().collect();
    let mut worst: Option<(Radius, TeleopTermination)> = None;
    for i in minima
        .into_iter()
        .take(MINIMA)
        .flat_map(|i| [i - 1, i, i + 1])
    {
        let Some([operator, environment]) = closing_hands(ta, law, i) else {
            continue;
        };
        // The hands put a pole on the circle; with less of their loss it
        // moves out, where the proof's slack says the disks reach past.
        for loss in [1.0, 0.5, 0.0] {
            let lossy = |y: Complex64| {
                let mut h = realise(y, omegas[i]);
                h.damping_nspm *= loss;
                h
            };
            let term = TeleopTermination {
                operator: lossy(operator),
                environment: lossy(environment),
            };
            let r = teleop_radius(&t, &term)?;
            verdict.evaluations += 1;
            if worst.as_ref().is_none_or(|(w, _)| r.score > w.score) {
                worst = Some((r, term));
            }
        }
    }
    if let Some((r, termination)) = worst {
        let worse = if r.unstable == verdict.unstable {
            r.score > verdict.spectral_radius
        } else {
            r.unstable
        };
        if worse {
            verdict = TeleopVerdict {
                unstable: r.unstable,
                spectral_radius: r.spectral_radius,
                frequency_hz: r.frequency_hz,
                termination,
                evaluations: verdict.evaluations,
            };
        }
    }
    Ok(verdict)
}
