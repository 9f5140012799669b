//! Any bytes into the device protocols' decoders, on both sides: no panic;
//! a Haply setup that decodes re-encodes to its own bytes, a reply holds
//! finite readings and re-encodes to counts it reads back; a Falcon packet
//! that decodes re-encodes to what it means.
#![no_main]

use libfuzzer_sys::fuzz_target;
use twoport_host::falcon::protocol::{Command, FalconStatus, PACKET};
use twoport_host::haply::protocol::{Direction, Joint, Setup};

fuzz_target!(|data: &[u8]| {
    if let Ok((setup, used)) = Setup::<2>::decode(data) {
        assert_eq!(
            setup.encode().expect("a decoded setup encodes"),
            &data[..used]
        );
    }
    let joint = |port, res| Joint {
        port,
        motor: Direction::Ccw,
        encoder: Direction::Cw,
        offset_deg: 120.0,
        counts_per_rev: res,
    };
    let s = Setup {
        device_id: 1,
        joints: [joint(2, 13_824.0), joint(1, 4_880.0)],
        sensor_pins: vec![2],
    };
    if let Ok(r) = s.decode_reply(data) {
        assert!(r.sensors.iter().all(|v| v.is_finite()));
        let again = s.decode_reply(&s.reply(&r.sensors, r.counts));
        // (Counts far past a revolution lose their last digits to f32.)
        if r.counts.iter().all(|c| c.unsigned_abs() < 1 << 20) {
            assert_eq!(again.map(|a| a.counts), Ok(r.counts));
        }
    }
    if let Ok(t) = s.decode_torques(data) {
        assert_eq!(s.torques(t)[..], data[..Setup::<2>::torques_len()]);
    }
    // The Falcon's packets, each way: what decodes re-encodes to what it
    // means (its spare byte and unused bits aside).
    if let Ok(p) = <[u8; PACKET]>::try_from(data.get(..PACKET).unwrap_or_default()) {
        if let Ok(c) = Command::decode(&p) {
            assert_eq!(Command::decode(&c.encode()), Ok(c));
        }
        if let Ok(st) = FalconStatus::decode(&p) {
            assert_eq!(FalconStatus::decode(&st.encode()), Ok(st));
        }
    }
});
