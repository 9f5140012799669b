//! The PC loop's own work in a tick, for a 3-DOF linkage (goal: at most
//! 3 µs): the device's answer turned into the board's sensors, the
//! image's whole control tick armed (the linkage servo: kinematics,
//! Jacobian, the three-axis coupling and VE, safety, the latency gate), a
//! host heartbeat read, and the command made. For the Falcon that is its
//! status packet decoded and its command packet encoded; for the 2DIY (two
//! joints), its reply decoded and its torques packet encoded; for the Touch,
//! OpenHaptics' joint angles read and its joint torques written. The
//! device's own exchange (USB, the HD library's frame) is not the PC's
//! work.

use criterion::{criterion_group, criterion_main, Criterion};
use std::cell::RefCell;
use std::collections::VecDeque;
use std::hint::black_box;
use std::rc::Rc;
use std::time::Duration;
use twoport_board::linkage::haply::{self as haply_image, HAPLY};
use twoport_board::linkage::pc::PcLinkageBoard;
use twoport_board::linkage::touch::{self, TOUCH};
use twoport_board::linkage::LinkageWorld;
use twoport_board::linkage::{falcon_pc, ImageSpec, FALCON};
use twoport_board::{BoardSupport, RawSensors};
use twoport_control::kinematics::Kinematics;
use twoport_control::world::World;
use twoport_hd::Frame;
use twoport_host::device_port::Grip;
use twoport_host::falcon::protocol::{Status, PACKET};
use twoport_host::falcon::{command, sensors};
use twoport_host::haply::{self, protocol::Setup, HaplyConfig};
use twoport_host::{BoardMode, BoardPort, HostBoard, LinkError};
use twoport_link::{encode, Message, MAX_FRAME};

/// A device's side of the exchange, in memory: the command out, the
/// sensors in, its encoders at `c` counts off the rest pose.
trait Exchange<const N: usize> {
    fn exchange(&mut self, duty: [i16; N], on: bool) -> RawSensors<N>;
    fn sweep(&mut self, c: i16);
}

/// The Falcon's packets.
#[derive(Default)]
struct FalconPackets {
    status: [u8; PACKET],
    command: [u8; PACKET],
}

impl Exchange<3> for FalconPackets {
    fn exchange(&mut self, duty: [i16; 3], on: bool) -> RawSensors<3> {
        let io = twoport_board::linkage::io(&FALCON);
        self.command = command(duty, on, &io, 0).encode();
        black_box(self.command);
        let s = Status::decode(&self.status).unwrap_or_default();
        sensors(&s, Grip::Button { mask: 1 })
    }
    fn sweep(&mut self, c: i16) {
        let s = Status {
            encoder: [c, -c, c / 2],
            buttons: 1,
            homed: 7,
        };
        self.status = s.encode();
    }
}

/// The Touch's frame: angles in, joint torques out.
struct TouchFrame {
    frame: Frame,
    torque_mnm: [f64; 3],
}

impl Exchange<3> for TouchFrame {
    fn exchange(&mut self, duty: [i16; 3], on: bool) -> RawSensors<3> {
        let io = twoport_board::linkage::io(&TOUCH);
        self.torque_mnm = twoport_host::touch::torques_mnm(duty, on, &io, [1.0; 3]);
        black_box(self.torque_mnm);
        twoport_host::touch::sensors(&self.frame, [1.0; 3], Grip::Button { mask: 1 })
    }
    fn sweep(&mut self, c: i16) {
        let per_count = core::f64::consts::TAU / f64::from(TOUCH.hardware.counts_per_rev);
        let c = f64::from(c) * per_count;
        let rest = TOUCH.rest_rad.map(f64::from);
        self.frame = Frame {
            joint_rad: [rest[0] + c, rest[1] - c, rest[2] + c / 2.0],
            buttons: 1,
        };
    }
}

/// The 2DIY's packets: torques out, the reply in.
struct HaplyPackets {
    setup: Setup<2>,
    reply: Vec<u8>,
    torques: Vec<u8>,
}

impl Exchange<2> for HaplyPackets {
    fn exchange(&mut self, duty: [i16; 2], on: bool) -> RawSensors<2> {
        let io = twoport_board::linkage::io(&HAPLY);
        self.torques = self.setup.torques(haply::torques_nm(duty, on, &io));
        black_box(&self.torques);
        let reply = self.setup.decode_reply(&self.reply).unwrap();
        haply::sensors(&self.setup, &reply, Self::grip())
    }
    fn sweep(&mut self, c: i16) {
        self.reply = self.setup.reply(&[1.0], [i32::from(c), -i32::from(c)]);
    }
}

