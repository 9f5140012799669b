//! The teleoperators' laws against their z-domain forms, as every law's
//! (`crate::response_tests`): each input driven in turn with the others
//! at rest, every term of the matrix measured and matched.

extern crate std;

use crate::response_tests::{assert_close, measure, pos, z_of, BINS, T, WINDOW};
use crate::*;

/// Lawrence's four-channel teleoperator with every channel and both
/// local force feedbacks on, and its two common cases (position-position,
/// force reflection), each with no delay and three ticks each way: every
/// term of each law's matrix (the devices' motions, the environment's and
/// the operator's sensed forces) is its z-domain form.
#[test]
fn four_channel_teleoperators() {
    use crate::teleop::{FourChannel, FourChannelGains};
    let full = FourChannelGains {
        k_m_npm: 800.0,
        b_m_nspm: 4.0,
        b_local_nspm: 1.5,
        k_s_npm: 1_200.0,
        b_s_nspm: 6.0,
        c2: 0.7,
        c3: 0.9,
        c5: -0.2,
        c6: -0.3,
    };
    type Law = FourChannel<f32, 8>;
    let laws: [(&str, &dyn Fn(usize) -> Law); 3] = [
        ("four-channel", &|d| {
            Law::new(full, T, d, Position::ZERO).unwrap()
        }),
        ("position-position", &|d| {
            Law::position_position(1_000.0, 5.0, T, d, Position::ZERO).unwrap()
        }),
        ("position-force", &|d| {
            Law::position_force(1_000.0, 5.0, 0.5, 2.0, T, d, Position::ZERO).unwrap()
        }),
    ];
    for (name, make) in laws {
        for d in [0, 3] {
            for p in BINS {
                for row in 0..2 {
                    for col in 0..4 {
                        let mut t = make(d);
                        let want = t.tf().eval(z_of(p))[row][col];
                        if want.norm() == 0.0 {
                            continue;
                        }
                        let mut est = FirstDifference::new(T, Position::ZERO).unwrap();
                        let rest = (Position::ZERO, 0.0);
                        let got = measure(p, |u| {
                            let (input, f) = match col {
                                2 => (u, t.step(rest, rest, 0.0, u as f32)),
                                3 => (u, t.step(rest, rest, u as f32, 0.0)),
                                _ => {
                                    let x = pos(1e-3 * u);
                                    let v = est.step(x);
                                    let f = if col == 0 {
                                        t.step((x, v), rest, 0.0, 0.0)
                                    } else {
                                        t.step(rest, (x, v), 0.0, 0.0)
                                    };
                                    (f64::from(v), f)
                                }
                            };
                            let out = if row == 0 { f.master_n } else { f.slave_n };
                            (input, f64::from(out))
                        });
                        assert_close(
                            &std::format!("{name} [{row}][{col}], {d} ticks"),
                            p,
                            got,
                            want,
                        );
                    }
                }
            }
        }
    }
}

/// The wave-variable channel, each device driven in turn with the other
/// held, at one, two and five ticks each way: every term is its z-domain
/// form. The channel is lossless, so the start's echo rings on at the
/// round trip's harmonics (bins that are multiples of `WINDOW/2d`, the
/// poles), and `Z_mm` vanishes half-way between them (the zeros); the
/// bins measured are off both (Nyquist, a multiple of each, is left out).
/// With the waves filtered (pole 0.6) the echo dies away, and every bin
/// is measured.
#[test]
fn wave_variable_teleoperator() {
    use crate::teleop::WaveVariables;
    for (d, pole) in [(1, 0.0), (2, 0.0), (5, 0.0), (1, 0.6), (3, 0.6)] {
        let off_poles = |p: &usize| pole > 0.0 || !p.is_multiple_of(WINDOW / (4 * d));
        for p in BINS.into_iter().filter(off_poles) {
            for (row, col) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                let mut w = WaveVariables::<f32, 8>::new(25.0, d)
                    .unwrap()
                    .with_wave_filter(pole as f32)
                    .unwrap();
                let got = measure(p, |u| {
                    let v = (0.1 * u) as f32;
                    let f = if col == 0 {
                        w.step(v, 0.0)
                    } else {
                        w.step(0.0, v)
                    };
                    let out = if row == 0 { f.master_n } else { f.slave_n };
                    (f64::from(v), f64::from(out))
                });
                let want = w.tf().eval(z_of(p))[row][col];
                let what = std::format!("[{row}][{col}], {d} ticks, pole {pole}");
                assert_close(&what, p, got, want);
            }
        }
    }
}
