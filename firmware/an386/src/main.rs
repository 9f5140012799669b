//! The board loop on QEMU mps2-an386 (Cortex-M4F) for processor-in-the-loop
//! runs: the same `twoport-board` loop as the STM32F405 image, with its
//! sensors arriving and its PWM duty leaving as link frames on UART0, one
//! tick per sensor frame (lockstep with host-sim). Started by
//! `cargo xtask pil`; a panic or HardFault ends QEMU with a failure code.
//! With the `passivity` feature the image runs the series damper at the
//! actuator's port (`cargo xtask pil --passivity`); with `xyz`, the
//! three-axis Excalibur image on its building-block world (`cargo xtask
//! pil scenes/xyz/pil_blocks.toml`); with `serial-arm` or `delta`, a
//! linkage image (`twoport_board::linkage`: joint encoders in, joint
//! torques out; `cargo xtask pil --linkage serial-arm`). With `sim-device`
//! the Excalibur image runs free on its own clock (SysTick, 1 ms) against
//! a device simulated on the chip (`twoport_board::Simulated`: the
//! actuator's mass, a hand pushing 2 N along +x, a 1 µm encoder), so that
//! a host application drives it as it would a real board (`cargo xtask
//! device`).

#![no_std]
#![no_main]

mod uart;
mod watchdog;

use cortex_m::peripheral::syst::SystClkSource;
use cortex_m_rt::entry;
use cortex_m_semihosting::hprintln;

use twoport_config::{RamFlash, Store};
use twoport_qemu_exit::exit;

/// The watchdog's time-out (ms): the reset follows a second one, so a
/// hung loop is reset within 100 ms.
const WATCHDOG_MS: u32 = 50;

#[entry]
fn main() -> ! {
    #[cfg(not(any(
        feature = "passivity",
        feature = "xyz",
        feature = "serial-arm",
        feature = "delta",
        feature = "sim-device",
        feature = "fast"
    )))]
    let board = twoport_board::excalibur::stiff_wall_board().map_err(|_| ());
    #[cfg(feature = "fast")]
    let board = twoport_board::excalibur::fast::board().map_err(|_| ());
    #[cfg(feature = "passivity")]
    let board = twoport_board::excalibur::stiff_wall_board_with_passivity().map_err(|_| ());
    #[cfg(feature = "xyz")]
    let board = twoport_board::excalibur::xyz::board().map_err(|_| ());
    #[cfg(feature = "serial-arm")]
    let board = twoport_board::linkage::serial_arm_board().map_err(|_| ());
    #[cfg(feature = "delta")]
    let board = twoport_board::linkage::delta_board().map_err(|_| ());
    #[cfg(feature = "sim-device")]
    let board = twoport_board::excalibur::stiff_wall_board().map_err(|_| ());
    // SysTick runs at the 25 MHz core clock; under -icount QEMU advances it
    // 1.6 counts an instruction, its model of the core's cycles.
    let board = board.map(|b| {
        b.with_pil(!cfg!(feature = "sim-device"))
            .with_count_rate(watchdog::CLOCK_HZ)
    });
    let Ok(mut board) = board else {
        hprintln!("the board image would not build");
        exit(false)
    };
    // QEMU's board has no flash for it: the configuration lives in RAM,
    // so every boot reports the defaults, and why (nothing stored).
    let mut store = Store::new(RamFlash::<512, 256>::new(), 0, 256);
    board.boot_config(&mut store);
    // A hung loop was reset by the watchdog: say so, latched, so that the
    // board stays disarmed until the host has seen it and cleared it.
    if watchdog::reset_by_watchdog() {
        board.trip(twoport_control::Faults::WATCHDOG_RESET);
        hprintln!("twoport-an386: restarted by the watchdog");
    }
    let mut io = uart::Uart::take();
    io.watchdog = Some(watchdog::Watchdog::start(WATCHDOG_MS));
    // SysTick times each tick; with `-icount shift=N` it is a
    // deterministic function of the instructions executed.
    if let Some(mut p) = cortex_m::Peripherals::take() {
        p.SYST.set_clock_source(SystClkSource::Core);
        p.SYST.set_reload(0x00FF_FFFF);
        p.SYST.clear_current();
        p.SYST.enable_counter();
    }
    #[cfg(feature = "sim-device")]
    run_free(board, io, store);
    #[cfg(not(feature = "sim-device"))]
    run_lockstep(board, io, store);
}

