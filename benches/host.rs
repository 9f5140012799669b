//! The host API's own cost, apart from the link's: a streamed state read
//! into the device object's buffer (the frame decoded, checked and turned
//! into SI), and a host VE update sent (encoded and framed). The port
//! replays recorded frames and swallows what it is sent, so only the
//! host's work is timed.

use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;
use std::time::Duration;
use twoport_host::{Axes, BoardPort, Contact, HostBoard, LinkError};
use twoport_link::{
    encode, AxisTelemetry, BoardMode, Decoder, Message, Telemetry, MAX_FRAME, PROTOCOL_VERSION,
};

/// A board that answers the handshake and the spec request as the
/// Excalibur image does, then streams one telemetry frame per read.
struct Replay {
    decoder: Decoder,
    out: Vec<u8>,
    session: u16,
    tick: u32,
    seq: u16,
}

impl Replay {
    fn queue(&mut self, m: &Message) {
        let mut buf = [0u8; MAX_FRAME];
        let n = encode(self.seq, m, &mut buf).unwrap();
        self.seq = self.seq.wrapping_add(1);
        self.out.extend_from_slice(&buf[..n]);
    }
}

impl BoardPort for Replay {
    fn send(&mut self, bytes: &[u8]) -> Result<(), LinkError> {
        let mut asked = Vec::new();
        self.decoder.feed(bytes, |e| asked.push(e.msg));
        for m in asked {
            match m {
                Message::Hello { session, .. } => {
                    self.session = session;
                    self.queue(&Message::HelloAck {
                        version: PROTOCOL_VERSION,
                        accepted: true,
                        axes: 1,
                        session,
                    });
                }
                Message::GetSpec => {
                    let board = twoport_board::excalibur::stiff_wall_board().unwrap();
                    self.queue(&Message::Spec(board.spec()));
                }
                _ => {}
            }
        }
        Ok(())
    }

    fn recv(&mut self, buf: &mut [u8], _: Duration) -> Result<usize, LinkError> {
        if self.out.is_empty() {
            self.tick = self.tick.wrapping_add(1);
            let t = Telemetry {
                tick: self.tick,
                axes: Axes::one(AxisTelemetry {
                    position_pm: 5_039_000_000,
                    velocity_mps: 1e-3,
                    load_cell_n: 2.0,
                    commanded_n: 1.989,
                    actuator_n: 1.989,
                    ve_position_pm: 5_000_000_000,
                }),
                mode: BoardMode::Armed,
                session: self.session,
                ve_seq: self.tick,
                ..Telemetry::default()
            };
            self.queue(&Message::Telemetry(t));
        }
        let n = buf.len().min(self.out.len());
        buf[..n].copy_from_slice(&self.out[..n]);
        self.out.drain(..n);
        Ok(n)
    }
}

fn host(c: &mut Criterion) {
    let port = Replay {
        decoder: Decoder::new(),
        out: Vec::new(),
        session: 0,
        tick: 0,
        seq: 0,
    };
    let mut b = HostBoard::open(port, 1).unwrap();
    c.bench_function("host: one streamed state read (poll)", |bench| {
        bench.iter(|| {
            let n = b.poll().unwrap();
            black_box(b.take_states_up_to(n));
        })
    });
    c.bench_function("host: one VE update sent (send_ve)", |bench| {
        bench.iter(|| b.send_ve(black_box(&[0.005]), &[Contact::Above]).unwrap())
    });
}

criterion_group!(benches, host);
criterion_main!(benches);
