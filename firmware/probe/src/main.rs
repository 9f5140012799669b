//! On-target tests of the control laws: the same f32 code the board runs,
//! checked in QEMU (Cortex-M4F) against its own z-domain forms. Prints one
//! line per check and `N passed, M failed`; exits through semihosting with
//! failure on any failed check, panic or HardFault.

#![no_std]
#![no_main]

use cortex_m_rt::entry;
use cortex_m_semihosting::hprintln;
use twoport_control::servo::SensorFrame;
use twoport_control::ve::{
    BilateralConstraint, CursorMass, Solid, UnilateralWall, VeTransfer, VirtualEnvironment,
};
use twoport_control::{
    AdmittanceCoupling, Complex64, Encoder, Faults, FirstDifference, ImpedanceCoupling,
    ImpedanceGains, Position, SafetyConfig, SafetyLayer, Servo, SineProbe, ZTransfer,
};
use twoport_qemu_exit::exit;

const T: f32 = 1.0e-3;
const WINDOW: u32 = 4000;
const SETTLE: u32 = 3000;
const BINS: [u32; 4] = [3, 130, 1200, 1990];

struct Tally {
    passed: u32,
    failed: u32,
}

impl Tally {
    fn check(&mut self, name: &str, ok: bool) {
        if ok {
            self.passed += 1;
            hprintln!("PASS {}", name);
        } else {
            self.failed += 1;
            hprintln!("FAIL {}", name);
        }
    }
}

/// One instruction count, as `COUNT <name> <instructions> <what>`: the
/// line `cargo xtask qemu` checks against `firmware/probe/counts.txt`.
fn count(name: &str, instructions: f32, what: &str) {
    hprintln!("COUNT {} {} {}", name, instructions, what);
}

fn z_of(p: u32) -> Complex64 {
    let th = 2.0 * core::f64::consts::PI * p as f64 / WINDOW as f64;
    Complex64::new(libm::cos(th), libm::sin(th))
}

/// Relative distance between two complex numbers.
fn rel(got: Complex64, want: Complex64) -> f64 {
    let d = got - want;
    libm::sqrt(d.norm_sqr() / want.norm_sqr())
}

fn measure(p: u32, tick: impl FnMut(f64) -> (f64, f64)) -> Complex64 {
    let z = z_of(p);
    SineProbe::measure(z.re, z.im, SETTLE, WINDOW, tick)
}

fn pm(x_m: f64) -> Position {
    Position::from_m_f64(x_m).unwrap_or(Position::ZERO)
}

fn ve_tf(t: VeTransfer) -> ZTransfer {
    match t {
        VeTransfer::Admittance(t) | VeTransfer::Impedance(t) => t,
    }
}

fn impedance_coupling(t: &mut Tally) {
    let mut worst = 0.0f64;
    for p in BINS {
        let mut est = FirstDifference::new(T, Position::ZERO).unwrap();
        let mut c = ImpedanceCoupling::new(51_000.0, 90.0, T).unwrap();
        let mut ve = BilateralConstraint::new(Position::ZERO);
        let got = measure(p, |u| {
            let x = pm(1e-3 * u);
            let v = est.step(x);
            (v as f64, c.step(x, v, &mut ve).force_n as f64)
        });
        worst = worst.max(rel(got, c.tf().eval(z_of(p))));
    }
    hprintln!("  Z_cI worst relative error {:e}", worst);
    t.check("Z_cI response equals its z-domain form", worst <= 1e-4);
}

fn admittance_coupling_with_cursor(t: &mut Tally) {
    let mut worst = 0.0f64;
    for p in BINS {
        let mut c = AdmittanceCoupling::new(5.0, 500.0, T).unwrap();
        let mut ve = CursorMass::new(0.25, T, Position::ZERO).unwrap();
        let got = measure(p, |u| {
            let f = (30.0 * u) as f32;
            (f as f64, c.step(f, &mut ve).velocity_mps as f64)
        });
        let z = z_of(p);
        let want = (c.tf().eval(z) + ve_tf(ve.tf()).eval(z).inv()).inv();
        worst = worst.max(rel(got, want));
    }
    hprintln!("  Z_cA + cursor worst relative error {:e}", worst);
    t.check("Fig. 7(d) loop solved exactly on target", worst <= 1e-4);
}