/// Lockstep: each control tick waits for the host's sensor frame.
#[cfg(not(feature = "sim-device"))]
fn run_lockstep<D: twoport_control::drive::Drive<N>, const R: usize, const N: usize>(
    mut board: twoport_board::Board<D, R, N>,
    mut io: uart::Uart,
    mut store: Store<RamFlash<512, 256>>,
) -> ! {
    hprintln!("twoport-an386: board loop up, waiting on UART0");
    #[cfg(feature = "watchdog-test")]
    let mut armed_ticks = 0u32;
    loop {
        board.control_tick_serving(&mut io, |b| b.service_config(&mut store));
        board.service_config(&mut store);
        board.flush(&mut io);
        // The watchdog test's image hangs on purpose after 1,500 armed
        // ticks, as a loop stuck in a bug would.
        #[cfg(feature = "watchdog-test")]
        {
            if board.mode() == twoport_link::BoardMode::Armed {
                armed_ticks += 1;
            }
            if armed_ticks == 1500 {
                hprintln!("twoport-an386: hanging on purpose (watchdog test)");
                #[allow(clippy::empty_loop)]
                loop {}
            }
        }
    }
}

/// SysTick counts per control tick: the board's 25 MHz core clock over
/// the Excalibur's 1 kHz.
#[cfg(feature = "sim-device")]
const CYCLES_PER_TICK: u32 = 25_000;

/// Ticks the simulated board waits for its host's heartbeat.
#[cfg(feature = "sim-device")]
const HOST_PATIENCE_TICKS: u32 = 500;

/// Link bytes read between looks at the clock.
#[cfg(feature = "sim-device")]
const BYTES_PER_LOOK: usize = 32;

/// The hand's push on the simulated handle (N, along +x).
#[cfg(feature = "sim-device")]
const HAND_N: f32 = 2.0;

/// The free-running board: a control tick each period of its own clock,
/// its sensors from the simulated device, and the link served between
/// ticks, as a board with real hardware runs.
#[cfg(feature = "sim-device")]
fn run_free(
    mut board: twoport_board::Board<
        twoport_control::Servo<twoport_control::ve::UnilateralWall>,
        { twoport_board::excalibur::REGION_POINTS },
    >,
    mut io: uart::Uart,
    mut store: Store<RamFlash<512, 256>>,
) -> ! {
    use twoport_board::{excalibur, BoardSupport, IoScale, SimAxis, Simulated};
    io.cycles_per_tick = CYCLES_PER_TICK;
    // QEMU shares the machine's cores with the host application it serves,
    // so a busy machine stalls the host for longer than a board's own would:
    // this board waits half a second for its heartbeat (the shipped image,
    // 50 ms).
    let mut cfg = board.config();
    for c in &mut cfg {
        c.limits.heartbeat_timeout_ticks = HOST_PATIENCE_TICKS;
    }
    if board.apply_config(&cfg).is_err() {
        hprintln!("twoport-an386: the simulated device's limits would not apply");
        exit(false)
    }
    let mut dev = Simulated::new(
        io,
        [SimAxis::excalibur(HAND_N)],
        [IoScale::EXCALIBUR],
        excalibur::ENCODER,
        excalibur::PERIOD_S,
    );
    hprintln!("twoport-an386: simulated device, running free, link on UART0");
    let mut next = dev.cycles();
    // The frame going out, and how much of it has.
    let mut out: Option<(twoport_board::Frame, usize)> = None;
    loop {
        // The link never holds off a tick, as a real board's timer
        // interrupt would not let it: a few bytes in at a time, and out
        // only what the UART takes now (a host that reads slowly loses
        // the oldest telemetry in the board's queue, not ticks).
        for _ in 0..BYTES_PER_LOOK {
            let Some(byte) = dev.read_byte() else { break };
            board.on_bytes(&[byte]);
        }
        board.service_config(&mut store);
        loop {
            if out.is_none() {
                out = board.pop_tx().map(|f| (f, 0));
            }
            let Some((frame, sent)) = &mut out else { break };
            if !dev.inner().try_send(frame[*sent]) {
                break;
            }
            *sent += 1;
            if *sent == frame.len() {
                out = None;
            }
        }
        if dev.cycles().wrapping_sub(next) as i32 >= 0 {
            next = next.wrapping_add(CYCLES_PER_TICK);
            board.control_tick(&mut dev);
        }
    }
}
