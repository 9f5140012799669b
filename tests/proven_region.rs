//! The gate on the board is the designer's proof: a region made by the
//! designer, loaded into the portable firmware loop, accepts only gains the
//! designer's own check calls absolutely stable, off the grid included.

use twoport_board::{Board, Bound, Region};
use twoport_control::ve::BilateralConstraint;
use twoport_control::{Encoder, ImpedanceGains, Position, SafetyConfig, Servo};
use twoport_design::analysis::*;
use twoport_design::network::HumanBound;

use twoport_link::{encode, Axes, Decoder, Gains, GainsReply, Message, MAX_FRAME};

const N: usize = 16;

#[test]
fn the_board_accepts_only_what_the_designer_proves() {
    let a = Analysis::excalibur();
    let h = Some(HumanBound::PAPER);
    let bound = a.impedance_bound(h);
    let rows = region_impedance(&[(&a, &bound)], (10.0, 150.0), N);
    assert_eq!(
        rows.len(),
        N,
        "every damping from 10 to 150 N s/m has a stable coupling"
    );
    let b: [f32; N] = std::array::from_fn(|i| rows[i].0 as f32);
    let k: [f32; N] = std::array::from_fn(|i| rows[i].1 as f32);
    let region = Region::new(Bound::MaxStiffness, b, k, None).unwrap();
    let enc = Encoder::new(16, 1_000_000, 0, Position::ZERO).unwrap();
    let servo = Servo::new(
        [ImpedanceGains::new(10_000.0, 50.0).into()],
        [enc],
        [SafetyConfig::excalibur()],
        BilateralConstraint::new(Position::ZERO),
    )
    .unwrap();
    let mut board = Board::new(servo, [region], 0);
    let mut accepted = 0;
    for i in 0..60 {
        let damping = 10.0 * 15f32.powf(i as f32 / 59.0); // 10..150, mostly off the grid
        for factor in [0.5f32, 0.99, 1.0, 1.02, 1.3] {
            let Some(limit) = region.limit_at(damping) else {
                continue;
            };
            let g = Gains::impedance(limit * factor, damping);
            let mut buf = [0u8; MAX_FRAME];
            let n = encode(0, &Message::SetGains(Axes::one(g)), &mut buf).unwrap();
            board.on_bytes(&buf[..n]);
            let mut reply = None;
            Decoder::new().feed(&board.pop_tx().unwrap(), |e| reply = Some(e.msg));
            if let Some(Message::GainsReply(GainsReply::Accepted(_))) = reply {
                accepted += 1;
                let c = check_impedance(&a, (limit * factor) as f64, damping as f64, h).unwrap();
                assert!(
                    c.absolutely_stable,
                    "board accepted k {} at b {damping}, designer: {c:?}",
                    limit * factor
                );
            } else {
                assert!(
                    factor > 1.0,
                    "refused a gain inside the region: {g:?} -> {reply:?}"
                );
            }
        }
    }
    assert!(accepted >= 150, "{accepted}");
}