fn servo_wall_and_fault(t: &mut Tally) {
    let enc = Encoder::new(16, 1_000_000, 0, Position::ZERO).unwrap();
    let wall = UnilateralWall::new(
        20_000.0,
        50.0,
        Position::ZERO,
        Solid::Above,
        T,
        Position::ZERO,
    )
    .unwrap();
    let mut s = paper_servo(enc, wall);
    let _ = s.enable();
    let mut f = 0.0;
    let mut k = 0u32;
    while k < 3000 {
        f = s
            .tick(&SensorFrame::held(k, [k.min(1000) * 2], [0.0]))
            .actuator_force_n[0];
        k += 1;
    }
    let want = 2e-3 / (1.0 / 51_000.0 + 1.0 / 20_000.0);
    t.check(
        "wall renders the series stiffness",
        libm::fabsf(f - want) < 1e-3 * want,
    );
    let out = s.tick(&SensorFrame::held(k, [0x1_0000], [0.0]));
    t.check(
        "invalid encoder value gives zero force in the same tick",
        out.actuator_force_n[0] == 0.0 && out.faults.contains(Faults::ENCODER_INVALID),
    );
}

/// The wall the cost measurements push into: 0.5 mm from the start, so the
/// encoder sweep (0 to 2 mm) is in contact three quarters of the time.
fn timing_wall() -> UnilateralWall {
    UnilateralWall::new(
        1e5,
        50.0,
        Position::from_nm(500_000),
        Solid::Above,
        T,
        Position::ZERO,
    )
    .unwrap()
}

/// The impedance display at the paper's coupling on `wall`.
fn paper_servo(enc: Encoder, wall: UnilateralWall) -> Servo<UnilateralWall> {
    let gains = ImpedanceGains::new(51_000.0, 90.0);
    Servo::new([gains.into()], [enc], [SafetyConfig::excalibur()], wall).unwrap()
}

/// The servo tick's cost in QEMU: SysTick counts the 25 MHz system clock, and
/// with `-icount shift=6` each instruction takes 64 ns of virtual time, so
/// one instruction is 1.6 counts (deterministic, unlike wall time).
fn tick_cost(t: &mut Tally, syst: &mut cortex_m::peripheral::SYST) {
    use cortex_m::peripheral::syst::SystClkSource;
    let enc = Encoder::new(16, 1_000_000, 0, Position::ZERO).unwrap();
    let wall = timing_wall();
    let mut s = paper_servo(enc, wall);
    let _ = s.enable();
    syst.set_clock_source(SystClkSource::Core);
    syst.set_reload(0x00FF_FFFF);
    syst.clear_current();
    syst.enable_counter();
    let (per_tick, empty) = counts_per_call(1000, |k| {
        let f = SensorFrame::held(k, [core::hint::black_box(k % 1000 * 2)], [0.0]);
        s.tick(&f).actuator_force_n[0]
    });
    count("empty_loop", empty / 1.6, "an empty loop's iteration");
    count(
        "impedance_tick",
        per_tick / 1.6,
        "impedance servo tick (encoder, estimator, Z_cI, wall, safety)",
    );
    t.check("servo tick measured", per_tick > 0.0);
}