impl HaplyPackets {
    /// A switch on analog pin 2, read closed.
    fn grip() -> Grip {
        Grip::Pin {
            pin: 2,
            closed_above: 0.5,
        }
    }
}

/// The board's peripherals in memory: the device's exchange, the link's
/// bytes both ways.
struct Memory<E, const N: usize> {
    device: E,
    rx: VecDeque<u8>,
    tx: Vec<u8>,
    duty: [i16; N],
    on: bool,
    cycles: u32,
}

impl<E: Exchange<N>, const N: usize> BoardSupport<N> for Memory<E, N> {
    /// The exchange, as the driver's: last tick's command out, the
    /// sensors in.
    fn sample(&mut self) -> RawSensors<N> {
        self.device.exchange(self.duty, self.on)
    }
    fn set_duty(&mut self, duty: [i16; N]) {
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
struct Lockstep<K: Kinematics<f32, N>, E, const N: usize> {
    board: PcLinkageBoard<K, N>,
    io: Memory<E, N>,
}

struct Port<K: Kinematics<f32, N>, E, const N: usize>(Rc<RefCell<Lockstep<K, E, N>>>);

impl<K: Kinematics<f32, N>, E: Exchange<N>, const N: usize> BoardPort for Port<K, E, N>
where
    LinkageWorld<N>: World<f32, N>,
{
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

/// Arm `board` (the device at rest, its grip held) and time its ticks
/// with the encoders sweeping 0 to 40 counts and back, a count a tick.
fn bench_device<K: Kinematics<f32, N>, E: Exchange<N>, const N: usize>(
    c: &mut Criterion,
    name: &str,
    board: PcLinkageBoard<K, N>,
    mut device: E,
    spec: &ImageSpec<N>,
) where
    LinkageWorld<N>: World<f32, N>,
{
    device.sweep(0);
    let lock = Rc::new(RefCell::new(Lockstep {
        board,
        io: Memory {
            device,
            rx: VecDeque::new(),
            tx: Vec::new(),
            duty: [0; N],
            on: false,
            cycles: 0,
        },
    }));
    let mut b = HostBoard::open(Port(Rc::clone(&lock)), N as u8).unwrap();
    b.calibrate(&spec.rest_rad.map(f64::from)).unwrap();
    assert_eq!(b.arm().unwrap().mode, BoardMode::Armed);
    let mut heartbeat = [0u8; MAX_FRAME];
    let n = encode(0, &Message::Heartbeat, &mut heartbeat).unwrap();
    let heartbeat = heartbeat[..n].to_vec();
    let mut l = lock.borrow_mut();
    let mut k = 0i16;
    let mut tick = |l: &mut Lockstep<K, E, N>| {
        k = k.wrapping_add(1);
        l.io.device.sweep(40 - (k % 80 - 40).abs());
        l.io.rx.extend(&heartbeat);
        let Lockstep { board, io } = l;
        board.poll_link(io);
        black_box(board.control_tick(io));
        board.flush(io);
        io.tx.clear();
    };
    for _ in 0..1000 {
        tick(&mut l);
    }
    let out = *l.board.last_output();
    assert!(
        l.io.on,
        "{name}: the board is still armed, its outputs on: {out:?}"
    );
    c.bench_function(name, |bench| bench.iter(|| tick(&mut l)));
}

fn pc_tick(c: &mut Criterion) {
    let setup = HaplyConfig::v3(HaplyPackets::grip()).setup();
    bench_device(
        c,
        "PC loop: a 2DIY tick's work (reply decoded, pantograph image armed, torques)",
        haply_image::board().unwrap(),
        HaplyPackets {
            setup,
            reply: Vec::new(),
            torques: Vec::new(),
        },
        &HAPLY,
    );
    bench_device(
        c,
        "PC loop: a Falcon tick's work (decode, delta image armed, encode)",
        falcon_pc::board().unwrap(),
        FalconPackets::default(),
        &FALCON,
    );
    bench_device(
        c,
        "PC loop: a Touch tick's work (HD's angles, serial-arm image armed, torques)",
        touch::board().unwrap(),
        TouchFrame {
            frame: Frame::default(),
            torque_mnm: [0.0; 3],
        },
        &TOUCH,
    );
}

criterion_group!(benches, pc_tick);
criterion_main!(benches);
