//! Every message round-trips; every corruption is dropped, counted and
//! survived; nothing panics on any byte stream.

use proptest::prelude::*;
use twoport_link::*;

/// Every message, at its extremes: the session, the gains, the modes and
/// the PIL frames here, the rest in [`spec_and_ve_messages`].
fn all_messages() -> Vec<Message> {
    let gi = Gains::impedance(51_000.0, 90.0);
    let ga = Gains::admittance(51_000.0, 90.0, 5.0, 500.0);
    vec![
        Message::hello(Role::Host, 3, u16::MAX),
        Message::HelloAck {
            version: PROTOCOL_VERSION,
            accepted: true,
            axes: MAX_AXES as u8,
            session: 1,
        },
        Message::Heartbeat,
        Message::Telemetry(Telemetry {
            tick: u32::MAX,
            axes: Axes::new([i64::MIN, i64::MAX, -1].map(|x| AxisTelemetry {
                position_pm: x,
                velocity_mps: -1.5,
                load_cell_n: f32::MAX,
                commanded_n: 199.9,
                actuator_n: -200.0,
                ve_position_pm: -x.saturating_add(1),
            }))
            .unwrap(),
            faults: 0xFFFF,
            loop_cycles: 1234,
            mode: BoardMode::Homing,
            stage_cycles: [u32::MAX; 3],
            deadline_misses: u32::MAX,
            worst_jitter_cycles: u32::MAX,
            worst_latency_cycles: u32::MAX,
            session: u16::MAX,
            ve_seq: u32::MAX,
        }),
        Message::GetGains,
        Message::Gains(Axes::new([gi, gi, gi]).unwrap()),
        Message::SetGains(Axes::one(ga)),
        Message::GainsReply(GainsReply::Accepted(Axes::new([gi, gi]).unwrap())),
        Message::GainsReply(GainsReply::Refused(AxisRefusal {
            axis: 2,
            why: Refusal::NotProvenStable { limit: 51_074.0 },
        })),
        Message::GainsReply(GainsReply::Refused(AxisRefusal {
            axis: 0,
            why: Refusal::WrongAxisCount { axes: 3 },
        })),
        Message::FaultReport {
            faults: 0x0101,
            first: 1,
        },
        Message::ClearFaults,
        Message::Arm,
        Message::Disarm,
        Message::Home,
        Message::Calibrate {
            position_pm: Axes::new([i64::MIN, 0, i64::MAX]).unwrap(),
        },
        Message::GetStatus,
        Message::SaveConfig,
        Message::GetConfig,
        Message::Config(ConfigSource::Stored { seq: u32::MAX }),
        Message::Config(ConfigSource::Defaults {
            why: ConfigFallback::OlderVersion { found: 0 },
        }),
        Message::Status(Status {
            mode: BoardMode::Armed,
            calibrated: true,
            faults: 0xFFFF,
            first_fault: 0x8000,
            session: u16::MAX,
        }),
        Message::ModeRefused {
            asked: ModeRequest::Arm,
            why: ModeRefusal::Faulted { faults: 0xFFFF },
        },
        Message::ModeRefused {
            asked: ModeRequest::Calibrate,
            why: ModeRefusal::NotDisarmed {
                mode: BoardMode::Homing,
            },
        },
        Message::Sensors(PilSensors {
            tick: 7,
            encoder_raw: Axes::new([65_535, u32::MAX, 0]).unwrap(),
            load_cell_raw: Axes::new([-2048, i32::MIN, i32::MAX]).unwrap(),
            dead_man_closed: true,
            index_raw: Axes::new([Some(u32::MAX), None, Some(0)]).unwrap(),
        }),
        Message::Sensors(PilSensors {
            tick: 8,
            encoder_raw: Axes::one(1),
            load_cell_raw: Axes::one(-1),
            dead_man_closed: false,
            index_raw: Axes::one(None),
        }),
        Message::Actuator(ActuatorFrame {
            tick: 7,
            duty: Axes::new([-32_767, 32_767, 0]).unwrap(),
            session: 0x5A5A,
        }),
    ]
    .into_iter()
    .chain(spec_and_ve_messages())
    .collect()
}

