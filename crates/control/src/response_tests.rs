//! The law you analyse is the law you run: every law is stepped with
//! sinusoids at twelve frequencies up to Nyquist, and its measured response
//! (one DFT bin over a whole number of periods) must equal its own z-domain
//! form within 1e-4 relative. The four Fig. 7 coupling/VE pairings are checked
//! against the composition of the parts' forms, which also proves that the
//! algebraic loops are solved exactly (a one-tick delay would fail).

extern crate std;

use crate::ve::{
    BilateralConstraint, Causality, CursorMass, ExplicitCursor, LosslessCursor, Port, Solid,
    Spring, TrapezoidalSpring, UnilateralWall, VeOutput, VeTransfer, VirtualEnvironment,
};
use crate::*;
use std::f64::consts::PI;

pub(crate) const T: f32 = 1.0e-3;
pub(crate) const WINDOW: usize = 4000;
const SETTLE: usize = 3000;
/// DFT bins: p periods per window; 2000 is Nyquist.
pub(crate) const BINS: [usize; 12] = [1, 3, 7, 20, 50, 130, 333, 700, 1200, 1800, 1990, 2000];

fn theta(p: usize) -> f64 {
    2.0 * PI * p as f64 / WINDOW as f64
}

pub(crate) fn z_of(p: usize) -> Complex64 {
    let th = theta(p);
    Complex64::new(th.cos(), th.sin())
}

/// Drive `tick` with `cos(θk)` for SETTLE + WINDOW ticks; it returns the
/// (input, output) it really had; the response is their DFT-bin ratio.
pub(crate) fn measure(p: usize, tick: impl FnMut(f64) -> (f64, f64)) -> Complex64 {
    let z = z_of(p);
    SineProbe::measure(z.re, z.im, SETTLE as u32, WINDOW as u32, tick)
}

pub(crate) fn assert_close(what: &str, p: usize, got: Complex64, want: Complex64) {
    let err = (got - want).norm() / want.norm();
    assert!(
        err <= 1e-4,
        "{what} at bin {p} ({:.1} Hz): measured {got}, z-domain {want}, rel err {err:.2e}",
        p as f64 / (WINDOW as f64 * T as f64)
    );
}

pub(crate) fn pos(x_m: f64) -> Position {
    Position::from_m_f64(x_m).unwrap()
}

/// A test VE that imposes a velocity whatever the force (admittance 0 plus a
/// source), for driving a coupling by its VE side.
struct VelocitySource(f32);

impl VirtualEnvironment for VelocitySource {
    fn causality(&self) -> Causality {
        Causality::Admittance
    }
    fn step(&mut self, port: Port) -> VeOutput {
        port.at(self.0)
    }
    fn reset(&mut self, _: Position) {}
    fn position(&self) -> Position {
        Position::ZERO
    }
    fn tf(&self) -> VeTransfer {
        VeTransfer::Admittance(ZTransfer::gain(0.0))
    }
}

#[test]
fn first_difference_estimator() {
    for p in BINS {
        let mut est = FirstDifference::new(T, Position::ZERO).unwrap();
        let got = measure(p, |c| {
            let x = pos(1e-3 * c);
            (x.m() as f64, est.step(x) as f64)
        });
        assert_close("(1 - z^-1)/T", p, got, est.tf().eval(z_of(p)));
    }
}

#[test]
fn velocity_integrator() {
    for p in BINS {
        let mut x = Integrator::new(T, Position::ZERO);
        let got = measure(p, |c| {
            let v = (0.2 * c) as f32;
            (v as f64, x.step(v).nm() as f64 * 1e-9)
        });
        assert_close("T/(1 - z^-1)", p, got, x.tf().eval(z_of(p)));
    }
}

#[test]
fn position_regulator() {
    for p in BINS {
        let mut r = PositionRegulator::new(51_000.0, 90.0, T).unwrap();
        let held = Integrator::new(T, Position::ZERO);
        let got = measure(p, |c| {
            let x = pos(1e-3 * c);
            (x.m() as f64, r.step(x, held.exact()) as f64)
        });
        assert_close("K_p", p, got, r.tf().eval(z_of(p)));
    }
}

