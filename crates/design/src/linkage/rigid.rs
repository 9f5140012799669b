//! The one-axis rigid bound a linkage's certificate rests on: every alias
//! of the handle with a passive hand lies in the disk of a rigid device of
//! the least damping (docs/linkages.md), so the certificate is that
//! device's bound, Colgate's with no latency and the designer's with one.

use super::file::LinkageFile;
use crate::model::Lag;

/// The hands-off (or least-grasp) boundary `2 (λ_min(D_x) + b_g - b_c)/T`.
#[derive(Clone, Copy)]
pub(super) struct Colgate<'a> {
    pub(super) file: &'a LinkageFile,
    pub(super) period_s: f64,
    pub(super) b_c_nspm: f64,
    pub(super) min_grasp_nspm: f64,
}

impl Colgate<'_> {
    pub(super) fn of(&self, damping_nspm: f64) -> Result<f64, crate::Error> {
        rigid_stiffness(self.file, damping_nspm + self.min_grasp_nspm, self.b_c_nspm)
    }

    /// [`of`](Self::of) a proven damping bound, rounded down by far more
    /// than its three operations' rounding: a proven stiffness bound.
    pub(super) fn proven(&self, damping_nspm: f64) -> Result<f64, crate::Error> {
        let k = self.of(damping_nspm)?;
        Ok(k - 1e-12 * k.abs())
    }
}

/// The stiffest coupling at damping `b_c_nspm` proven for a rigid
/// one-axis device of damping `damping_nspm` at the file's period and
/// latency (N/m). Every alias of the linkage's handle, with any passive
/// hand, lies in the disk a rigid device of its least damping gives, and
/// that disk does not depend on the mass (docs/linkages.md): so this is
/// the linkage's bound. With no latency it is Colgate's `2 (b - b_c)/T`;
/// with one, the designer's proof for that rigid device (its bound grows
/// with the damping, so the least damping binds). The device is scaled
/// to unit damping (a device, its coupling and its stiffness scaled
/// together keep their stability), so at `b_c = 0` the bound is exactly
/// proportional to the damping. The bound does not depend on the mass;
/// one whose time constant is a period keeps the grid's numbers tight
/// (a slow pole near DC leaves them 0.3% low at 10 kHz).
pub(super) fn rigid_stiffness(
    file: &LinkageFile,
    damping_nspm: f64,
    b_c_nspm: f64,
) -> Result<f64, crate::Error> {
    let lag = file.lag();
    if lag == Lag::NONE || damping_nspm <= b_c_nspm {
        return Ok(2.0 * (damping_nspm - b_c_nspm) / file.period_s);
    }
    let t = file.period_s;
    let scale = damping_nspm;
    let model = crate::DeviceModel::from_toml(
        &format!(
            "name = \"{} along its least damped direction\"\nperiod_s = {t:e}\n\
             peak_force_n = 1.0\ncontinuous_force_n = 1.0\ndelay_samples = {}\n\
             latency_s = {:e}\nM = [[{t:e}]]\nD = [[1.0]]\nK = [[0.0]]\n\
             G = [[1.0, -1.0]]\nC_v = [[1.0], [-1.0]]\n",
            file.name,
            lag.ticks,
            lag.fraction * t,
        ),
        &file.name,
    )
    .map_err(crate::Error::Model)?;
    let d = crate::Designer::new(vec![model], Some(t), None)?;
    d.design_impedance(Some(b_c_nspm / scale), 0.0)?
        .coupling
        .map(|(k, _)| k * scale)
        .ok_or_else(|| {
            crate::Error::Coupling(format!(
                "{}: no stiffness at b_c = {b_c_nspm} N s/m with the latency",
                file.name
            ))
        })
}

/// Why the paper's human bound is not proven on a linkage with a latency.
pub(super) fn latency_unsupported(file: &LinkageFile) -> crate::Error {
    crate::Error::Coupling(format!(
        "{}: the human bound's proof of a linkage takes no latency yet \
         (hands off, or with --min-grasp, it does)",
        file.name
    ))
}
