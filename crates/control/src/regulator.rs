//! The admittance display's position regulator (paper eq 30).

#[cfg(doc)]
use crate::Integrator;
use crate::{param, ParamError, Position, Real, ZTransfer};

/// `K_p(z) = k_p + b_p (1 - z^-1) / T`: actuator force (N) from the position
/// error `e = x_a - x_cmd` (m), a positive force resisting positive
/// actuator motion. By eq 30 the impedance-display coupling that the designer
/// finds is this regulator: `k_p = k_cI`, `b_p = b_cI`.
///
/// The command comes as whole nanometres plus a part in nanometres (the
/// command integrator's state, see [`Integrator::step_unsplit`]), and the
/// error and its first difference are taken the same way: integers for the
/// whole part, so the derivative term has no cancellation error beyond the
/// rounding of the small part, and the regulator sees the command's exact
/// state (rounded to the nanometre, its 1 nm steps would be a 0.1 mN ripple
/// at Nyquist, 1e-4 of the response there).
#[derive(Clone, Copy, Debug)]
pub struct PositionRegulator<R = f32> {
    kp: R,
    bp: f32,
    period_s: f32,
    bp_over_t: R,
    prev_error_nm: i32,
    /// The previous error's part beyond its whole nanometres (nm).
    prev_part_nm: R,
}

impl PositionRegulator {
    /// A regulator of stiffness `kp_npm` (N/m) and damping `bp_nspm`
    /// (N s/m), with zero error history.
    ///
    /// # Examples
    ///
    /// ```
    /// use twoport_control::PositionRegulator;
    /// let k = PositionRegulator::new(51_000.0, 90.0, 1e-3)?;
    /// // K_p(z) = k_p + b_p (1 - z^-1)/T: at DC it is the stiffness.
    /// let dc = k.tf().eval(twoport_control::Complex64::new(1.0, 0.0));
    /// assert!((dc.re - 51_000.0).abs() < 1e-6);
    /// assert!(PositionRegulator::new(-1.0, 90.0, 1e-3).is_err());
    /// # Ok::<(), twoport_control::ParamError>(())
    /// ```
    pub fn new(kp_npm: f32, bp_nspm: f32, period_s: f32) -> Result<Self, ParamError> {
        Self::new_in(kp_npm, bp_nspm, period_s)
    }
}

impl<R: Real> PositionRegulator<R> {
    /// [`PositionRegulator::new`] computing in `R`.
    pub fn new_in(kp_npm: f32, bp_nspm: f32, period_s: f32) -> Result<Self, ParamError> {
        let t = param::positive("T (s)", period_s)?;
        let mut r = PositionRegulator {
            kp: R::ZERO,
            bp: 0.0,
            period_s: t,
            bp_over_t: R::ZERO,
            prev_error_nm: 0,
            prev_part_nm: R::ZERO,
        };
        r.set_gains(kp_npm, bp_nspm)?;
        Ok(r)
    }

    /// Change the gains; the error history is kept.
    pub fn set_gains(&mut self, kp_npm: f32, bp_nspm: f32) -> Result<(), ParamError> {
        self.kp = R::of(param::non_negative("k_p (N/m)", kp_npm)?);
        self.bp = param::non_negative("b_p (N s/m)", bp_nspm)?;
        self.bp_over_t = R::of(self.bp) / R::of(self.period_s);
        Ok(())
    }

    /// Stiffness (N/m) and damping (N s/m).
    pub fn gains(&self) -> (f32, f32) {
        (self.kp.to_f32(), self.bp)
    }

    /// Set the remembered previous error to zero.
    pub fn reset(&mut self) {
        self.prev_error_nm = 0;
        self.prev_part_nm = R::ZERO;
    }

    /// The force (N) for actuator position `x_a` and the position command
    /// `x_cmd + x_cmd_part_nm` (the integrator of Fig. 6, from
    /// [`Integrator::step_unsplit`] or [`Integrator::exact`]).
    #[inline]
    pub fn step(&mut self, x_a: Position, (x_cmd, x_cmd_part_nm): (Position, R)) -> R {
        let e = x_a - x_cmd;
        let part = -x_cmd_part_nm;
        let de = R::from_i32(e.saturating_sub(self.prev_error_nm)) + (part - self.prev_part_nm);
        self.prev_error_nm = e;
        self.prev_part_nm = part;
        self.kp * ((R::from_i32(e) + part) * R::M_PER_NM) + self.bp_over_t * (de * R::M_PER_NM)
    }

    /// `K_p(z) = (k_p + b_p/T) - (b_p/T) z^-1`: force (N) per error (m).
    pub fn tf(&self) -> ZTransfer {
        let (kp, bt) = (self.kp.to_f64(), self.bp_over_t.to_f64());
        ZTransfer::first_order([kp + bt, -bt], 0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Integrator;

    /// Fed the command integrator's unsplit answer or its split state, the
    /// regulator gives the same force to f32 rounding, tick after tick,
    /// through fast and slow, large and sub-nanometre command steps.
    #[test]
    fn unsplit_and_split_commands_give_the_same_force() {
        let t = 1.0e-3;
        let mut cmd = Integrator::new(t, Position::from_nm(1_000));
        let (mut a, mut b) = (
            PositionRegulator::new(51_000.0, 90.0, t).unwrap(),
            PositionRegulator::new(51_000.0, 90.0, t).unwrap(),
        );
        for k in 0..20_000 {
            let s = k as f32 * 1e-3;
            let v = 0.5 * (7.0 * s).sin() + 2e-7 * (k % 3) as f32;
            let x_a = Position::from_nm((3e5 * (5.0 * s).cos()) as i32);
            let unsplit = cmd.step_unsplit(v);
            let (fa, fb) = (a.step(x_a, unsplit), b.step(x_a, cmd.exact()));
            assert!(
                (fa - fb).abs() <= 2e-6 * fb.abs() + 1e-4,
                "tick {k}: {fa} vs {fb}"
            );
        }
    }
}
