//! Any bytes as a stored configuration record, as a board reads its flash
//! at boot: no panic; whatever decodes validates and re-encodes to the
//! same config. The bytes are tried as they are (which the CRC almost
//! always refuses) and with their CRC made right, so that the fuzzer
//! reaches the header checks and the payload's decoder behind it; and
//! through the two-copy store, as both copies. Each is read as a one-axis
//! and as a three-axis board reads it.
#![no_main]

use libfuzzer_sys::fuzz_target;
use twoport_config::record::{decode, decode_axes, encode, encode_axes, HEADER, MAX_RECORD};
use twoport_config::{crc32, RamFlash, Store};

fn check(bytes: &[u8]) {
    if let Ok((seq, cfg)) = decode(bytes) {
        assert!(cfg.validate().is_ok());
        let mut buf = [0u8; MAX_RECORD + 4];
        let n = encode(&cfg, seq, &mut buf).expect("a decoded config re-encodes");
        assert_eq!(decode(&buf[..n]), Ok((seq, cfg)));
    }
    if let Ok((seq, cfg)) = decode_axes::<3>(bytes) {
        assert!(cfg.iter().all(|c| c.validate().is_ok()));
        let mut buf = [0u8; MAX_RECORD + 4];
        let n = encode_axes(&cfg, seq, &mut buf).expect("decoded configs re-encode");
        assert_eq!(decode_axes::<3>(&buf[..n]), Ok((seq, cfg)));
    }
}

fuzz_target!(|data: &[u8]| {
    check(data);
    if data.len() >= HEADER + 4 {
        let mut fixed = data.to_vec();
        fixed[..4].copy_from_slice(b"TPCF");
        let n = (u16::from_le_bytes([fixed[6], fixed[7]]) as usize).min(fixed.len() - HEADER - 4);
        fixed[6..8].copy_from_slice(&(n as u16).to_le_bytes());
        let crc = crc32(&fixed[4..HEADER + n]);
        fixed[HEADER + n..HEADER + n + 4].copy_from_slice(&crc.to_le_bytes());
        check(&fixed);
        let mut flash = RamFlash::<512, 256>::new();
        let k = fixed.len().min(256);
        flash.bytes_mut()[..k].copy_from_slice(&fixed[..k]);
        flash.bytes_mut()[256..256 + k].copy_from_slice(&fixed[..k]);
        let mut store = Store::new(flash, 0, 256);
        let defaults = twoport_config::Config {
            gains: twoport_link::Gains::impedance(1.0, 1.0),
            load_cell: twoport_config::LoadCell {
                offset_counts: 0,
                n_per_count: 1.0,
            },
            homing: twoport_config::HomingSetup {
                stop_nm: 0,
                toward_positive: false,
                force_limit_n: 1.0,
                index_nm: None,
            },
            limits: twoport_config::Limits {
                peak_force_n: 2.0,
                continuous_force_n: 1.0,
                max_velocity_mps: 1.0,
                heartbeat_timeout_ticks: 0,
            },
        };
        let (cfg, _) = store.load(&defaults);
        assert!(cfg.validate().is_ok());
        let (cfg, _) = store.load_axes(&[defaults; 3]);
        assert!(cfg.iter().all(|c| c.validate().is_ok()));
    }
});