/// `Z_cI` against a fixed VE at bin `p`, computing in `R`: (measured,
/// z-domain form).
fn zci_fixed_ve<R: Real>(p: usize) -> (Complex64, Complex64) {
    let mut est = FirstDifference::<R>::new_in(T, Position::ZERO).unwrap();
    let mut c = ImpedanceCoupling::<R>::new_in(51_000.0, 90.0, T).unwrap();
    let mut ve = BilateralConstraint::new(Position::ZERO);
    let got = measure(p, |u| {
        let x = pos(1e-3 * u);
        let v = est.step(x);
        (v.to_f64(), c.step(x, v, &mut ve).force_n.to_f64())
    });
    (got, c.tf().eval(z_of(p)))
}

#[test]
fn impedance_coupling_against_a_fixed_ve() {
    for p in BINS {
        let (got, want) = zci_fixed_ve::<f32>(p);
        assert_close("Z_cI", p, got, want);
    }
}

#[test]
fn admittance_coupling_driven_by_velocity() {
    for p in BINS {
        let mut c = AdmittanceCoupling::new(5.0, 500.0, T).unwrap();
        let mut src = VelocitySource(0.0);
        let got = measure(p, |u| {
            src.0 = (0.1 * u) as f32;
            let s = c.step(0.0, &mut src);
            (s.velocity_mps as f64, s.coupling_force_n as f64)
        });
        assert_close("Z_cA", p, got, c.tf().eval(z_of(p)));
    }
}

/// Admittance VE laws are measured as velocity per force, impedance ones as
/// force per velocity, each through a port of arbitrary feedthrough.
fn ve_response(p: usize, ve: &mut dyn VirtualEnvironment, bias_n: f64, amp_n: f64) -> Complex64 {
    let adm = ve.causality() == Causality::Admittance;
    measure(p, |u| {
        let o = ve.step(Port {
            f0_n: (bias_n + amp_n * u) as f32,
            z_nspm: 40.0,
        });
        let (f, v) = (o.force_n as f64, o.velocity_mps as f64);
        if adm {
            (f, v)
        } else {
            (v, f)
        }
    })
}

fn ve_tf(ve: &dyn VirtualEnvironment) -> ZTransfer {
    match ve.tf() {
        VeTransfer::Admittance(t) | VeTransfer::Impedance(t) => t,
    }
}

#[test]
fn cursor_mass_ve() {
    for p in BINS {
        let mut ve = CursorMass::new(0.25, T, Position::ZERO).unwrap();
        let got = ve_response(p, &mut ve, 0.0, 10.0);
        assert_close("cursor (T/m)/(1 - z^-1)", p, got, ve_tf(&ve).eval(z_of(p)));
    }
}

#[test]
fn lossless_cursor_ve_matches_its_z_form_and_is_lossless() {
    // (Its admittance is infinite at DC and 0 at Nyquist: the bins between.)
    for p in BINS.into_iter().filter(|&p| 2 * p < WINDOW) {
        let mut ve = LosslessCursor::new(0.25, T, Position::ZERO).unwrap();
        let got = ve_response(p, &mut ve, 0.0, 10.0);
        let want = ve_tf(&ve).eval(z_of(p));
        assert_close("lossless cursor (T/2m)(1 + z^-1)/(1 - z^-1)", p, got, want);
        assert!(want.re.abs() < 1e-9 * want.norm(), "{want}");
    }
}

#[test]
fn explicit_cursor_ve() {
    // The mean velocity has a zero at Nyquist: skip that bin.
    for p in BINS.into_iter().filter(|&p| 2 * p < WINDOW) {
        let mut ve = ExplicitCursor::new_in(0.25, T, Position::ZERO).unwrap();
        let got = ve_response(p, &mut ve, 0.0, 10.0);
        let want = ve_tf(&ve).eval(z_of(p));
        assert_close(
            "explicit cursor (T/2m)(z^-1 + z^-2)/(1 - z^-1)",
            p,
            got,
            want,
        );
    }
}

fn wall() -> UnilateralWall {
    UnilateralWall::new(
        20_000.0,
        50.0,
        Position::ZERO,
        Solid::Above,
        T,
        Position::ZERO,
    )
    .unwrap()
}

