//! Any byte stream into the link decoder: no panic, every frame ends as
//! good or counted-dropped, and good frames re-encode to themselves.
#![no_main]

use libfuzzer_sys::fuzz_target;
use twoport_link::{encode, Decoder, MAX_FRAME};

fuzz_target!(|data: &[u8]| {
    let mut d = Decoder::new();
    let mut ends = 0u32;
    for &b in data {
        match d.push(b) {
            Some(Ok(env)) => {
                ends += 1;
                let mut buf = [0u8; MAX_FRAME];
                let n = encode(env.seq, &env.msg, &mut buf).expect("a decoded message re-encodes");
                let mut again = Decoder::new();
                let mut back = None;
                again.feed(&buf[..n], |e| back = Some(e));
                assert_eq!(back, Some(env));
            }
            Some(Err(_)) => ends += 1,
            None => {}
        }
    }
    let s = d.stats();
    assert_eq!(s.frames + s.dropped(), ends);
});
