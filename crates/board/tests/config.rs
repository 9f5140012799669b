//! The stored configuration as a board boots from it and saves it: the
//! defaults and the reason when there is none it can run, what a save
//! keeps, and a save cut by a power loss.

use twoport_config::record::{encode, MAX_RECORD};
use twoport_config::{Config, RamFlash, Store};
use twoport_control::SafetyConfig;
use twoport_link::{
    encode as frame, Axes, BoardMode, ConfigFallback, ConfigSource, Decoder, Gains, GainsReply,
    Message, ModeRefusal, ModeRequest, MAX_FRAME,
};

type Flash = RamFlash<512, 256>;
mod common;
use common::TestBoard;

fn board() -> TestBoard {
    common::board(51_000.0, SafetyConfig::excalibur(), 0)
}

fn say(b: &mut TestBoard, m: Message) {
    let mut buf = [0u8; MAX_FRAME];
    let n = frame(0, &m, &mut buf).unwrap();
    b.on_bytes(&buf[..n]);
}

fn heard(b: &mut TestBoard) -> Vec<Message> {
    let mut out = Vec::new();
    while let Some(f) = b.pop_tx() {
        Decoder::new().feed(&f, |e| out.push(e.msg));
    }
    out
}

fn store(flash: Flash) -> Store<Flash> {
    Store::new(flash, 0, 256)
}

#[test]
fn a_new_board_runs_its_defaults_and_says_why() {
    let mut b = board();
    let defaults = b.config();
    let mut st = store(Flash::new());
    let src = b.boot_config(&mut st);
    let missing = ConfigSource::Defaults {
        why: ConfigFallback::Missing,
    };
    assert_eq!(src, missing);
    assert_eq!(heard(&mut b), [Message::Config(missing)]);
    assert_eq!(b.config(), defaults);
    say(&mut b, Message::GetConfig);
    assert_eq!(heard(&mut b), [Message::Config(missing)]);
}

/// Tuned gains and a saved record: the next boot runs them. A save while
/// armed is refused, and one cut by a power loss is reported and leaves
/// the last committed record in force.
#[test]
fn saved_gains_come_back_at_the_next_boot() {
    let mut b = board();
    let mut st = store(Flash::new());
    b.boot_config(&mut st);
    let tuned = Gains::impedance(45_000.0, 60.0);
    say(&mut b, Message::SetGains(Axes::one(tuned)));
    say(&mut b, Message::SaveConfig);
    b.service_config(&mut st);
    let msgs = heard(&mut b);
    assert!(msgs.contains(&Message::GainsReply(GainsReply::Accepted(Axes::one(tuned)))));
    assert_eq!(
        msgs.last(),
        Some(&Message::Config(ConfigSource::Stored { seq: 1 }))
    );
    // Reboot on the same flash.
    let mut again = board();
    assert_eq!(again.boot_config(&mut st), ConfigSource::Stored { seq: 1 });
    assert_eq!(again.config()[0].gains, tuned);

    // Armed, a save is refused.
    again.tick(&twoport_control::SensorFrame::held(0, [0], [0.0]));
    say(
        &mut again,
        Message::Calibrate {
            position_pm: Axes::one(0),
        },
    );
    say(&mut again, Message::Arm);
    assert_eq!(again.mode(), BoardMode::Armed);
    heard(&mut again);
    say(&mut again, Message::SaveConfig);
    again.service_config(&mut st);
    assert_eq!(
        heard(&mut again),
        [Message::ModeRefused {
            asked: ModeRequest::SaveConfig,
            why: ModeRefusal::NotDisarmed {
                mode: BoardMode::Armed
            }
        }]
    );
    // Disarmed, a save that loses power half-way is reported.
    say(&mut again, Message::Disarm);
    say(
        &mut again,
        Message::SetGains(Axes::one(Gains::impedance(40_000.0, 60.0))),
    );
    say(&mut again, Message::SaveConfig);
    heard(&mut again);
    st.flash_mut().cut_power_after(100);
    again.service_config(&mut st);
    assert_eq!(
        heard(&mut again),
        [Message::ModeRefused {
            asked: ModeRequest::SaveConfig,
            why: ModeRefusal::FlashFailed
        }]
    );
    st.flash_mut().restore_power();
    let mut third = board();
    assert_eq!(third.boot_config(&mut st), ConfigSource::Stored { seq: 1 });
    assert_eq!(third.config()[0].gains, tuned);
}

/// A record this image cannot run: gains outside its proven region. The
/// board keeps its defaults, all of them, and says why.
#[test]
fn a_stored_record_with_unproven_gains_is_not_run() {
    let mut b = board();
    let defaults = b.config();
    let [mut cfg] = defaults;
    cfg.gains = Gains::impedance(60_000.0, 90.0);
    cfg.load_cell.offset_counts = 2048;
    let mut flash = Flash::new();
    let mut buf = [0u8; MAX_RECORD + 4];
    let n = encode(&cfg, 4, &mut buf).unwrap();
    flash.bytes_mut()[..n].copy_from_slice(&buf[..n]);
    let mut st = store(flash);
    assert_eq!(
        b.boot_config(&mut st),
        ConfigSource::Defaults {
            why: ConfigFallback::NotProven
        }
    );
    assert_eq!(b.config(), defaults);
}

/// A record with a calibrated load cell and tighter limits: both are in
/// force after the boot.
#[test]
fn stored_calibration_and_limits_are_put_in_force() {
    let mut b = board();
    let [mut cfg]: [Config; 1] = b.config();
    cfg.load_cell.offset_counts = 2048;
    cfg.limits.peak_force_n = 50.0;
    cfg.limits.continuous_force_n = 20.0;
    cfg.homing.stop_nm = 15_000_000;
    cfg.homing.toward_positive = true;
    let mut st = store(Flash::new());
    st.save(&cfg).unwrap();
    assert_eq!(b.boot_config(&mut st), ConfigSource::Stored { seq: 1 });
    assert_eq!(b.io()[0].load_cell_n(2048 + 1000), 1.0);
    assert_eq!(b.servo().safety().config().peak_force_n, 50.0);
    assert_eq!(b.config(), [cfg]);
}
