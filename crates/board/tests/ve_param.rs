//! The board's own VE set from the host (protocol 9), and what the spec
//! says of the board's travel and its link.

use twoport_board::excalibur;
use twoport_control::servo::SensorFrame;
use twoport_control::Position;
use twoport_link::{
    encode, Axes, BoardMode, Decoder, Message, ModeRefusal, ModeRequest, VeParam, MAX_FRAME,
};

type Wall = twoport_board::Board<
    twoport_control::Servo<twoport_control::ve::UnilateralWall>,
    { excalibur::REGION_POINTS },
>;

fn send(b: &mut Wall, seq: u16, m: Message) -> Vec<Message> {
    let mut buf = [0u8; MAX_FRAME];
    let n = encode(seq, &m, &mut buf).unwrap();
    b.on_bytes(&buf[..n]);
    let mut d = Decoder::new();
    let mut out = Vec::new();
    while let Some(f) = b.pop_tx() {
        d.feed(&f, |e| out.push(e.msg));
    }
    out.retain(|m| !matches!(m, Message::Telemetry(_)));
    out
}

fn refused(why: ModeRefusal) -> Vec<Message> {
    vec![Message::ModeRefused {
        asked: ModeRequest::SetVeParam,
        why,
    }]
}

/// The shipped image, calibrated at 0 (its wall at +10 mm, solid above),
/// the wall's surface moved to `surface_nm` where given, then armed and
/// ticked 300 ms with the handle held at 0: the force the actuator gives.
fn force_at_zero(surface_nm: Option<i32>) -> f32 {
    let mut b = excalibur::stiff_wall_board().unwrap().with_pil(true);
    let held = |t| SensorFrame::held(t, [0], [0.0]);
    b.tick(&held(0));
    send(
        &mut b,
        1,
        Message::Calibrate {
            position_pm: Axes::one(0),
        },
    );
    if let Some(nm) = surface_nm {
        let param = VeParam::Surface(Position::from_nm(nm));
        assert_eq!(
            send(&mut b, 2, Message::SetVeParam { axis: 0, param }),
            vec![Message::VeParamSet { axis: 0, param }]
        );
    }
    send(&mut b, 3, Message::Arm);
    assert_eq!(b.mode(), BoardMode::Armed);
    let mut f = 0.0;
    for t in 1..300 {
        send(&mut b, 4 + t as u16, Message::Heartbeat);
        f = b.tick(&held(t)).actuator_force_n[0];
    }
    f
}

/// Moved below the handle, the wall holds it out: the coupling pulls the
/// handle toward the surface 5 mm down, where with the wall left at
/// +10 mm the handle is in free space.
#[test]
fn a_surface_set_from_the_host_moves_the_wall() {
    assert_eq!(force_at_zero(None), 0.0);
    let f = force_at_zero(Some(-5_000_000));
    assert!(f.abs() > 100.0, "{f} N");
}

/// Only a disarmed board takes a parameter; an axis it has not, a value
/// out of range and a parameter the VE has not are refused by name and
/// change nothing.
#[test]
fn bad_parameters_and_an_armed_board_are_refused() {
    let mut b = excalibur::stiff_wall_board().unwrap().with_pil(true);
    b.tick(&SensorFrame::held(0, [0], [0.0]));
    let set = |axis, param| Message::SetVeParam { axis, param };
    assert_eq!(
        send(&mut b, 1, set(1, VeParam::Stiffness(1.0))),
        refused(ModeRefusal::BadVeParam)
    );
    assert_eq!(
        send(&mut b, 2, set(0, VeParam::Stiffness(-1.0))),
        refused(ModeRefusal::BadVeParam)
    );
    assert_eq!(
        send(&mut b, 3, set(0, VeParam::Damping(f32::NAN))),
        refused(ModeRefusal::BadVeParam)
    );
    send(
        &mut b,
        5,
        Message::Calibrate {
            position_pm: Axes::one(0),
        },
    );
    send(&mut b, 6, Message::Arm);
    assert_eq!(
        send(&mut b, 7, set(0, VeParam::Damping(1.0))),
        refused(ModeRefusal::NotDisarmed {
            mode: BoardMode::Armed
        })
    );
}

/// A board that knows its travel and its link says so; one that does not
/// says nothing.
#[test]
fn the_spec_states_the_travel_and_the_link_rate_it_knows() {
    let spec = |b: &mut Wall| match send(b, 1, Message::GetSpec).as_slice() {
        [Message::Spec(s)] => *s,
        other => panic!("{other:?}"),
    };
    let mut b = excalibur::stiff_wall_board().unwrap();
    let s = spec(&mut b);
    assert_eq!((s.link_bytes_per_s, s.axes[0].workspace_nm), (None, None));
    let travel = (
        Position::from_nm(-20_000_000),
        Position::from_nm(100_000_000),
    );
    let mut b = excalibur::stiff_wall_board()
        .unwrap()
        .with_workspace([travel])
        .with_link_rate(11_520);
    let s = spec(&mut b);
    assert_eq!(s.link_bytes_per_s, Some(11_520));
    assert_eq!(s.axes[0].workspace_nm, Some((-20_000_000, 100_000_000)));
}