/// The three-axis impedance tick in QEMU: three encoders and couplings,
/// the safety layer over the force vector, and either a wall on every axis
/// (the same sweep into each as the one-axis tick's) or the building-block
/// world of 50 blocks with the cursor pressing into one's top.
fn tick_cost_axes(t: &mut Tally) {
    use twoport_control::world::vbb::{Block, Vbb, VbbConfig};
    use twoport_control::world::PerAxis;
    let enc = Encoder::new(16, 1_000_000, 0, Position::ZERO).unwrap();
    let gains = ImpedanceGains::new(51_000.0, 90.0).into();
    let safety = [SafetyConfig::excalibur(); 3];
    let sweep = |k: u32| {
        let raw = core::hint::black_box(k % 1000 * 2);
        SensorFrame {
            tick: k,
            encoder_raw: [raw; 3],
            load_cell_n: [0.0; 3],
            dead_man_closed: true,
        }
    };
    let walls = PerAxis([timing_wall(); 3]);
    let mut s = Servo::new([gains; 3], [enc; 3], safety, walls).unwrap();
    let _ = s.enable();
    let (per_tick, _) = counts_per_call(1000, |k| s.tick(&sweep(k)).actuator_force_n[2]);
    count(
        "xyz_walls_tick",
        per_tick / 1.6,
        "3-axis impedance servo tick, a wall on each axis",
    );
    // 50 blocks of 20 mm in a 10 x 5 grid on the floor; the cursor rests on
    // the middle one's top and the device sweeps 2 mm into it along z.
    let mut blocks = [Block::new([0.0; 3], [0.02; 3], 0.1).unwrap(); 50];
    for (i, b) in blocks.iter_mut().enumerate() {
        let (x, y) = (
            (i % 10) as f32 * 0.025 - 0.125,
            (i / 10) as f32 * 0.025 - 0.0625,
        );
        *b = Block::new([x, y, 0.0], [0.02; 3], 0.1).unwrap();
    }
    let mut cfg = VbbConfig::excalibur(T);
    cfg.held_weight = true;
    let world = Vbb::<f32, 50>::new(cfg, &blocks).unwrap();
    let mut s = Servo::new([gains; 3], [enc; 3], safety, world).unwrap();
    let top = blocks[25];
    let x = |a: usize| top.min[a].offset_nm(top.size_nm[a] / 2);
    s.calibrate([x(0), x(1), top.min[2].offset_nm(top.size_nm[2] + 1_000_000)]);
    let _ = s.enable();
    let down = |k: u32| {
        let raw = core::hint::black_box((k % 1000 * 2).wrapping_neg() & 0xFFFF);
        SensorFrame {
            encoder_raw: [0, 0, raw],
            ..sweep(k)
        }
    };
    // (100 ticks: 1,000 of them would run SysTick's 24-bit count over.)
    let (per_tick, _) = counts_per_call(100, |k| s.tick(&down(k)).actuator_force_n[2]);
    count(
        "xyz_blocks50_tick",
        per_tick / 1.6,
        "3-axis impedance servo tick on the 50-block world",
    );
    t.check(
        "3-axis tick measured",
        per_tick > 0.0 && s.safety().faults().is_empty(),
    );
}

