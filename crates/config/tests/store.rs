//! The two-copy store: what a board reads back after saves, power losses,
//! corruption and records of other formats.

use proptest::prelude::*;
use twoport_config::record::{self, decode, encode_as, MAX_RECORD};
use twoport_config::{Config, HomingSetup, Limits, LoadCell, RamFlash, SaveError, Store};
use twoport_link::{ConfigFallback, ConfigSource, Gains};

type Flash = RamFlash<2048, 1024>;

fn defaults() -> Config {
    Config {
        gains: Gains::impedance(51_000.0, 90.0),
        load_cell: LoadCell {
            offset_counts: 0,
            n_per_count: 1e-3,
        },
        homing: HomingSetup {
            stop_nm: -20_000_000,
            toward_positive: false,
            force_limit_n: 5.0,
            index_nm: None,
        },
        limits: Limits {
            peak_force_n: 200.0,
            continuous_force_n: 100.0,
            max_velocity_mps: 1.0,
            heartbeat_timeout_ticks: 50,
        },
    }
}

fn tuned(k: f32) -> Config {
    Config {
        gains: Gains::impedance(k, 90.0),
        ..defaults()
    }
}

fn store() -> Store<Flash> {
    Store::new(Flash::new(), 0, 1024)
}

#[test]
fn saves_alternate_copies_and_the_newest_wins() {
    let mut s = store();
    for (i, k) in [40_000.0, 41_000.0, 42_000.0, 43_000.0]
        .into_iter()
        .enumerate()
    {
        assert_eq!(s.save(&tuned(k)), Ok(i as u32 + 1));
        assert_eq!(
            s.load(&defaults()),
            (tuned(k), ConfigSource::Stored { seq: i as u32 + 1 })
        );
    }
    // Both copies hold a record: the last two saves.
    let f = s.into_inner();
    assert_eq!(decode(&f.bytes()[..]).unwrap().0, 3);
    assert_eq!(decode(&f.bytes()[1024..]).unwrap().0, 4);
}

/// Cut the power after every possible number of bytes of a save (the
/// erase, the record, the commit word, the read-back): the next boot reads
/// the last committed record or the new one, never anything else, and the
/// new one whenever the save said it committed.
#[test]
fn a_power_loss_anywhere_in_a_save_loses_nothing_committed() {
    let (old, new) = (tuned(40_000.0), tuned(45_000.0));
    let mut cuts = 0;
    for cut in 0..1200 {
        let mut s = store();
        s.save(&tuned(39_000.0)).unwrap();
        s.save(&old).unwrap();
        s.flash_mut().cut_power_after(cut);
        let saved = s.save(&new);
        s.flash_mut().restore_power();
        let (cfg, src) = s.load(&defaults());
        match saved {
            Ok(3) => assert_eq!((cfg, src), (new, ConfigSource::Stored { seq: 3 })),
            Ok(n) => panic!("saved as {n}"),
            Err(e) => {
                cuts += 1;
                assert_eq!(e, SaveError::Flash, "cut {cut}");
                let ok = (cfg, src) == (old, ConfigSource::Stored { seq: 2 })
                    || (cfg, src) == (new, ConfigSource::Stored { seq: 3 });
                assert!(ok, "cut after {cut} bytes: {cfg:?} {src:?}");
            }
        }
    }
    // The erase (1,024 bytes) and the record are inside the range swept.
    assert!(cuts > 1024, "{cuts}");
}

#[test]
fn a_cut_first_save_leaves_the_defaults_with_the_reason() {
    for cut in [0, 500, 1030] {
        let mut s = store();
        s.flash_mut().cut_power_after(cut);
        assert!(s.save(&tuned(40_000.0)).is_err());
        s.flash_mut().restore_power();
        assert_eq!(
            s.load(&defaults()),
            (
                defaults(),
                ConfigSource::Defaults {
                    why: ConfigFallback::Missing
                }
            )
        );
    }
}

#[test]
fn a_corrupt_newest_copy_falls_back_to_the_older_then_to_defaults() {
    let mut s = store();
    s.save(&tuned(40_000.0)).unwrap();
    s.save(&tuned(41_000.0)).unwrap();
    // One bit of the newest record's payload (copy B) flips.
    s.flash_mut().bytes_mut()[1024 + 20] ^= 0x04;
    assert_eq!(
        s.load(&defaults()),
        (tuned(40_000.0), ConfigSource::Stored { seq: 1 })
    );
    s.flash_mut().bytes_mut()[20] ^= 0x10;
    assert_eq!(
        s.load(&defaults()),
        (
            defaults(),
            ConfigSource::Defaults {
                why: ConfigFallback::Corrupt
            }
        )
    );
    // The next save still commits, over a corrupt copy.
    assert_eq!(s.save(&tuned(42_000.0)), Ok(1));
}

