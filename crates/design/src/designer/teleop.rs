//! The designer's teleoperator: the proof of a four-channel law between
//! two devices, and the largest gain it allows.

use super::report::TeleopCheckReport;
use crate::analysis::{check_teleop, felt_at_low_frequency, teleop_range, TeleopAnalysis};
use crate::network::HumanBound;
use crate::verify::TeleopLaw;
use crate::{DeviceModel, Error};
use twoport_control::teleop::FourChannelGains;

/// A teleoperator's devices on one grid, the channel's delay and the
/// operator's bound: what every proof of a law between them shares.
#[derive(Clone, Debug)]
pub struct TeleopDesigner {
    analysis: TeleopAnalysis,
    delay_ticks: usize,
    human: Option<HumanBound>,
}

impl TeleopDesigner {
    /// `master` and `slave` (one period), `delay_ticks` each way, the
    /// operator within `human` (none: any passive operator).
    pub fn new(
        master: &DeviceModel,
        slave: &DeviceModel,
        delay_ticks: usize,
        human: Option<HumanBound>,
    ) -> Result<Self, Error> {
        Ok(TeleopDesigner {
            analysis: TeleopAnalysis::of(master, slave)?,
            delay_ticks,
            human,
        })
    }

    /// Prove Lawrence's four-channel law of `gains`.
    pub fn check(&self, gains: FourChannelGains) -> Result<TeleopCheckReport, Error> {
        self.check_law(TeleopLaw::FourChannel(gains))
    }

    /// Prove `law` (four channels or waves).
    pub fn check_law(&self, law: TeleopLaw) -> Result<TeleopCheckReport, Error> {
        let (master, slave) = (self.analysis.master(), self.analysis.slave());
        let tf = law
            .tf(master.period_s, self.delay_ticks)
            .map_err(Error::Teleop)?;
        Ok(TeleopCheckReport {
            master: master.name.clone(),
            slave: slave.name.clone(),
            period_s: master.period_s,
            delay_ticks: self.delay_ticks,
            human_bound: self.human.is_some(),
            law,
            check: check_teleop(&self.analysis, &tf, self.human)?,
            felt: felt_at_low_frequency(&teleop_range(&self.analysis, &tf)),
        })
    }

    /// What the operator feels through `law` at each grid frequency:
    /// `(ω, Z_free, Z_rigid)` (rad/s, N s/m; [`teleop_range`]).
    pub fn range(
        &self,
        law: TeleopLaw,
    ) -> Result<Vec<(f64, num_complex::Complex64, num_complex::Complex64)>, Error> {
        let period_s = self.analysis.master().period_s;
        let tf = law.tf(period_s, self.delay_ticks).map_err(Error::Teleop)?;
        Ok(teleop_range(&self.analysis, &tf))
    }

    /// The largest `x` up to `x_max` at which `gains_at(x)` is proven (to
    /// 0.1%), and its report: up by fours from `x_max` times 1e-8, then
    /// bisecting.
    /// `None` where none of those proves. The answer is itself proven,
    /// whatever the proofs do between the points tried.
    pub fn largest(
        &self,
        gains_at: impl Fn(f64) -> FourChannelGains,
        x_max: f64,
    ) -> Result<Option<(f64, TeleopCheckReport)>, Error> {
        self.largest_law(|x| TeleopLaw::FourChannel(gains_at(x)), x_max)
    }

    /// [`largest`](Self::largest) for any law: `law_at(x)` four channels
    /// or waves (the wave channel's largest proven impedance at a given
    /// filter).
    pub fn largest_law(
        &self,
        law_at: impl Fn(f64) -> TeleopLaw,
        x_max: f64,
    ) -> Result<Option<(f64, TeleopCheckReport)>, Error> {
        let at = |x: f64| self.check_law(law_at(x));
        let mut x = x_max * 1e-8;
        let mut best = None;
        while x <= x_max {
            let r = at(x)?;
            if !r.check.proven {
                break;
            }
            best = Some((x, r));
            x *= 4.0;
        }
        let Some(mut lo) = best.as_ref().map(|b| b.0) else {
            return Ok(None);
        };
        let mut hi = (4.0 * lo).min(x_max);
        if hi <= lo {
            return Ok(best);
        }
        if hi == x_max {
            let r = at(hi)?;
            if r.check.proven {
                return Ok(Some((hi, r)));
            }
        }
        while hi - lo > 1e-3 * lo {
            let mid = 0.5 * (lo + hi);
            let r = at(mid)?;
            if r.check.proven {
                (lo, best) = (mid, Some((mid, r)));
            } else {
                hi = mid;
            }
        }
        Ok(best)
    }
}
