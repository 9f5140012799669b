//! What a fit does not know, as a set of models: the fitted model and,
//! along each principal direction of its parameters' covariance, the
//! models `κ` standard deviations either side, each with its damping
//! lowered by a stated doubt. A design proven for every model of the set
//! (as poses) holds for the device wherever the truth lies within that
//! many deviations along those directions, and has no less damping than
//! that.
//!
//! The covariance is the fit's ([`Fit::covariance`]): the measured
//! variance of each harmonic (what the coherence says), inflated by the
//! misfit where the model explains the data worse than their noise. The
//! parameters are logarithms, so a step is a relative change, and every
//! model of the set stays physical.

use super::Fit;
use nalgebra::{DMatrix, DVector, SymmetricEigen};
use twoport_design::DeviceModel;

/// How far the set reaches beyond the fit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Doubt {
    /// Standard deviations either side of the fit along each principal
    /// direction.
    pub sigmas: f64,
    /// The fraction by which every model of the set has its damping
    /// matrix `D` lowered. The noise does not bound what is systematic:
    /// damping depends on amplitude (friction before it slides is read as
    /// damping), and a lightly damped mode's damping is what bounds the
    /// stiffness a coupling may have, nearly in proportion.
    pub damping: f64,
}

impl Default for Doubt {
    /// 3 standard deviations (99.7% of each direction taken alone), and
    /// 5% of the damping: on the simulated Excalibur, friction read as
    /// damping raised the fitted modes' damping by up to 4%.
    fn default() -> Self {
        Doubt {
            sigmas: 3.0,
            damping: 0.05,
        }
    }
}

/// One model of the set: where it lies, and its model file.
#[derive(Clone, Debug)]
pub struct Member {
    /// The principal direction (`None` for the fit itself).
    pub direction: Option<usize>,
    /// Standard deviations along it (signed).
    pub sigmas: f64,
    /// The step along it: the largest change of any one parameter (for a
    /// logarithm, about the relative change).
    pub step: f64,
    /// The model.
    pub model: DeviceModel,
}

/// The fitted model, then the models `doubt.sigmas` standard deviations
/// either side of it along each principal direction of the covariance
/// whose step changes some parameter by more than `1e-6` (the others move
/// no design), every one with its damping lowered by `doubt.damping`.
/// Directions that make no valid model are left out. `None` if the
/// covariance or the doubt is not finite, or the damping doubt is not a
/// fraction below one.
pub fn span(fit: &Fit, doubt: Doubt) -> Option<Vec<Member>> {
    let k = fit.params.len();
    let c: DMatrix<f64> = fit.covariance.view((0, 0), (k, k)).into_owned();
    let kappa = doubt.sigmas;
    let sound = c.iter().all(|v| v.is_finite())
        && kappa.is_finite()
        && kappa >= 0.0
        && (0.0..1.0).contains(&doubt.damping);
    if !sound {
        return None;
    }
    let lower = |mut m: DeviceModel| {
        m.d *= 1.0 - doubt.damping;
        m
    };
    let eig = SymmetricEigen::new((&c + c.transpose()) * 0.5);
    let mut set = vec![Member {
        direction: None,
        sigmas: 0.0,
        step: 0.0,
        model: lower(fit.model.clone()),
    }];
    let mut order: Vec<usize> = (0..k).collect();
    order.sort_by(|a, b| eig.eigenvalues[*b].total_cmp(&eig.eigenvalues[*a]));
    for (d, &i) in order.iter().enumerate() {
        let sd = eig.eigenvalues[i].max(0.0).sqrt();
        let v: DVector<f64> = eig.eigenvectors.column(i) * sd;
        let step = kappa * v.amax();
        if step < 1e-6 {
            continue;
        }
        for s in [kappa, -kappa] {
            if let Some(model) = fit.model_at(&(&fit.params + &v * s)) {
                set.push(Member {
                    direction: Some(d),
                    sigmas: s,
                    step,
                    model: lower(model),
                });
            }
        }
    }
    Some(set)
}