/// A 3-DOF linkage's tick in QEMU: three joint encoders, the kinematics
/// and Jacobian, the three-axis Cartesian servo with a wall on each axis,
/// `J^T f`, gravity held up as the linkage images do, and the motors'
/// limits. The joints sweep back and forth (a
/// triangle of 300 counts), so the handle passes in and out of the walls.
fn tick_cost_linkage(t: &mut Tally) {
    use twoport_control::kinematics::{Delta, Kinematics, SerialArm};
    use twoport_control::linkage::{Gravity, JointEncoder, LinkageServo, MotorConfig};
    use twoport_control::world::{PerAxis, World};
    /// The walls as their own world type. A board image runs one servo,
    /// whose tick the compiler inlines into the loop; here the Cartesian
    /// three-axis probe shares `PerAxis<UnilateralWall, 3>`, and two
    /// callers of one instantiation would keep it out of line in both.
    struct Walls(PerAxis<UnilateralWall, 3>);
    impl World<f32, 3> for Walls {
        #[inline(always)]
        fn step_axes(
            &mut self,
            ports: &[twoport_control::ve::Port<f32>; 3],
        ) -> [twoport_control::ve::VeOutput<f32>; 3] {
            self.0.step_axes(ports)
        }
        #[inline(always)]
        fn offsets_m(&self, x: &[Position; 3]) -> [f32; 3] {
            self.0.offsets_m(x)
        }
        fn reset_axes(&mut self, x: &[Position; 3]) {
            self.0.reset_axes(x)
        }
        fn positions(&self) -> [Position; 3] {
            self.0.positions()
        }
        fn axis_tf(&self, axis: usize) -> VeTransfer {
            self.0.axis_tf(axis)
        }
    }
    fn run<K: Kinematics<f32, 3> + Copy>(
        t: &mut Tally,
        k: K,
        q0: [f32; 3],
        counts_per_rev: f32,
        gravity: Gravity,
        name: &str,
        what: &str,
    ) {
        let Ok(start) = k.forward(&q0) else {
            t.check(name, false);
            return;
        };
        let walls = Walls(PerAxis(core::array::from_fn(|i| {
            let at = Position::from_m(start.position_m[i] + 0.002).unwrap_or(Position::ZERO);
            let here = Position::from_m(start.position_m[i]).unwrap_or(Position::ZERO);
            UnilateralWall::new(2_000.0, 2.0, at, Solid::Above, T, here).unwrap()
        })));
        let joints = q0.map(|q| JointEncoder::new(16, counts_per_rev, 0, q).unwrap());
        let gains = ImpedanceGains::new(800.0, 1.0).into();
        let mut safety = SafetyConfig::new(T, 10.0, 4.0);
        safety.max_velocity_mps = 10.0;
        let limits = [[-3.0, 3.0], [-3.0, 3.0], [-3.0, 4.0]];
        let motors = [MotorConfig::new(1.0, 0.4); 3];
        let Ok(mut s) =
            LinkageServo::new(k, joints, limits, [gains; 3], [safety; 3], motors, walls)
                .map_err(|_| ())
                .and_then(|s| s.with_gravity(gravity).map_err(|_| ()))
        else {
            t.check(name, false);
            return;
        };
        let _ = s.enable();
        let sweep = |k: u32| {
            let p = k % 600;
            let c = core::hint::black_box(if p < 300 { p } else { 600 - p });
            SensorFrame {
                tick: k,
                encoder_raw: [c, c, c.wrapping_neg() & 0xFFFF],
                load_cell_n: [0.0; 3],
                dead_man_closed: true,
            }
        };
        let (per_tick, _) = counts_per_call(1000, |k| s.tick(&sweep(k)).torque_nm[2]);
        count(name, per_tick / 1.6, what);
        t.check(
            name,
            per_tick > 0.0 && s.cartesian().safety().faults().is_empty(),
        );
    }
    let arm = SerialArm::new(0.215, 0.17).unwrap();
    run(
        t,
        arm,
        [0.1, 0.3, 1.0],
        26_600.0,
        Gravity::SerialArm {
            upper_nm: -0.0163,
            fore_nm: -0.0738,
        },
        "serial_arm_tick",
        "3-DOF serial arm tick (joints, kinematics, Jacobian, walls, safety, J^T f, gravity)",
    );
    let delta = Delta::new(0.04, 0.02309, 0.06, 0.1025).unwrap();
    run(
        t,
        delta,
        [0.5, 0.5, 0.5],
        2_470.0,
        Gravity::Handle { weight_n: 0.5886 },
        "delta_tick",
        "3-DOF delta tick (joints, forward solve, Jacobian, walls, safety, J^T f, gravity)",
    );
}

