//! `verify` for teleoperators: the exact discrete closed loop of master,
//! slave, law and channel, against what is known from outside it.

use twoport_control::teleop::FourChannel;
use twoport_control::Position;
use twoport_design::verify::{teleop_radius, verify_teleop, Hand, TeleopTermination, Teleoperator};
use twoport_design::DeviceModel;

mod common;

/// A rigid handle of `m` kg with `b` N s/m of its own damping.
fn rigid(m: f64, b: f64) -> DeviceModel {
    common::rigid(m, b, 0)
}

const T: f64 = 1e-3;

fn pp(k: f64, b: f64, d: usize) -> twoport_control::teleop::TeleopTransfer {
    FourChannel::<f64, 64>::position_position(k as f32, b as f32, T as f32, d, Position::ZERO)
        .unwrap()
        .tf()
}

/// Two rigid devices (0.1 kg, 1 N s/m each) joined by position-position
/// with no damping and no delay: their relative motion is one mass on the
/// sampled spring `2k`, whose loop holds below Colgate's `b > (2k) T/2`,
/// `k < b/T`, and grows above. `verify` finds the edge from both sides
/// within 2%, and nothing below it over every operator and environment it
/// sweeps.
#[test]
fn position_position_on_rigid_devices_meets_colgates_edge() {
    let (master, slave) = (rigid(0.1, 1.0), rigid(0.1, 1.0));
    let edge = 1.0 / T;
    let at = |share: f64| {
        let t = Teleoperator {
            master: &master,
            slave: &slave,
            law: pp(share * edge, 0.0, 0),
        };
        verify_teleop(&t).unwrap()
    };
    let (below, above) = (at(0.98), at(1.02));
    assert!(!below.unstable, "{below:?}");
    assert!(above.unstable, "{above:?}");
    // Free of both ends: the relative mode, at `√(2k/m_r)`, about 22 Hz.
    assert_eq!(above.termination.operator, Hand::OFF);
    assert!((above.frequency_hz - 22.7).abs() < 1.0, "{above:?}");
}

/// The matrix is the law run: the control crate's `FourChannel`, stepped
/// on the two devices integrated exactly between ticks (free of both
/// ends, 2% either side of the edge), decays where the spectral radius is
/// below one and grows where it is above, at the radius's own rate.
#[test]
fn the_closed_loop_matches_the_law_stepped_in_time() {
    let (master, slave) = (rigid(0.1, 1.0), rigid(0.1, 1.0));
    let free = TeleopTermination {
        operator: Hand::OFF,
        environment: Hand::OFF,
    };
    for share in [0.98, 1.02] {
        let k = share / T;
        let t = Teleoperator {
            master: &master,
            slave: &slave,
            law: pp(k, 0.0, 0),
        };
        let r = teleop_radius(&t, &free).unwrap();
        // The relative coordinate's amplitude over 4,000 ticks, from a
        // 1 mm stretch.
        let mut law =
            FourChannel::<f64, 4>::position_position(k as f32, 0.0, T as f32, 0, Position::ZERO)
                .unwrap();
        let ticks = 4000;
        let peaks = common::stepped_rigid_pair(&mut law, (0.1, 1.0), T, 1e-3, ticks);
        let per_tick = (peaks.1 / peaks.0).ln() / (ticks - 500) as f64;
        // (The oscillating mode's, not the translation's at z = 1.)
        let predicted = r.score.ln();
        assert!(
            (per_tick - predicted).abs() < 0.1 * predicted.abs(),
            "{share}: time {per_tick:e} a tick, matrix {predicted:e}"
        );
        assert_eq!(per_tick > 0.0, r.unstable, "{share}: {r:?}");
    }
}

/// A channel's delay lowers the edge: at half the undelayed edge the
/// loop holds with one tick each way and grows with four.
#[test]
fn a_delay_lowers_position_positions_edge() {
    let (master, slave) = (rigid(0.1, 1.0), rigid(0.1, 1.0));
    let at = |d: usize| {
        let t = Teleoperator {
            master: &master,
            slave: &slave,
            law: pp(0.5 / T, 0.0, d),
        };
        verify_teleop(&t).unwrap()
    };
    let (one, four) = (at(1), at(4));
    assert!(!one.unstable, "{one:?}");
    assert!(four.unstable, "{four:?}");
}
