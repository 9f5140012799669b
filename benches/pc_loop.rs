//! The PC loop's own work in a tick, for a 3-DOF linkage (goal: at most
//! 3 µs), on the loop the drivers run ([`SteppedPc`], stepped): the
//! device's answer turned into the board's sensors, the image's whole
//! control tick armed (the linkage servo: kinematics, Jacobian, the
//! three-axis coupling and VE, safety), a host heartbeat read, the
//! command made, and the loop's bookkeeping (the link's lock, the tick's
//! timing). For the Falcon that is its status packet decoded and its
//! command packet encoded; for the 2DIY (two joints), its reply decoded
//! and its torques packet encoded; for the Touch, OpenHaptics' joint
//! angles read and its joint torques written. The device's own exchange
//! (USB, the HD library's frame) is not the PC's work.

use criterion::{criterion_group, criterion_main, Criterion};
use std::cell::RefCell;
use std::hint::black_box;
use std::rc::Rc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;
use twoport_board::linkage::haply::{self as haply_image, HAPLY};
use twoport_board::linkage::pc::PcLinkageBoard;
use twoport_board::linkage::touch::{self, TOUCH};
use twoport_board::linkage::LinkageWorld;
use twoport_board::linkage::{falcon_pc, ImageSpec, FALCON};
use twoport_board::RawSensors;
use twoport_control::kinematics::Kinematics;
use twoport_control::world::World;
use twoport_hd::HdFrame;
use twoport_host::device_port::Grip;
use twoport_host::falcon::protocol::{FalconStatus, PACKET};
use twoport_host::falcon::{command, sensors};
use twoport_host::haply::{self, protocol::Setup, HaplyConfig};
use twoport_host::{BoardMode, BoardPort, DeviceIo, HostBoard, LinkError, SteppedPc};
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
        let s = FalconStatus::decode(&self.status).unwrap_or_default();
        sensors(&s, Grip::Button { mask: 1 })
    }
    fn sweep(&mut self, c: i16) {
        let s = FalconStatus {
            encoder: [c, -c, c / 2],
            buttons: 1,
            homed: 7,
        };
        self.status = s.encode();
    }
}

/// The Touch's frame: angles in, joint torques out.
struct TouchFrame {
    frame: HdFrame,
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
        self.frame = HdFrame {
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

/// A device in memory as the PC's loop drives it: once `sweeping`, its
/// encoders sweep 0 to 40 counts and back, a count an exchange; `on` is
/// the amplifiers' last state.
struct Swept<E> {
    device: E,
    k: i16,
    flags: Arc<Flags>,
}

#[derive(Default)]
struct Flags {
    sweeping: AtomicBool,
    on: AtomicBool,
}

impl<E: Exchange<N> + Send, const N: usize> DeviceIo<N> for Swept<E> {
    fn exchange(&mut self, duty: [i16; N], on: bool) -> Result<RawSensors<N>, String> {
        if self.flags.sweeping.load(Ordering::Relaxed) {
            self.k = self.k.wrapping_add(1);
            self.device.sweep(40 - (self.k % 80 - 40).abs());
        }
        self.flags.on.store(on, Ordering::Relaxed);
        Ok(self.device.exchange(duty, on))
    }
}

/// The stepped loop, shared between the application's board and the
/// bench's ticks.
struct Port<P>(Rc<RefCell<P>>);

impl<P: BoardPort> BoardPort for Port<P> {
    fn send(&mut self, bytes: &[u8]) -> Result<(), LinkError> {
        self.0.borrow_mut().send(bytes)
    }
    fn recv(&mut self, buf: &mut [u8], timeout: Duration) -> Result<usize, LinkError> {
        self.0.borrow_mut().recv(buf, timeout)
    }
}

/// Arm `board` (the device at rest, its grip held) on the PC's loop,
/// stepped, and time its ticks with the encoders sweeping: each tick, a
/// host heartbeat sent and the board's bytes read back.
fn bench_device<K: Kinematics<f32, N> + Send, E: Exchange<N> + Send, const N: usize>(
    c: &mut Criterion,
    name: &str,
    board: PcLinkageBoard<K, N>,
    mut device: E,
    spec: &ImageSpec<N>,
) where
    LinkageWorld<N>: World<f32, N>,
{
    device.sweep(0);
    let flags = Arc::new(Flags::default());
    let io = Swept {
        device,
        k: 0,
        flags: Arc::clone(&flags),
    };
    let pc = Rc::new(RefCell::new(SteppedPc::new(board, io)));
    let mut b = HostBoard::open(Port(Rc::clone(&pc)), N as u8).unwrap();
    b.calibrate(&spec.rest_rad.map(f64::from)).unwrap();
    assert_eq!(b.arm().unwrap().mode, BoardMode::Armed);
    flags.sweeping.store(true, Ordering::Relaxed);
    let mut heartbeat = [0u8; MAX_FRAME];
    let n = encode(0, &Message::Heartbeat, &mut heartbeat).unwrap();
    let heartbeat = heartbeat[..n].to_vec();
    let mut buf = vec![0u8; 1 << 16];
    let mut tick = || {
        let mut pc = pc.borrow_mut();
        pc.send(&heartbeat).unwrap();
        black_box(pc.recv(&mut buf, Duration::ZERO).unwrap());
    };
    for _ in 0..1000 {
        tick();
    }
    assert!(
        flags.on.load(Ordering::Relaxed),
        "{name}: the board is still armed, its outputs on"
    );
    c.bench_function(name, |bench| bench.iter(&mut tick));
    drop(b);
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
            frame: HdFrame::default(),
            torque_mnm: [0.0; 3],
        },
        &TOUCH,
    );
}

criterion_group!(benches, pc_tick);
criterion_main!(benches);