/// The same tick with the passivity layer (the series damper) between the
/// device and the coupling, in two sweeps: pressing into the wall (the
/// element takes energy in, the layer only books it) and withdrawing from
/// it (the wall gives its energy back plus what the hold adds, and the
/// layer damps from the second tick on).
fn tick_cost_layered(t: &mut Tally) {
    use twoport_control::passivity::{PassivityLimits, SeriesDamper};
    let limits = PassivityLimits::for_device(0.7, T, 200.0).unwrap();
    let layered = |first_raw: u32| {
        let origin = Position::from_nm(first_raw as i32 * 1000);
        let enc = Encoder::new(16, 1_000_000, first_raw, origin).unwrap();
        let pc = SeriesDamper::new(limits).unwrap();
        let mut s = paper_servo(enc, timing_wall()).with_layers([pc]).unwrap();
        let _ = s.enable();
        s
    };
    let mut s = layered(0);
    let (pressing, _) = counts_per_call(1000, |k| {
        let f = SensorFrame::held(k, [core::hint::black_box(k * 2)], [0.0]);
        s.tick(&f).actuator_force_n[0]
    });
    let passive = s.layers()[0].damping_nspm() == 0.0 && s.safety().faults().is_empty();
    let mut s = layered(2000);
    let (withdrawing, _) = counts_per_call(1000, |k| {
        let f = SensorFrame::held(k, [core::hint::black_box(2000 - k * 2)], [0.0]);
        s.tick(&f).actuator_force_n[0]
    });
    // The same sweep again, untimed, to count the ticks the layer damped.
    let mut s = layered(2000);
    let mut damped = 0u32;
    for k in 0..1000 {
        s.tick(&SensorFrame::held(k, [2000 - k * 2], [0.0]));
        damped += (s.layers()[0].damping_nspm() > 0.0) as u32;
    }
    count(
        "series_damper_pressing_tick",
        pressing / 1.6,
        "impedance tick with the series damper, pressing (passive)",
    );
    count(
        "series_damper_withdrawing_tick",
        withdrawing / 1.6,
        "impedance tick with the series damper, withdrawing (damping)",
    );
    hprintln!("  the series damper damped on {} of 1000 ticks", damped);
    t.check("passivity layer idle while pressing", passive);
    t.check(
        "passivity layer damping while withdrawing",
        damped > 900 && s.safety().faults().is_empty(),
    );
}

/// The tick with the passivity layer at the VE's port (`PassiveVe`): the
/// impedance display at the paper's coupling on an explicitly integrated
/// 50 g cursor (the paper's building-block integrator), the device
/// sweeping 2 mm. Also what an `f64` energy sum would cost against the
/// `f32` compensated one.
fn tick_cost_ve_port(t: &mut Tally) {
    use twoport_control::passivity::{CompensatedSum, ParallelLimits, PassiveVe};
    use twoport_control::ve::ExplicitCursor;
    let servo = || {
        let enc = Encoder::new(16, 1_000_000, 0, Position::ZERO).unwrap();
        let cursor = ExplicitCursor::new_in(0.05, T, Position::ZERO).unwrap();
        let limits = ParallelLimits::for_display(0.05, T, 1.0).unwrap();
        let ve = PassiveVe::new(cursor, limits).unwrap();
        let gains = ImpedanceGains::new(51_000.0, 90.0);
        let mut s = Servo::new([gains.into()], [enc], [SafetyConfig::excalibur()], ve).unwrap();
        let _ = s.enable();
        s
    };
    let sweep = |k: u32| SensorFrame::held(k, [core::hint::black_box(k % 1000 * 2)], [0.0]);
    let mut s = servo();
    let (per_tick, _) = counts_per_call(1000, |k| s.tick(&sweep(k)).actuator_force_n[0]);
    let mut s = servo();
    let mut acting = 0u32;
    for k in 0..1000 {
        s.tick(&sweep(k));
        acting += (s.world().conductance_mpns() > 0.0) as u32;
    }
    count(
        "ve_port_layer_tick",
        per_tick / 1.6,
        "impedance tick with the passivity layer at the VE's port",
    );
    hprintln!("  the VE-port layer acted on {} of 1000 ticks", acting);
    // The same servo on a bare cursor, for the layer's share. A bare 50 g
    // cursor rings up and trips the safety layer, so this one is the
    // paper's 0.25 kg: the cursor's code is the same for any mass.
    let enc = Encoder::new(16, 1_000_000, 0, Position::ZERO).unwrap();
    let cursor = ExplicitCursor::new_in(0.25, T, Position::ZERO).unwrap();
    let gains = ImpedanceGains::new(51_000.0, 90.0);
    let mut bare = Servo::new([gains.into()], [enc], [SafetyConfig::excalibur()], cursor).unwrap();
    let _ = bare.enable();
    let (bare_tick, _) = counts_per_call(1000, |k| bare.tick(&sweep(k)).actuator_force_n[0]);
    count(
        "explicit_cursor_tick",
        bare_tick / 1.6,
        "the same tick on a bare explicit cursor (0.25 kg)",
    );
    let mut c = CompensatedSum::<f32>::new();
    let (kahan, _) = counts_per_call(1000, |k| {
        c.add(core::hint::black_box(k as f32 * 1e-6));
        c.value()
    });
    let mut d = 0.0f64;
    let (double, _) = counts_per_call(1000, |k| {
        d += core::hint::black_box(k as f32 * 1e-6) as f64;
        d as f32
    });
    count(
        "energy_sum_f32",
        kahan / 1.6,
        "energy sum per term, f32 compensated",
    );
    count(
        "energy_sum_f64",
        double / 1.6,
        "energy sum per term, f64 (soft float)",
    );
    t.check(
        "VE-port layer measured",
        per_tick > 0.0 && acting > 0 && bare.safety().faults().is_empty(),
    );
}

