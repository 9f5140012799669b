//! One servo type for both displays: its gains go in and come out as one
//! value, and a refused change leaves the old gains in force.

use twoport_control::servo::{Display, GainsError};
use twoport_control::ve::BilateralConstraint;
use twoport_control::{AdmittanceGains, Encoder, Gains, ImpedanceGains, Position, SafetyConfig};
use twoport_control::{AxisError, ParamError, Servo};

fn servo(g: Gains) -> Servo<BilateralConstraint> {
    let enc = Encoder::new(16, 1_000_000, 0, Position::ZERO).unwrap();
    let ve = BilateralConstraint::new(Position::ZERO);
    Servo::new([g], [enc], [SafetyConfig::excalibur()], ve).unwrap()
}

const IMP: ImpedanceGains = ImpedanceGains::new(51_000.0, 90.0);
const ADM: AdmittanceGains = AdmittanceGains::new(51_000.0, 90.0, 5.0, 500.0);

#[test]
fn gains_round_trip_through_the_servo() {
    for g in [Gains::from(IMP), Gains::from(ADM)] {
        let s = servo(g);
        assert_eq!(s.gains(), [g]);
        assert_eq!(s.display(), g.display());
    }
}

#[test]
fn gains_for_the_other_display_are_refused() {
    let mut s = servo(IMP.into());
    assert_eq!(
        s.set_gains([ADM.into()]),
        Err(AxisError::new(
            0,
            GainsError::WrongDisplay {
                servo: Display::Impedance,
                gains: Display::Admittance,
            }
        ))
    );
    assert_eq!(s.gains(), [IMP.into()]);
}

#[test]
fn a_refused_admittance_change_changes_nothing() {
    let mut s = servo(ADM.into());
    // A valid regulator with an invalid coupling mass: neither is applied.
    let bad = AdmittanceGains {
        kp_npm: 20_000.0,
        m_kg: -1.0,
        ..ADM
    };
    assert!(matches!(
        s.set_gains([bad.into()]),
        Err(AxisError {
            axis: 0,
            error: GainsError::Param(ParamError { .. })
        })
    ));
    assert_eq!(s.gains(), [ADM.into()]);
    let good = AdmittanceGains { m_kg: 6.0, ..ADM };
    s.set_gains([good.into()]).unwrap();
    assert_eq!(s.gains(), [good.into()]);
}

#[test]
fn invalid_gains_are_refused_at_construction() {
    let enc = Encoder::new(16, 1_000_000, 0, Position::ZERO).unwrap();
    let ve = BilateralConstraint::new(Position::ZERO);
    let bad = ImpedanceGains::new(-1.0, -1.0);
    assert!(Servo::new([bad.into()], [enc], [SafetyConfig::excalibur()], ve).is_err());
}