#[test]
fn wall_ve_in_contact() {
    for p in BINS {
        let mut ve = wall();
        // 100 +- 30 N keeps the probe 3.5 to 6.5 mm deep: always in contact.
        let got = ve_response(p, &mut ve, 100.0, 30.0);
        assert!(ve.in_contact());
        assert_close("wall b + kT/(1 - z^-1)", p, got, ve_tf(&ve).eval(z_of(p)));
    }
}

#[test]
fn spring_ve_pulls_and_pushes_linearly() {
    for p in BINS {
        let mut ve = Spring::new(20_000.0, 50.0, Position::ZERO, T, Position::ZERO).unwrap();
        // Zero-mean force: the spring is linear on both sides.
        let got = ve_response(p, &mut ve, 0.0, 30.0);
        assert_close("spring b + kT/(1 - z^-1)", p, got, ve_tf(&ve).eval(z_of(p)));
    }
}

#[test]
fn trapezoidal_spring_ve_matches_its_z_form_and_is_lossless() {
    // (At Nyquist a lossless trapezoidal spring has impedance exactly 0:
    // the damped case below covers that bin.)
    for p in BINS.into_iter().filter(|p| 2 * *p != WINDOW) {
        let mut ve = TrapezoidalSpring::from(
            Spring::new(20_000.0, 0.0, Position::ZERO, T, Position::ZERO).unwrap(),
        );
        let got = ve_response(p, &mut ve, 0.0, 30.0);
        let want = ve_tf(&ve).eval(z_of(p));
        assert_close("spring b + (kT/2)(1 + z^-1)/(1 - z^-1)", p, got, want);
        // No damping of its own: the real part vanishes on the unit circle.
        assert!(want.re.abs() < 1e-9 * want.norm(), "{want}");
    }
    for p in BINS {
        let mut ve = TrapezoidalSpring::from(
            Spring::new(20_000.0, 50.0, Position::ZERO, T, Position::ZERO).unwrap(),
        );
        let got = ve_response(p, &mut ve, 0.0, 30.0);
        assert_close("with damping", p, got, ve_tf(&ve).eval(z_of(p)));
    }
}

fn series_adm(z1: Complex64, z2: Complex64) -> Complex64 {
    // Two impedances whose admittances add.
    Complex64::new(1.0, 0.0) / (z1.inv() + z2.inv())
}

/// Fig. 7(a): impedance display, impedance VE (a wall in contact).
#[test]
fn fig7a_impedance_coupling_with_impedance_ve() {
    for p in BINS {
        let x0 = Position::ZERO;
        let mut est = FirstDifference::new(T, x0).unwrap();
        let mut c = ImpedanceCoupling::new(51_000.0, 90.0, T).unwrap();
        let mut ve = UnilateralWall::new(20_000.0, 50.0, pos(-5e-3), Solid::Above, T, x0).unwrap();
        // 0.1 mm keeps the wall's damper from ever wanting to pull at 500 Hz,
        // so the wall stays on its linear (contact) piece.
        let got = measure(p, |u| {
            let x = pos(1e-4 * u);
            let v = est.step(x);
            (v as f64, c.step(x, v, &mut ve).force_n as f64)
        });
        assert!(ve.in_contact());
        let z = z_of(p);
        assert_close(
            "Z_cI + wall",
            p,
            got,
            series_adm(c.tf().eval(z), ve_tf(&ve).eval(z)),
        );
    }
}

/// Fig. 7(a) with the trapezoidal spring, whose own probe is a trapezoid
/// sum: the coupling's spring still acts on the rectangle sum of the VE
/// velocity (the point the VE reports), so the two compose as analysed.
#[test]
fn fig7a_impedance_coupling_with_trapezoidal_spring() {
    for p in BINS {
        let x0 = Position::ZERO;
        let mut est = FirstDifference::new(T, x0).unwrap();
        let mut c = ImpedanceCoupling::new(51_000.0, 90.0, T).unwrap();
        let mut ve = TrapezoidalSpring::from(Spring::new(20_000.0, 50.0, x0, T, x0).unwrap());
        let got = measure(p, |u| {
            let x = pos(1e-4 * u);
            let v = est.step(x);
            (v as f64, c.step(x, v, &mut ve).force_n as f64)
        });
        let z = z_of(p);
        assert_close(
            "Z_cI + trapezoidal spring",
            p,
            got,
            series_adm(c.tf().eval(z), ve_tf(&ve).eval(z)),
        );
    }
}