/// Every message of the spec, the stream and the VE, at its extremes.
fn spec_and_ve_messages() -> Vec<Message> {
    vec![
        Message::GetSpec,
        // The widest spec: every axis admittance, every number full width.
        Message::Spec(Spec {
            period_ns: u32::MAX,
            stream_every: u32::MAX,
            linkage: true,
            ve: VeSource::Host {
                ramp_ticks: u32::MAX,
                deadline_ticks: u32::MAX,
            },
            link_bytes_per_s: Some(u32::MAX),
            count_hz: Some(u32::MAX),
            worst_latency_cycles: u32::MAX,
            latency_budget_s: f32::MAX,
            axes: Axes::new([f32::MAX, 1.0, -0.0].map(|x| AxisSpec {
                peak_force_n: x,
                continuous_force_n: x,
                max_velocity_mps: x,
                region: ProvenRegion::MinMass {
                    kp_npm: x,
                    bp_nspm: x,
                    b_min_nspm: x,
                    b_max_nspm: x,
                    m_min_kg: x,
                    b_at_m_min_nspm: x,
                },
                workspace_nm: Some((i32::MIN, i32::MAX)),
            }))
            .unwrap(),
        }),
        Message::Spec(Spec {
            period_ns: 1_000_000,
            stream_every: 0,
            linkage: false,
            ve: VeSource::Board,
            link_bytes_per_s: None,
            count_hz: None,
            worst_latency_cycles: 0,
            latency_budget_s: 25e-6,
            axes: Axes::one(AxisSpec {
                peak_force_n: 200.0,
                continuous_force_n: 100.0,
                max_velocity_mps: 1.0,
                region: ProvenRegion::MaxStiffness {
                    b_min_nspm: 10.0,
                    b_max_nspm: 90.0,
                    k_max_npm: 51_074.0,
                    b_at_k_max_nspm: 90.0,
                },
                workspace_nm: None,
            }),
        }),
        Message::SetStream {
            every_ticks: u32::MAX,
        },
        Message::Stream { every_ticks: 0 },
        Message::SetVe(VeSource::Host {
            ramp_ticks: 10,
            deadline_ticks: 30,
        }),
        Message::Ve(VeSource::Board),
        Message::VeUpdate(VeUpdate {
            seq: u32::MAX,
            position_pm: Axes::new([i64::MIN, i64::MAX, 0]).unwrap(),
            contact: Axes::new([Contact::Held, Contact::Above, Contact::Free]).unwrap(),
        }),
        Message::SetVeParam {
            axis: u8::MAX,
            param: VeParam::Surface(twoport_control::Position(i32::MIN)),
        },
        Message::SetVeParam {
            axis: 0,
            param: VeParam::Stiffness(f32::MAX),
        },
        Message::VeParamSet {
            axis: 2,
            param: VeParam::Damping(-0.0),
        },
    ]
}

fn frame(seq: u16, m: &Message) -> Vec<u8> {
    let mut buf = [0u8; MAX_FRAME];
    let n = encode(seq, m, &mut buf).unwrap();
    buf[..n].to_vec()
}

fn decode_all(bytes: &[u8]) -> (Vec<Envelope>, Stats) {
    let mut d = Decoder::new();
    let mut out = Vec::new();
    d.feed(bytes, |e| out.push(e));
    (out, d.stats())
}

#[test]
fn every_message_round_trips_within_the_frame_limit() {
    let mut stream = Vec::new();
    for (i, m) in all_messages().iter().enumerate() {
        let f = frame(i as u16, m);
        assert!(f.len() <= MAX_FRAME, "{m:?}: {} bytes", f.len());
        assert_eq!(
            f.iter().filter(|b| **b == 0).count(),
            1,
            "one delimiter, at the end"
        );
        stream.extend(f);
    }
    let (got, stats) = decode_all(&stream);
    let want: Vec<Envelope> = all_messages()
        .into_iter()
        .enumerate()
        .map(|(i, msg)| Envelope { seq: i as u16, msg })
        .collect();
    assert_eq!(got, want);
    assert_eq!(stats.frames as usize, want.len());
    assert_eq!(stats.dropped(), 0);
    assert_eq!(stats.missing, 0);
}

/// Flip every byte of a frame to every other value: the frame is dropped
/// and counted (or, never, accepted as something else), and the next frame
/// still decodes.
#[test]
fn every_single_byte_corruption_is_dropped_and_survived() {
    let good = frame(
        1,
        &Message::Telemetry(Telemetry {
            tick: 42,
            axes: Axes::one(AxisTelemetry {
                position_pm: 123_456_789,
                ..Default::default()
            }),
            ..Default::default()
        }),
    );
    let next = frame(2, &Message::Heartbeat);
    let mut cases = 0;
    for i in 0..good.len() - 1 {
        for v in 0..=255u8 {
            if v == good[i] {
                continue;
            }
            let mut bad = good.clone();
            bad[i] = v;
            let mut stream = bad;
            stream.extend(&next);
            let (got, stats) = decode_all(&stream);
            assert!(
                !got.iter().any(|e| e.seq == 1),
                "byte {i} = {v:#04x} accepted"
            );
            assert_eq!(
                got.last().map(|e| e.msg),
                Some(Message::Heartbeat),
                "byte {i} = {v:#04x}: no resync"
            );
            assert!(stats.dropped() >= 1, "byte {i} = {v:#04x} not counted");
            cases += 1;
        }
    }
    assert!(cases > 5000);
}

#[test]
fn truncated_and_overlong_frames_are_dropped() {
    let good = frame(
        5,
        &Message::SetGains(Axes::one(Gains::impedance(1e4, 10.0))),
    );
    let mut stream = good[..good.len() / 2].to_vec();
    stream.push(0);
    stream.extend(vec![0x55u8; 3 * MAX_FRAME]);
    stream.push(0);
    stream.extend(&good);
    let (got, stats) = decode_all(&stream);
    assert_eq!(got.len(), 1);
    assert_eq!(stats.overflow, 1);
    assert_eq!(stats.dropped(), 2);
}

