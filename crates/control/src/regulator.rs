//! The admittance display's position regulator (paper eq 30).

use crate::{param, Integrator, ParamError, Position, ZTransfer};

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
pub struct PositionRegulator {
    kp: f32,
    bp: f32,
    period_s: f32,
    bp_over_t: f32,
    prev_error_nm: i32,
    /// The previous error's fraction of a nanometre.
    prev_fraction_nm: f32,
}

impl PositionRegulator {
    /// A regulator of stiffness `kp_npm` (N/m) and damping `bp_nspm`
    /// (N s/m), with zero error history.
    pub fn new(kp_npm: f32, bp_nspm: f32, period_s: f32) -> Result<Self, ParamError> {
        let t = param::positive("T (s)", period_s)?;
        let mut r = PositionRegulator {
            kp: 0.0,
            bp: 0.0,
            period_s: t,
            bp_over_t: 0.0,
            prev_error_nm: 0,
            prev_fraction_nm: 0.0,
        };
        r.set_gains(kp_npm, bp_nspm)?;
        Ok(r)
    }

    /// Change the gains; the error history is kept.
    pub fn set_gains(&mut self, kp_npm: f32, bp_nspm: f32) -> Result<(), ParamError> {
        self.kp = param::non_negative("k_p (N/m)", kp_npm)?;
        self.bp = param::non_negative("b_p (N s/m)", bp_nspm)?;
        self.bp_over_t = self.bp / self.period_s;
        Ok(())
    }

    /// Stiffness (N/m) and damping (N s/m).
    pub fn gains(&self) -> (f32, f32) {
        (self.kp, self.bp)
    }

    /// Set the remembered previous error to zero.
    pub fn reset(&mut self) {
        self.prev_error_nm = 0;
        self.prev_fraction_nm = 0.0;
    }

    /// The force (N) for actuator position `x_a` and the position command
    /// `x_cmd` (the integrator of Fig. 6, read with its remainder).
    #[inline]
    pub fn step(&mut self, x_a: Position, x_cmd: &Integrator) -> f32 {
        let (cmd, cmd_fraction_nm) = x_cmd.exact();
        let e = x_a - cmd;
        let fraction = -cmd_fraction_nm;
        let de = e.saturating_sub(self.prev_error_nm) as f32 + (fraction - self.prev_fraction_nm);
        self.prev_error_nm = e;
        self.prev_fraction_nm = fraction;
        const M_PER_NM: f32 = 1.0e-9;
        self.kp * ((e as f32 + fraction) * M_PER_NM) + self.bp_over_t * (de * M_PER_NM)
    }

    /// `K_p(z) = (k_p + b_p/T) - (b_p/T) z^-1`: force (N) per error (m).
    pub fn tf(&self) -> ZTransfer {
        let (kp, bt) = (self.kp as f64, self.bp_over_t as f64);
        ZTransfer::first_order([kp + bt, -bt], 0.0)
    }
}
