//! The admittance-display virtual coupling, a mass and a damper whose
//! admittances add (eq 21).

use crate::ve::{Port, VeOutput, VirtualEnvironment};
use crate::{param, ParamError, Real, ZTransfer};

/// `Z_cA(z) = m b (z - 1) / ((m + bT) z - m)` (paper eq 21), i.e.
/// `1/Z_cA = 1/b + Tz/(m(z - 1))`: a damper `b` in series with a mass `m`.
///
/// In the admittance display the VE and the coupling share one velocity,
/// the display's velocity command `v_c = v_e`, and the measured handle force
/// `f_c` divides between them: `f_e = f_c - Z_cA v_e`. The coupling's
/// direct feedthrough `m b / (m + bT)` closes an algebraic loop with an
/// admittance VE; it is solved exactly through [`Port`].
#[derive(Clone, Copy, Debug)]
pub struct AdmittanceCoupling<R = f32> {
    m: f32,
    b: f32,
    period_s: f32,
    t_over_m: R,
    z_direct: R,
    /// Velocity of the coupling's mass (m/s).
    mass_velocity_mps: R,
}

/// One tick of the admittance coupling.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AdmittanceStep<R = f32> {
    /// Velocity command to the display, `v_c = v_e` (m/s).
    pub velocity_mps: R,
    /// Force on the VE, `f_e` (N).
    pub ve_force_n: R,
    /// Force taken by the coupling, `f_c - f_e = Z_cA v_e` (N).
    pub coupling_force_n: R,
}

impl AdmittanceCoupling {
    /// A coupling of mass `m_kg` (kg) and damping `b_nspm` (N s/m), at rest.
    ///
    /// # Examples
    ///
    /// ```
    /// use twoport_control::AdmittanceCoupling;
    /// // The paper's admittance-display coupling: 5 kg and 500 N s/m at 1 kHz.
    /// let c = AdmittanceCoupling::new(5.0, 500.0, 1e-3)?;
    /// assert_eq!(c.gains(), (5.0, 500.0));
    /// assert!(AdmittanceCoupling::new(0.0, 500.0, 1e-3).is_err()); // a mass > 0
    /// # Ok::<(), twoport_control::ParamError>(())
    /// ```
    pub fn new(m_kg: f32, b_nspm: f32, period_s: f32) -> Result<Self, ParamError> {
        Self::new_in(m_kg, b_nspm, period_s)
    }
}

impl<R: Real> AdmittanceCoupling<R> {
    /// [`AdmittanceCoupling::new`] computing in `R`.
    pub fn new_in(m_kg: f32, b_nspm: f32, period_s: f32) -> Result<Self, ParamError> {
        let t = param::positive("T (s)", period_s)?;
        let mut c = AdmittanceCoupling {
            m: 1.0,
            b: 1.0,
            period_s: t,
            t_over_m: R::ZERO,
            z_direct: R::ZERO,
            mass_velocity_mps: R::ZERO,
        };
        c.set_gains(m_kg, b_nspm)?;
        Ok(c)
    }

    /// Change the gains; the mass keeps its velocity.
    pub fn set_gains(&mut self, m_kg: f32, b_nspm: f32) -> Result<(), ParamError> {
        let m = param::positive("m_c (kg)", m_kg)?;
        let b = param::positive("b_c (N s/m)", b_nspm)?;
        // Derived in R, so an f64 law's constants are the f64 values of its
        // z-form; checked as the f32 the error reports.
        let (mr, br, t) = (R::of(m), R::of(b), R::of(self.period_s));
        let z = mr * br / (mr + br * t);
        param::positive("m_c b_c / (m_c + b_c T) (N s/m)", z.to_f32())?;
        (self.m, self.b) = (m, b);
        (self.t_over_m, self.z_direct) = (t / mr, z);
        Ok(())
    }

    /// Mass (kg) and damping (N s/m).
    pub fn gains(&self) -> (f32, f32) {
        (self.m, self.b)
    }

    /// Bring the coupling's mass to rest.
    pub fn reset(&mut self) {
        self.mass_velocity_mps = R::ZERO;
    }

    /// One tick: the measured handle force `f_c` (N) in, the VE solved
    /// exactly against the coupling, the display's velocity command out.
    pub fn step<V: VirtualEnvironment<R> + ?Sized>(
        &mut self,
        f_c_n: R,
        ve: &mut V,
    ) -> AdmittanceStep<R> {
        let out = ve.step(self.port(f_c_n));
        self.finish(f_c_n, out)
    }

    /// This tick's law as the VE sees it, for the measured handle force
    /// `f_c` (N): what [`step`](Self::step) hands its VE, for a VE that
    /// several couplings share (one per axis). Give the VE's answer to
    /// [`finish`](Self::finish).
    #[inline(always)]
    pub fn port(&self, f_c_n: R) -> Port<R> {
        // Coupling force Z_cA v = z (v - v_mass[k-1]); the VE gets the rest.
        Port {
            f0_n: f_c_n + self.z_direct * self.mass_velocity_mps,
            z_nspm: self.z_direct,
        }
    }

    /// Complete the tick [`port`](Self::port) began with the VE's answer
    /// `out` on that port.
    #[inline(always)]
    pub fn finish(&mut self, f_c_n: R, out: VeOutput<R>) -> AdmittanceStep<R> {
        let coupling = self.z_direct * (out.velocity_mps - self.mass_velocity_mps);
        let vm = self.mass_velocity_mps + self.t_over_m * coupling;
        if vm.is_finite() {
            self.mass_velocity_mps = vm;
        }
        AdmittanceStep {
            velocity_mps: out.velocity_mps,
            ve_force_n: f_c_n - coupling,
            coupling_force_n: coupling,
        }
    }

    /// `Z_cA(z) = m b (1 - z^-1) / ((m + bT) - m z^-1)`: coupling force (N)
    /// per velocity (m/s).
    pub fn tf(&self) -> ZTransfer {
        let (m, b, t) = (self.m as f64, self.b as f64, self.period_s as f64);
        let d = m + b * t;
        ZTransfer::first_order([m * b / d, -m * b / d], -m / d)
    }
}
