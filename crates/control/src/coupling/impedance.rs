//! The impedance-display virtual coupling, a shunt spring-damper (eq 20).

use crate::ve::{Port, VeOutput, VirtualEnvironment};
use crate::{param, ParamError, Position, Real, ZTransfer};

/// `Z_cI(z) = b + kTz/(z - 1)` between the device and the VE (paper eq 20).
///
/// The device force command and the VE force are both `Z_cI (v_c - v_e)`.
/// The spring acts on the position error `x_c - x_e` (integer positions), so
/// it is the sum of velocities exactly and does not drift; with a fixed VE
/// the force is `k e + b (e - e_prev) / T` on the error `e`. The coupling
/// holds no position of its own: `x_e` is the VE's
/// ([`VirtualEnvironment::offset_m`]), the sum of the velocities the VE
/// returned, so the VE and the coupling can never disagree on where the VE
/// point is (and the tick integrates it once).
///
/// Sign: a positive force resists positive device motion (it is the
/// paper's actuator force `f_a`, which enters the device through `G` with a
/// minus sign), and pulls the VE along +x.
#[derive(Clone, Copy, Debug)]
pub struct ImpedanceCoupling<R = f32> {
    k: R,
    b: R,
    period_s: f32,
    z_direct: R,
}

/// One tick of the impedance coupling.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ImpedanceStep<R = f32> {
    /// Device force command `f_c` (N), equal to the VE force `f_e`.
    pub force_n: R,
    /// VE velocity `v_e` (m/s).
    pub ve_velocity_mps: R,
}

// The VE's answer is on the port's line, so its force is this tick's
// coupling force: f_c and f_e are one number.
impl<R> From<VeOutput<R>> for ImpedanceStep<R> {
    #[inline(always)]
    fn from(out: VeOutput<R>) -> Self {
        ImpedanceStep {
            force_n: out.force_n,
            ve_velocity_mps: out.velocity_mps,
        }
    }
}

impl ImpedanceCoupling {
    /// A coupling of stiffness `k_npm` (N/m) and damping `b_nspm` (N s/m) at
    /// period `period_s` (s). `kT + b` must be > 0.
    ///
    /// # Examples
    ///
    /// ```
    /// use twoport_control::ImpedanceCoupling;
    /// // The paper's impedance-display coupling at 1 kHz.
    /// let c = ImpedanceCoupling::new(51_000.0, 90.0, 1e-3)?;
    /// assert_eq!(c.gains(), (51_000.0, 90.0));
    /// // Z_cI(z) = b + kTz/(z - 1): at Nyquist (z = -1) it is b + kT/2.
    /// let nyq = c.tf().eval(twoport_control::Complex64::new(-1.0, 0.0));
    /// assert!((nyq.re - (90.0 + 25.5)).abs() < 1e-3);
    /// assert!(ImpedanceCoupling::new(-1.0, 90.0, 1e-3).is_err());
    /// # Ok::<(), twoport_control::ParamError>(())
    /// ```
    pub fn new(k_npm: f32, b_nspm: f32, period_s: f32) -> Result<Self, ParamError> {
        Self::new_in(k_npm, b_nspm, period_s)
    }
}

impl<R: Real> ImpedanceCoupling<R> {
    /// [`ImpedanceCoupling::new`] computing in `R`.
    pub fn new_in(k_npm: f32, b_nspm: f32, period_s: f32) -> Result<Self, ParamError> {
        let t = param::positive("T (s)", period_s)?;
        let mut c = ImpedanceCoupling {
            k: R::ZERO,
            b: R::ZERO,
            period_s: t,
            z_direct: R::ZERO,
        };
        c.set_gains(k_npm, b_nspm)?;
        Ok(c)
    }

    /// Change the gains; the state (the spring's stretch) is kept.
    pub fn set_gains(&mut self, k_npm: f32, b_nspm: f32) -> Result<(), ParamError> {
        let k = param::non_negative("k_c (N/m)", k_npm)?;
        let b = param::non_negative("b_c (N s/m)", b_nspm)?;
        // Derived in R, so an f64 law's constant is the f64 value of its
        // z-form; checked as the f32 the error reports.
        let (k, b) = (R::of(k), R::of(b));
        let z = k * R::of(self.period_s) + b;
        param::positive("k_c T + b_c (N s/m)", z.to_f32())?;
        (self.k, self.b, self.z_direct) = (k, b, z);
        Ok(())
    }

    /// Stiffness (N/m) and damping (N s/m).
    pub fn gains(&self) -> (f32, f32) {
        (self.k.to_f32(), self.b.to_f32())
    }

    /// One tick: device position `x_c` and its velocity estimate `v_c`
    /// (m/s) in, the VE solved exactly against the coupling, force out.
    // Always inlined: it runs once per tick, and an image with two servo
    // types (with and without a passivity layer) would otherwise share one
    // out-of-line copy and pay a call on the board's hot path.
    #[inline(always)]
    pub fn step<V: VirtualEnvironment<R> + ?Sized>(
        &mut self,
        x_c: Position,
        v_c_mps: R,
        ve: &mut V,
    ) -> ImpedanceStep<R> {
        let port = self.port(-ve.offset_m(x_c), v_c_mps);
        ImpedanceStep::from(ve.step(port))
    }

    /// This tick's law as the VE sees it, for the spring's stretch
    /// `x_c - x_e[k-1]` (m) and the device velocity `v_c` (m/s): what
    /// [`step`](Self::step) hands its VE, for a VE that several couplings
    /// share (one per axis) and that answers them all at once.
    #[inline(always)]
    pub fn port(&self, stretch_m: R, v_c_mps: R) -> Port<R> {
        // f = k (x_c - x_e[k-1] - T v_e) + b (v_c - v_e) = f0 - (kT + b) v_e
        Port {
            f0_n: self.k * stretch_m + self.b * v_c_mps,
            z_nspm: self.z_direct,
        }
    }

    /// `Z_cI(z) = ((b + kT) - b z^-1) / (1 - z^-1)`: force (N) per velocity
    /// difference `v_c - v_e` (m/s).
    pub fn tf(&self) -> ZTransfer {
        let (b, kt) = (self.b.to_f64(), self.k.to_f64() * self.period_s as f64);
        ZTransfer::first_order([b + kt, -b], -1.0)
    }
}
