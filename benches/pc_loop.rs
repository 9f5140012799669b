//! The PC loop's own work in a tick, for a 3-DOF linkage (goal: at most
//! 3 µs): the Falcon's status packet decoded and turned into the board's
//! sensors, the delta image's whole control tick armed (the linkage
//! servo: kinematics, Jacobian, the three-axis coupling and VE, safety,
//! the latency gate), a host heartbeat read, and the command packet
//! encoded. The device's own exchange (USB) is not the PC's work.

use criterion::{criterion_group, criterion_main, Criterion};
use std::cell::RefCell;
use std::collections::VecDeque;
use std::hint::black_box;
use std::rc::Rc;
use std::time::Duration;
use twoport_board::linkage::falcon_pc::{self, FalconBoard};
use twoport_board::linkage::FALCON;
use twoport_board::{BoardSupport, RawSensors};
use twoport_host::device_port::Grip;
use twoport_host::falcon::protocol::{Status, PACKET};
use twoport_host::falcon::{command, sensors};
use twoport_host::{BoardMode, BoardPort, HostBoard, LinkError};
use twoport_link::{encode, Message, MAX_FRAME};

/// The board's peripherals in memory: the Falcon's last status packet
/// in, the command packet out, the link's bytes both ways.
#[derive(Default)]
struct Memory {
    status: [u8; PACKET],
    command: [u8; PACKET],
    rx: VecDeque<u8>,
    tx: Vec<u8>,
    duty: [i16; 3],
    on: bool,
    cycles: u32,
}

impl BoardSupport<3> for Memory {
    /// The exchange, as the driver's: last tick's command out, the
    /// status in.
    fn sample(&mut self) -> RawSensors<3> {
        let io = twoport_board::linkage::io(&FALCON);
        self.command = command(self.duty, self.on, &io, 0).encode();
        let s = Status::decode(&self.status).unwrap_or_default();
        sensors(&s, Grip::Button { mask: 1 })
    }
    fn set_duty(&mut self, duty: [i16; 3]) {
        self.duty = duty;
    }
    fn set_outputs(&mut self, on: bool) {
        self.on = on;
    }
    fn feed_watchdog(&mut self) {}
    fn read_byte(&mut self) -> Option<u8> {
        self.rx.pop_front()
    }
    fn write(&mut self, bytes: &[u8]) {
        self.tx.extend_from_slice(bytes);
    }
    fn cycles(&mut self) -> u32 {
        self.cycles = self.cycles.wrapping_add(1);
        self.cycles
    }
    fn cycles_per_tick(&self) -> u32 {
        1_000_000
    }
}

/// The board and its memory, ticked as the host's calls arrive.
struct Lockstep {
    board: FalconBoard,
    io: Memory,
}

#[derive(Clone)]
struct Port(Rc<RefCell<Lockstep>>);

impl BoardPort for Port {
    fn send(&mut self, bytes: &[u8]) -> Result<(), LinkError> {
        let mut l = self.0.borrow_mut();
        let Lockstep { board, io } = &mut *l;
        io.rx.extend(bytes);
        while !io.rx.is_empty() {
            board.poll_link(io);
            board.control_tick(io);
            board.flush(io);
        }
        board.control_tick(io);
        board.flush(io);
        Ok(())
    }
    fn recv(&mut self, buf: &mut [u8], _: Duration) -> Result<usize, LinkError> {
        let mut l = self.0.borrow_mut();
        let n = buf.len().min(l.io.tx.len());
        buf[..n].copy_from_slice(&l.io.tx[..n]);
        l.io.tx.drain(..n);
        Ok(n)
    }
}

fn pc_tick(c: &mut Criterion) {
    // The grip's button held, the handle at the rest pose.
    let status = Status {
        buttons: 1,
        ..Status::default()
    };
    let lock = Rc::new(RefCell::new(Lockstep {
        board: falcon_pc::board().unwrap(),
        io: Memory {
            status: status.encode(),
            ..Memory::default()
        },
    }));
    let mut b = HostBoard::open(Port(Rc::clone(&lock)), 3).unwrap();
    b.calibrate(&FALCON.rest_rad.map(f64::from)).unwrap();
    assert_eq!(b.arm().unwrap().mode, BoardMode::Armed);
    let mut heartbeat = [0u8; MAX_FRAME];
    let n = encode(0, &Message::Heartbeat, &mut heartbeat).unwrap();
    let heartbeat = heartbeat[..n].to_vec();
    let mut l = lock.borrow_mut();
    let mut k = 0i16;
    let mut tick = |l: &mut Lockstep| {
        k = k.wrapping_add(1);
        // The encoders sweep 0 to 40 counts and back, a count a tick.
        let c = (k % 80 - 40).abs();
        let s = Status {
            encoder: [c, -c, c / 2],
            buttons: 1,
            homed: 7,
        };
        l.io.status = s.encode();
        l.io.rx.extend(&heartbeat);
        let Lockstep { board, io } = l;
        board.poll_link(io);
        black_box(board.control_tick(io));
        board.flush(io);
        io.tx.clear();
        black_box(io.command);
    };
    for _ in 0..1000 {
        tick(&mut l);
    }
    let out = *l.board.last_output();
    assert!(l.io.on, "the board is still armed, its outputs on: {out:?}");
    c.bench_function(
        "PC loop: a Falcon tick's work (decode, delta image armed, encode)",
        |bench| bench.iter(|| tick(&mut l)),
    );
}

criterion_group!(benches, pc_tick);
criterion_main!(benches);
