//! Talking to a test board over the wire, as a host does: frames in,
//! decoded replies out, and sensor frames for its ticks.

use twoport_control::servo::SensorFrame;
use twoport_link::{encode, Decoder, Message, MAX_FRAME};

use super::common::TestBoard;

/// Send `m` to `b` as frame `seq`.
pub fn send(b: &mut TestBoard, seq: u16, m: Message) {
    let mut buf = [0u8; MAX_FRAME];
    let n = encode(seq, &m, &mut buf).unwrap();
    b.on_bytes(&buf[..n]);
}

/// Everything `b` has queued, decoded, oldest first.
pub fn replies(b: &mut TestBoard) -> Vec<Message> {
    let mut d = Decoder::new();
    let mut out = Vec::new();
    while let Some(f) = b.pop_tx() {
        d.feed(&f, |e| out.push(e.msg));
    }
    out
}

/// Tick `tick`'s sensors: the encoder at `raw`, no load, dead-man closed.
pub fn frame(tick: u32, raw: u32) -> SensorFrame {
    SensorFrame::held(tick, [raw], [0.0])
}