/// Fig. 7(b): impedance display, admittance VE (a 0.25 kg cursor).
#[test]
fn fig7b_impedance_coupling_with_admittance_ve() {
    for p in BINS {
        let x0 = Position::ZERO;
        let mut est = FirstDifference::new(T, x0).unwrap();
        let mut c = ImpedanceCoupling::new(51_000.0, 90.0, T).unwrap();
        let mut ve = CursorMass::new(0.25, T, x0).unwrap();
        let got = measure(p, |u| {
            let x = pos(1e-3 * u);
            let v = est.step(x);
            (v as f64, c.step(x, v, &mut ve).force_n as f64)
        });
        let z = z_of(p);
        let want = Complex64::new(1.0, 0.0) / (c.tf().eval(z).inv() + ve_tf(&ve).eval(z));
        assert_close("Z_cI + cursor", p, got, want);
    }
}

/// Fig. 7(c): admittance display, impedance VE (a wall in contact).
#[test]
fn fig7c_admittance_coupling_with_impedance_ve() {
    for p in BINS {
        let mut c = AdmittanceCoupling::new(5.0, 500.0, T).unwrap();
        let mut ve = wall();
        let got = measure(p, |u| {
            let f = (100.0 + 30.0 * u) as f32;
            (f as f64, c.step(f, &mut ve).velocity_mps as f64)
        });
        assert!(ve.in_contact());
        let z = z_of(p);
        let want = (c.tf().eval(z) + ve_tf(&ve).eval(z)).inv();
        assert_close("1/(Z_cA + wall)", p, got, want);
    }
}

/// Fig. 7(d) at bin `p`, computing in `R`: (measured, composed z-forms).
fn fig7d<R: Real>(p: usize) -> (Complex64, Complex64) {
    let mut c = AdmittanceCoupling::<R>::new_in(5.0, 500.0, T).unwrap();
    let mut ve = CursorMass::<R>::new_in(0.25, T, Position::ZERO).unwrap();
    let got = measure(p, |u| {
        let f = R::of((30.0 * u) as f32);
        (f.to_f64(), c.step(f, &mut ve).velocity_mps.to_f64())
    });
    let z = z_of(p);
    let cursor = match VirtualEnvironment::<R>::tf(&ve) {
        VeTransfer::Admittance(t) | VeTransfer::Impedance(t) => t.eval(z),
    };
    (got, (c.tf().eval(z) + cursor.inv()).inv())
}

/// Fig. 7(d): admittance display, admittance VE (a 0.25 kg cursor).
#[test]
fn fig7d_admittance_coupling_with_admittance_ve() {
    for p in BINS {
        let (got, want) = fig7d::<f32>(p);
        assert_close("1/(Z_cA + 1/Y_cursor)", p, got, want);
    }
}

/// Worst relative error of `Z_cI` (against a fixed VE) and of the Fig. 7(d)
/// loop (`Z_cA` with a cursor) over all bins, computing in `R`.
fn worst_errors<R: Real>() -> (f64, f64) {
    let rel = |(got, want): (Complex64, Complex64)| (got - want).norm() / want.norm();
    BINS.into_iter().fold((0.0f64, 0.0f64), |(zci, loop_d), p| {
        (
            zci.max(rel(zci_fixed_ve::<R>(p))),
            loop_d.max(rel(fig7d::<R>(p))),
        )
    })
}

/// The same laws in f64 (`new_in::<f64>`): the response equals the z-form
/// to double precision, where the board's f32 shows its rounding. The f64
/// law is the f32 law, only wider.
#[test]
fn f64_laws_match_their_z_forms_to_double_precision() {
    let (zci32, d32) = worst_errors::<f32>();
    let (zci64, d64) = worst_errors::<f64>();
    std::eprintln!(
        "Z_cI: f32 {zci32:.1e}, f64 {zci64:.1e}; Fig. 7(d): f32 {d32:.1e}, f64 {d64:.1e}"
    );
    assert!(zci64 < 1e-10 && d64 < 1e-10, "{zci64:e} {d64:e}");
    assert!(zci32 > 100.0 * zci64 && d32 > 100.0 * d64);
    assert!(zci32 < 1e-4 && d32 < 1e-4);
}
