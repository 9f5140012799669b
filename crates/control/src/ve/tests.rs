//! Each VE against its own law, through bad ports and bad parameters.

use super::*;
use crate::Position;

const T: f32 = 1.0e-3;

fn wall_at_zero(probe_m: f32) -> UnilateralWall {
    let probe = Position::from_m(probe_m).unwrap();
    UnilateralWall::new(10_000.0, 20.0, Position::ZERO, Solid::Above, T, probe).unwrap()
}

#[test]
fn wall_is_free_outside_and_pushes_inside() {
    // Far outside, pulled gently: free, the port's force is zero.
    let mut w = wall_at_zero(-0.01);
    let out = w.step(Port {
        f0_n: 1.0,
        z_nspm: 100.0,
    });
    assert_eq!(out.force_n, 0.0);
    assert!((out.velocity_mps - 0.01).abs() < 1e-7);
    // Inside by 1 mm, held: force k d + (kT + b) v balances f0 - z v.
    let mut w = wall_at_zero(1e-3);
    let out = w.step(Port {
        f0_n: 10.0,
        z_nspm: 100.0,
    });
    let expect_v = (10.0 - 10_000.0 * 1e-3) / (100.0 + 10.0 + 20.0);
    assert!((out.velocity_mps - expect_v).abs() < 1e-6);
    assert!(out.force_n >= 0.0);
}

#[test]
fn wall_stops_a_fast_probe_at_the_surface_and_never_pulls() {
    // 0.1 mm outside, driven hard inward: the damper's jump on touch
    // leaves the probe exactly on the surface this tick.
    let mut w = wall_at_zero(-1e-4);
    let out = w.step(Port {
        f0_n: 2.0,
        z_nspm: 10.0,
    });
    assert!((out.velocity_mps - 0.1).abs() < 1e-5, "{out:?}");
    assert!(out.force_n >= 0.0);
    assert!(w.position().nm().abs() <= 1, "{:?}", w.position());
    // Inside but pulled out fast: the wall lets go (force 0, not < 0).
    let mut w = wall_at_zero(1e-4);
    let out = w.step(Port {
        f0_n: -50.0,
        z_nspm: 10.0,
    });
    assert_eq!(out.force_n, 0.0);
    // A wall solid below mirrors it.
    let mut w = UnilateralWall::new(
        10_000.0,
        20.0,
        Position::ZERO,
        Solid::Below,
        T,
        Position::from_m(-1e-3).unwrap(),
    )
    .unwrap();
    assert!(w.in_contact());
    let out = w.step(Port {
        f0_n: -10.0,
        z_nspm: 100.0,
    });
    assert!(out.force_n <= 0.0, "pushes toward +x: {out:?}");
}

#[test]
fn ve_state_survives_a_non_finite_port() {
    let mut m = CursorMass::new(0.25, T, Position::ZERO).unwrap();
    m.step(Port {
        f0_n: f32::NAN,
        z_nspm: 1.0,
    });
    assert_eq!(m.velocity_mps(), 0.0);
    assert_eq!(m.position(), Position::ZERO);
    // Outside, inside, solid on either side: no non-finite port moves
    // the probe (a NaN once reached the surface case and moved it there).
    for (probe_m, solid) in [
        (-1e-3, Solid::Above),
        (1e-3, Solid::Above),
        (1e-3, Solid::Below),
    ] {
        for f0_n in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
            let probe = Position::from_m(probe_m).unwrap();
            let mut w =
                UnilateralWall::new(10_000.0, 20.0, Position::ZERO, solid, T, probe).unwrap();
            let out = w.step(Port { f0_n, z_nspm: 1.0 });
            assert_eq!(w.position(), probe, "{f0_n} at {probe_m} m, {solid:?}");
            assert!(!out.velocity_mps.is_finite() || !out.force_n.is_finite());
        }
    }
}

/// The cursor keeps `1/(1 + (T/m) z)` for the port's `z`: when a
/// coupling's gains change `z` (or a NaN passes), its answer is still the
/// loop solve's, to f32 rounding, tick after tick.
#[test]
fn cursor_follows_a_changing_port_feedthrough() {
    let mut m = CursorMass::new(0.25, T, Position::ZERO).unwrap();
    let mut twin_v = 0.0f32; // the same mass by the divided formula
    for (k, z) in [100.0, 100.0, 250.0, f32::NAN, 250.0, 40.0, 40.0]
        .into_iter()
        .enumerate()
    {
        let port = Port {
            f0_n: 3.0 - k as f32,
            z_nspm: z,
        };
        let want = port.solve_admittance(twin_v, T / 0.25);
        let got = m.step(port);
        if z.is_nan() {
            assert!(got.velocity_mps.is_nan());
            continue;
        }
        let tol = 3e-7 * want.velocity_mps.abs();
        assert!(
            (got.velocity_mps - want.velocity_mps).abs() <= tol,
            "tick {k}, z {z}: {got:?} vs {want:?}"
        );
        twin_v = want.velocity_mps;
        assert!((m.velocity_mps() - twin_v).abs() <= tol);
    }
}

#[test]
fn constructors_refuse_bad_parameters() {
    assert_eq!(
        CursorMass::new(0.0, T, Position::ZERO).unwrap_err().name,
        "cursor mass (kg)"
    );
    assert!(
        UnilateralWall::new(-1.0, 0.0, Position::ZERO, Solid::Above, T, Position::ZERO).is_err()
    );
}

/// A wall's surface, stiffness and damping set through the VE trait and
/// through a world: the law is the one built with them; a bad value and a
/// parameter the VE does not have are refused by name, the VE unchanged.
#[test]
fn a_walls_parameters_are_set_by_name_and_checked() {
    use crate::world::{PerAxis, World};
    let t = 1e-3;
    let mut w = UnilateralWall::new(
        1000.0,
        10.0,
        Position::ZERO,
        Solid::Above,
        t,
        Position::ZERO,
    )
    .unwrap();
    w.set_param(VeParam::Surface(Position::from_nm(-1_000_000)))
        .unwrap();
    w.set_param(VeParam::Stiffness(5000.0)).unwrap();
    World::<f32, 1>::set_axis_param(&mut w, 0, VeParam::Damping(20.0)).unwrap();
    let built = UnilateralWall::new(
        5000.0,
        20.0,
        Position::from_nm(-1_000_000),
        Solid::Above,
        t,
        Position::ZERO,
    )
    .unwrap();
    let port = Port {
        f0_n: 3.0,
        z_nspm: 100.0,
    };
    assert_eq!(w.clone().step(port), built.clone().step(port));
    assert_eq!(w.spring(), (5000.0, 20.0));
    let e = w.set_param(VeParam::Stiffness(-1.0)).unwrap_err();
    assert_eq!(e.name, "stiffness (N/m)");
    assert_eq!(w.spring(), (5000.0, 20.0));
    let e = World::<f32, 1>::set_axis_param(&mut w, 1, VeParam::Damping(1.0)).unwrap_err();
    assert_eq!(e.problem, "is not a parameter of this VE");
    let mut axes = PerAxis([w; 3]);
    axes.set_axis_param(2, VeParam::Stiffness(7000.0)).unwrap();
    assert_eq!(
        (axes.0[2].spring().0, axes.0[0].spring().0),
        (7000.0, 5000.0)
    );
    let mut cursor = CursorMass::new(1.0, t, Position::ZERO).unwrap();
    let e = cursor.set_param(VeParam::Stiffness(1.0)).unwrap_err();
    assert_eq!(e.name, "VE stiffness (N/m)");
}
