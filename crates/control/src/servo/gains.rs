//! The gains of either display, as one value: what a scene file, a slider
//! and a link message all carry to a servo (with the `serde` feature,
//! the link's and the flash record's encoding).

use crate::ParamError;
use core::fmt;

/// Which display a servo runs (paper Figs. 5 and 6). With the `serde`
/// feature it reads from a file as `impedance` or `admittance`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Deserialize),
    serde(rename_all = "snake_case")
)]
pub enum Display {
    /// Measure motion, command force (Fig. 5).
    Impedance,
    /// Measure force, command motion (Fig. 6).
    Admittance,
}

impl fmt::Display for Display {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Display::Impedance => "impedance",
            Display::Admittance => "admittance",
        })
    }
}

/// The impedance display's coupling `Z_cI` (paper eq 20).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct ImpedanceGains {
    /// Coupling stiffness `k_c` (N/m).
    pub k_npm: f32,
    /// Coupling damping `b_c` (N s/m).
    pub b_nspm: f32,
}

impl ImpedanceGains {
    /// Stiffness `k_npm` (N/m) and damping `b_nspm` (N s/m).
    pub const fn new(k_npm: f32, b_nspm: f32) -> Self {
        ImpedanceGains { k_npm, b_nspm }
    }
}

/// The admittance display's regulator `K_p` (eq 30) and coupling `Z_cA`
/// (eq 21).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct AdmittanceGains {
    /// Regulator stiffness `k_p` (N/m).
    pub kp_npm: f32,
    /// Regulator damping `b_p` (N s/m).
    pub bp_nspm: f32,
    /// Coupling mass `m_c` (kg).
    pub m_kg: f32,
    /// Coupling damping `b_c` (N s/m).
    pub b_nspm: f32,
}

impl AdmittanceGains {
    /// Regulator `kp_npm` (N/m), `bp_nspm` (N s/m); coupling `m_kg` (kg),
    /// `b_nspm` (N s/m).
    pub const fn new(kp_npm: f32, bp_nspm: f32, m_kg: f32, b_nspm: f32) -> Self {
        AdmittanceGains {
            kp_npm,
            bp_nspm,
            m_kg,
            b_nspm,
        }
    }
}

/// The gains of either display.
///
/// # Examples
///
/// ```
/// use twoport_control::servo::{Display, Gains, ImpedanceGains};
/// // The paper's Excalibur coupling.
/// let g = Gains::Impedance(ImpedanceGains { k_npm: 51_000.0, b_nspm: 90.0 });
/// assert_eq!(g.display(), Display::Impedance);
/// assert!(g.all_finite());
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Gains {
    /// Impedance display.
    Impedance(ImpedanceGains),
    /// Admittance display.
    Admittance(AdmittanceGains),
}

impl Gains {
    /// The impedance display's coupling: stiffness (N/m) and damping (N s/m).
    pub const fn impedance(k_npm: f32, b_nspm: f32) -> Self {
        Gains::Impedance(ImpedanceGains::new(k_npm, b_nspm))
    }

    /// The admittance display's regulator, stiffness (N/m) and damping
    /// (N s/m), and coupling, mass (kg) and damping (N s/m).
    pub const fn admittance(kp_npm: f32, bp_nspm: f32, m_kg: f32, b_nspm: f32) -> Self {
        Gains::Admittance(AdmittanceGains::new(kp_npm, bp_nspm, m_kg, b_nspm))
    }

    /// The display these gains are for.
    pub fn display(&self) -> Display {
        match self {
            Gains::Impedance(_) => Display::Impedance,
            Gains::Admittance(_) => Display::Admittance,
        }
    }

    /// Whether no gain is NaN or infinite.
    pub fn all_finite(&self) -> bool {
        match *self {
            Gains::Impedance(g) => g.k_npm.is_finite() && g.b_nspm.is_finite(),
            Gains::Admittance(g) => {
                g.kp_npm.is_finite()
                    && g.bp_nspm.is_finite()
                    && g.m_kg.is_finite()
                    && g.b_nspm.is_finite()
            }
        }
    }
}

impl From<ImpedanceGains> for Gains {
    fn from(g: ImpedanceGains) -> Self {
        Gains::Impedance(g)
    }
}

impl From<AdmittanceGains> for Gains {
    fn from(g: AdmittanceGains) -> Self {
        Gains::Admittance(g)
    }
}

/// Why a servo refused new gains; it keeps its old ones.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum GainsError {
    /// The gains are for the other display.
    WrongDisplay {
        /// The servo's display.
        servo: Display,
        /// The gains'.
        gains: Display,
    },
    /// A gain is out of its law's range.
    Param(ParamError),
}

impl From<ParamError> for GainsError {
    fn from(e: ParamError) -> Self {
        GainsError::Param(e)
    }
}

impl fmt::Display for GainsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            GainsError::WrongDisplay { servo, gains } => {
                write!(f, "{gains}-display gains for an {servo}-display servo")
            }
            GainsError::Param(e) => e.fmt(f),
        }
    }
}

impl core::error::Error for GainsError {}
