//! The admittance display's position regulator (paper eq 30).

use crate::{param, Integrator, ParamError, Position, Real, ZTransfer};

/// `K_p(z) = k_p + b_p (1 - z^-1) / T`: actuator force (N) from the position
/// error `e = x_a - x_cmd` (m), a positive force resisting positive
/// actuator motion. By eq 30 the impedance-display coupling that the designer
/// finds is this regulator: `k_p = k_cI`, `b_p = b_cI`.
///
/// The error and its first difference are taken in integer nanometres plus
/// the command's sub-nanometre remainder, so the derivative term has no
/// cancellation error and the regulator sees the command integrator's exact
/// state (rounded to the nanometre, its 1 nm steps would be a 0.1 mN ripple
/// at Nyquist, 1e-4 of the response there).
#[derive(Clone, Copy, Debug)]
pub struct PositionRegulator<R = f32> {
    kp: R,
    bp: f32,
    period_s: f32,
    bp_over_t: R,
    prev_error_nm: i32,
    /// The previous error's fraction of a nanometre.
    prev_fraction_nm: R,
}

impl PositionRegulator {
    /// A regulator of stiffness `kp_npm` (N/m) and damping `bp_nspm`
    /// (N s/m), with zero error history.
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
            prev_fraction_nm: R::ZERO,
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
        self.prev_fraction_nm = R::ZERO;
    }

    /// The force (N) for actuator position `x_a` and the position command
    /// `x_cmd` (the integrator of Fig. 6, read with its remainder).
    #[inline]
    pub fn step(&mut self, x_a: Position, x_cmd: &Integrator<R>) -> R {
        let (cmd, cmd_fraction_nm) = x_cmd.exact();
        let e = x_a - cmd;
        let fraction = -cmd_fraction_nm;
        let de =
            R::from_i32(e.saturating_sub(self.prev_error_nm)) + (fraction - self.prev_fraction_nm);
        self.prev_error_nm = e;
        self.prev_fraction_nm = fraction;
        self.kp * ((R::from_i32(e) + fraction) * R::M_PER_NM) + self.bp_over_t * (de * R::M_PER_NM)
    }

    /// `K_p(z) = (k_p + b_p/T) - (b_p/T) z^-1`: force (N) per error (m).
    pub fn tf(&self) -> ZTransfer {
        let (kp, bt) = (self.kp.to_f64(), self.bp_over_t.to_f64());
        ZTransfer::first_order([kp + bt, -bt], 0.0)
    }
}