/// SysTick counts per call of `f` over `n` calls, less the loop's own
/// cost; and that cost, per iteration of an empty loop.
fn counts_per_call(n: u32, mut f: impl FnMut(u32) -> f32) -> (f32, f32) {
    use cortex_m::peripheral::SYST;
    let mut sink = 0.0f32;
    let start = SYST::get_current();
    for k in 0..n {
        sink += core::hint::black_box(k as f32);
    }
    let empty = start.wrapping_sub(SYST::get_current()) & 0x00FF_FFFF;
    let start = SYST::get_current();
    for k in 0..n {
        sink += f(core::hint::black_box(k));
    }
    let used = start.wrapping_sub(SYST::get_current()) & 0x00FF_FFFF;
    core::hint::black_box(sink);
    (
        used.saturating_sub(empty) as f32 / n as f32,
        empty as f32 / n as f32,
    )
}

/// Where a tick's instructions go: each stage of the impedance-display
/// tick alone (SysTick is already running; 1.6 counts per instruction).
fn cost_breakdown() {
    use twoport_control::safety::SafetyInputs;
    let n = 1000;
    let mut enc = Encoder::new(16, 1_000_000, 0, Position::ZERO).unwrap();
    let mut est = FirstDifference::new(T, Position::ZERO).unwrap();
    let (sense, _) = counts_per_call(n, |k| {
        let p = enc.update(k % 1000 * 2).unwrap_or(Position::ZERO);
        est.step(p)
    });
    let mut c = ImpedanceCoupling::new(51_000.0, 90.0, T).unwrap();
    let mut wall = timing_wall();
    let (law, _) = counts_per_call(n, |k| {
        let x = Position::from_nm((k % 1000 * 2) as i32 * 1000);
        c.step(x, 0.01, &mut wall).force_n
    });
    let mut safety = SafetyLayer::new(SafetyConfig::excalibur()).unwrap();
    let _ = safety.enable();
    let (safe, _) = counts_per_call(n, |k| {
        let i = SafetyInputs {
            tick: k,
            dead_man_closed: true,
            velocity_mps: 0.01,
            sensor_faults: Faults::NONE,
        };
        safety.step(&i, (k % 7) as f32).force_n
    });
    count(
        "stage_sense",
        sense / 1.6,
        "tick stage: encoder and estimator",
    );
    count(
        "stage_coupling_wall",
        law / 1.6,
        "tick stage: coupling and wall",
    );
    count("stage_safety", safe / 1.6, "tick stage: safety layer");
}

#[entry]
fn main() -> ! {
    let mut t = Tally {
        passed: 0,
        failed: 0,
    };
    impedance_coupling(&mut t);
    admittance_coupling_with_cursor(&mut t);
    servo_wall_and_fault(&mut t);
    if let Some(mut p) = cortex_m::Peripherals::take() {
        tick_cost(&mut t, &mut p.SYST);
        tick_cost_layered(&mut t);
        tick_cost_ve_port(&mut t);
        tick_cost_axes(&mut t);
        tick_cost_linkage(&mut t);
        cost_breakdown();
    }
    hprintln!("{} passed, {} failed", t.passed, t.failed);
    exit(t.failed == 0)
}