#[test]
fn sequence_gaps_are_counted() {
    let mut stream = Vec::new();
    for seq in [10u16, 11, 14, 15, u16::MAX, 0] {
        stream.extend(frame(seq, &Message::Heartbeat));
    }
    let (_, stats) = decode_all(&stream);
    // 12, 13 missing; then 16..=65534 missing (65519 frames).
    assert_eq!(stats.missing, 2 + (u16::MAX as u32 - 16));
}

#[test]
fn handshake_accepts_only_the_same_version_and_axes() {
    let ack = |accepted, axes, session| {
        Some(Message::HelloAck {
            version: PROTOCOL_VERSION,
            accepted,
            axes,
            session,
        })
    };
    // A three-axis board answers a three-axis host, and a one-axis one;
    // accepted, it is in the host's session, refused in its old one.
    assert_eq!(
        Message::hello(Role::Host, 3, 7).answer(3, 0),
        ack(true, 3, 7)
    );
    assert_eq!(
        Message::hello(Role::Host, 1, 7).answer(3, 4),
        ack(false, 3, 4)
    );
    let newer = Message::Hello {
        version: PROTOCOL_VERSION + 1,
        role: Role::Host,
        axes: 1,
        session: 7,
    };
    assert_eq!(newer.answer(1, 0), ack(false, 1, 0));
    assert_eq!(Message::Heartbeat.answer(1, 0), None);
    // A host must open a session: NO_SESSION is what a reset board says.
    let none = Message::hello(Role::Host, 1, NO_SESSION).answer(1, 0);
    assert_eq!(none, ack(false, 1, 0));

    // The host refuses a board of another count, and says so in words.
    let board = Message::hello(Role::Host, 1, 7).answer(3, 0).unwrap();
    let e = board.accept_ack(1, 7).unwrap_err();
    assert_eq!(e, HandshakeError::Axes { board: 3, host: 1 });
    assert_eq!(
        e.to_string(),
        "the board has 3 axes and this host drives 1: use a scene (or a host) built for 3"
    );
    let old = Message::HelloAck {
        version: 3,
        accepted: false,
        axes: 1,
        session: 0,
    };
    assert!(old
        .accept_ack(1, 7)
        .unwrap_err()
        .to_string()
        .contains("protocol 3"));
    assert_eq!(ack(true, 1, 7).unwrap().accept_ack(1, 7), Ok(()));
    // An answer for another session is no answer to this host's Hello.
    assert_eq!(
        ack(true, 1, 8).unwrap().accept_ack(1, 7),
        Err(HandshakeError::NotAnAnswer)
    );
    assert_eq!(
        Message::Heartbeat.accept_ack(1, 7),
        Err(HandshakeError::NotAnAnswer)
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    /// Any byte stream: no panic, every byte is accounted for (a frame
    /// ends as good or as counted-dropped), and a frame accepted from
    /// garbage is a well-formed message that round-trips.
    #[test]
    fn garbage_never_panics_and_accepted_frames_are_well_formed(bytes in proptest::collection::vec(any::<u8>(), 0..600)) {
        let mut d = Decoder::new();
        let mut ends = 0u32;
        for &b in &bytes {
            match d.push(b) {
                Some(Ok(env)) => {
                    ends += 1;
                    let mut buf = [0u8; MAX_FRAME];
                    let n = encode(env.seq, &env.msg, &mut buf).unwrap();
                    let (again, _) = decode_all(&buf[..n]);
                    prop_assert_eq!(again, vec![env]);
                }
                Some(Err(_)) => ends += 1,
                None => {}
            }
        }
        let s = d.stats();
        prop_assert_eq!(s.frames + s.dropped(), ends);
    }

    #[test]
    fn telemetry_round_trips(tick in any::<u32>(), pos in proptest::collection::vec(any::<i64>(), 1..=MAX_AXES), v in -10.0f32..10.0, faults in any::<u16>()) {
        let axes = pos.iter().map(|&position_pm| AxisTelemetry { position_pm, velocity_mps: v, ..Default::default() });
        let axes = Axes::from_slice(&axes.collect::<Vec<_>>()).unwrap();
        let m = Message::Telemetry(Telemetry { tick, axes, faults, ..Default::default() });
        let (got, _) = decode_all(&frame(tick as u16, &m));
        prop_assert_eq!(got, vec![Envelope { seq: tick as u16, msg: m }]);
    }
}

/// The link carries the servo's own gains, in the bytes the link's own
/// mirror of them had (the variant, then each field in order, as
/// little-endian f32): boards and records written before read the same.
#[test]
fn gains_keep_their_wire_bytes() {
    let mut buf = [0u8; 32];
    let impedance = postcard::to_slice(&Gains::impedance(51_000.0, 90.0), &mut buf).unwrap();
    assert_eq!(impedance, [0, 0, 56, 71, 71, 0, 0, 180, 66]);
    let admittance = postcard::to_slice(&Gains::admittance(1.0, 2.0, 3.0, 4.0), &mut buf).unwrap();
    assert_eq!(
        admittance,
        [1, 0, 0, 128, 63, 0, 0, 0, 64, 0, 0, 64, 64, 0, 0, 128, 64]
    );
}