#[test]
fn records_of_another_format_give_the_defaults_and_say_which() {
    for (version, why) in [
        (0, ConfigFallback::OlderVersion { found: 0 }),
        (7, ConfigFallback::NewerVersion { found: 7 }),
    ] {
        let mut s = store();
        let mut buf = [0xFFu8; MAX_RECORD + 4];
        let n = encode_as(version, &tuned(40_000.0), 5, &mut buf).unwrap();
        s.flash_mut().bytes_mut()[..n].copy_from_slice(&buf[..n]);
        assert_eq!(
            s.load(&defaults()),
            (defaults(), ConfigSource::Defaults { why })
        );
    }
}

#[test]
fn values_out_of_range_are_never_saved_and_never_loaded() {
    let mut bad = defaults();
    bad.limits.continuous_force_n = 300.0;
    let mut s = store();
    assert_eq!(
        s.save(&bad),
        Err(SaveError::Invalid("limits.continuous_force_n (N)"))
    );
    let mut bad = defaults();
    bad.gains = Gains::impedance(f32::NAN, 90.0);
    assert_eq!(s.save(&bad), Err(SaveError::Invalid("gains")));
    bad = defaults();
    bad.homing.force_limit_n = 500.0;
    assert_eq!(
        s.save(&bad),
        Err(SaveError::Invalid("homing.force_limit_n (N)"))
    );
    assert_eq!(s.load(&defaults()).0, defaults());
}

#[test]
fn the_sequence_number_wraps() {
    let mut s = store();
    let mut buf = [0xFFu8; MAX_RECORD + 4];
    let n = record::encode(&tuned(40_000.0), u32::MAX, &mut buf).unwrap();
    s.flash_mut().bytes_mut()[..n].copy_from_slice(&buf[..n]);
    assert_eq!(s.save(&tuned(41_000.0)), Ok(0));
    assert_eq!(
        s.load(&defaults()),
        (tuned(41_000.0), ConfigSource::Stored { seq: 0 })
    );
}

proptest! {
    /// Any bytes, and any valid record with bytes changed: decoding never
    /// panics, and whatever it accepts validates.
    #[test]
    fn decoding_never_panics_and_accepts_only_valid_configs(
        junk in proptest::collection::vec(any::<u8>(), 0..200),
        flips in proptest::collection::vec((0usize..MAX_RECORD, any::<u8>()), 0..4),
    ) {
        if let Ok((_, c)) = decode(&junk) {
            prop_assert!(c.validate().is_ok());
        }
        let mut buf = [0xFFu8; MAX_RECORD + 4];
        record::encode(&tuned(40_000.0), 9, &mut buf).unwrap();
        for (i, x) in &flips {
            buf[*i] ^= x;
        }
        if let Ok((_, c)) = decode(&buf) {
            prop_assert!(c.validate().is_ok());
        }
    }
}

/// A three-axis board's record holds every axis; the largest (admittance
/// gains, an index, extreme values on every axis) fits a 256-byte erase
/// unit; a reader of another axis count is told how many it holds.
#[test]
fn a_three_axis_record_round_trips_and_names_its_axis_count() {
    let mut big = defaults();
    big.gains = Gains::admittance(f32::MAX, f32::MAX, f32::MAX, f32::MAX);
    big.load_cell.offset_counts = i32::MIN;
    big.homing.stop_nm = i32::MIN;
    big.homing.index_nm = Some(i32::MIN);
    big.limits.heartbeat_timeout_ticks = u32::MAX;
    let axes = [big, tuned(40_000.0), big];
    let mut buf = [0xFFu8; MAX_RECORD + 4];
    let n = record::encode_axes(&axes, 7, &mut buf).unwrap();
    assert!(n <= 256, "{n} bytes");
    assert_eq!(record::decode_axes::<3>(&buf[..n]), Ok((7, axes)));
    assert_eq!(
        decode(&buf[..n]),
        Err(record::RecordError::Axes { found: 3 })
    );
    let mut st = Store::new(Flash::new(), 0, 1024);
    st.save_axes(&axes).unwrap();
    assert_eq!(
        st.load_axes(&[defaults(); 3]),
        (axes, ConfigSource::Stored { seq: 1 })
    );
    assert_eq!(
        st.load(&defaults()),
        (
            defaults(),
            ConfigSource::Defaults {
                why: ConfigFallback::WrongAxes { found: 3 }
            }
        )
    );
}
