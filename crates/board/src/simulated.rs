//! A device simulated on the board itself, for trying a host application
//! without hardware: the same loop, the same link, the same safety layer,
//! with each axis's sensors read from a simulated mass instead of the
//! peripherals. The image built with it runs free on its own timer, as a
//! real board does (the QEMU board a host application drives), and a host
//! test runs it in-process the same way.

use crate::io::{EncoderScale, IoScale};
use crate::support::{BoardSupport, RawSensors};

/// One axis of the simulated device: a rigid mass with viscous damping,
/// pushed by its motor and by a hand with a constant force, above a hard
/// stop where it has one (what homing drives into). The hand leans on the
/// handle only while the amplifier's outputs are on (it lets go of a
/// handle that does not push back, which would otherwise drift off before
/// the host arms the board). The load cell reads the hand's force.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SimAxis {
    /// The moving mass (kg).
    pub mass_kg: f32,
    /// Its viscous damping to ground (N s/m).
    pub damping_nspm: f32,
    /// The hand's force along +x (N) while the outputs are on.
    pub hand_n: f32,
    /// Where the mass starts (m).
    pub start_m: f32,
    /// A rigid stop below which the mass cannot go (m), or none: the mass
    /// stops dead on it.
    pub stop_m: Option<f32>,
}

impl SimAxis {
    /// The Excalibur's actuator mass (0.93 kg) with 4 N s/m of damping,
    /// at rest at the origin, the hand pushing with `hand_n`, a stop 30 mm
    /// below (the Excalibur image homes toward negative positions).
    pub const fn excalibur(hand_n: f32) -> Self {
        SimAxis {
            mass_kg: 0.93,
            damping_nspm: 4.0,
            hand_n,
            start_m: 0.0,
            stop_m: Some(-0.03),
        }
    }
}

/// A simulated device of `N` axes behind the board support `S`, which
/// keeps the link, the clock and the watchdog. Each
/// [`sample`](BoardSupport::sample) advances the device one period under
/// the duty the loop last commanded (semi-implicit Euler, in f32): the
/// loop is one tick late on the device, as it is on hardware. The dead-man
/// switch is closed (the hand is on), and the amplifier gives force only
/// while its outputs are on.
#[derive(Clone, Debug)]
pub struct Simulated<S, const N: usize> {
    inner: S,
    axes: [SimAxis; N],
    io: [IoScale; N],
    /// The encoder.
    encoder: EncoderScale,
    period_s: f32,
    x_m: [f32; N],
    v_mps: [f32; N],
    duty: [i16; N],
    outputs_on: bool,
    /// When the last sample's sensors were latched, and when the force
    /// computed from them was applied, in the inner support's count.
    latched: u32,
    applied: Option<u32>,
}

impl<S, const N: usize> Simulated<S, N> {
    /// `axes` simulated behind `inner`, their motors scaled by `io`, read by
    /// `encoder`, stepped every `period_s` (s).
    pub fn new(
        inner: S,
        axes: [SimAxis; N],
        io: [IoScale; N],
        encoder: EncoderScale,
        period_s: f32,
    ) -> Self {
        Simulated {
            inner,
            axes,
            io,
            encoder,
            period_s,
            x_m: axes.map(|a| a.start_m),
            v_mps: [0.0; N],
            duty: [0; N],
            outputs_on: false,
            latched: 0,
            applied: None,
        }
    }

    /// Each axis's position (m).
    pub fn position_m(&self) -> [f32; N] {
        self.x_m
    }

    /// Each axis's velocity (m/s).
    pub fn velocity_mps(&self) -> [f32; N] {
        self.v_mps
    }

    /// The board support behind the device.
    pub fn inner(&mut self) -> &mut S {
        &mut self.inner
    }

    /// The encoder's count for `x_m`, wrapped to its counter.
    fn count(&self, x_m: f32) -> u32 {
        let EncoderScale {
            bits,
            pm_per_count: pm,
        } = self.encoder;
        // The nearest count: floor(y + 1/2), without libm.
        let y = f64::from(x_m) * 1e12 / pm as f64 + 0.5;
        let t = y as i64;
        let c = if (t as f64) > y { t - 1 } else { t };
        let mask = if bits >= 32 {
            u32::MAX
        } else {
            (1u32 << bits) - 1
        };
        (c as u32) & mask
    }
}

impl<S: BoardSupport<N>, const N: usize> BoardSupport<N> for Simulated<S, N> {
    fn sample(&mut self) -> RawSensors<N> {
        let t = self.period_s;
        for i in 0..N {
            let a = &self.axes[i];
            // f_a resists positive motion: the motor pushes with -f_a.
            let (motor, hand) = match self.outputs_on {
                true => (self.io[i].force_n(self.duty[i]), a.hand_n),
                false => (0.0, 0.0),
            };
            let f = hand - motor - a.damping_nspm * self.v_mps[i];
            self.v_mps[i] += t * f / a.mass_kg;
            self.x_m[i] += t * self.v_mps[i];
            if let Some(stop) = a.stop_m {
                if self.x_m[i] < stop {
                    self.x_m[i] = stop;
                    self.v_mps[i] = self.v_mps[i].max(0.0);
                }
            }
        }
        let raw = RawSensors {
            encoder_raw: core::array::from_fn(|i| self.count(self.x_m[i])),
            load_cell_counts: core::array::from_fn(|i| {
                let hand = if self.outputs_on {
                    self.axes[i].hand_n
                } else {
                    0.0
                };
                self.io[i].load_cell_counts(hand)
            }),
            dead_man_closed: true,
            index_raw: [None; N],
        };
        // The simulated sensors are latched once the device's step is
        // done: the step is the device's time, not the loop's latency.
        self.latched = self.inner.cycles();
        self.applied = None;
        raw
    }

    fn set_duty(&mut self, duty: [i16; N]) {
        self.applied = Some(self.inner.cycles());
        self.duty = duty;
        self.inner.set_duty(duty);
    }

    fn force_latency(&self) -> Option<u32> {
        self.applied.map(|a| a.wrapping_sub(self.latched))
    }

    fn set_outputs(&mut self, on: bool) {
        self.outputs_on = on;
        self.inner.set_outputs(on);
    }

    fn feed_watchdog(&mut self) {
        self.inner.feed_watchdog();
    }

    fn read_byte(&mut self) -> Option<u8> {
        self.inner.read_byte()
    }

    fn write(&mut self, bytes: &[u8]) {
        self.inner.write(bytes);
    }

    fn cycles(&mut self) -> u32 {
        self.inner.cycles()
    }

    fn cycles_per_tick(&self) -> u32 {
        self.inner.cycles_per_tick()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// No hardware behind the device: nothing on the link, no clock.
    struct Nothing;

    impl BoardSupport<1> for Nothing {
        fn sample(&mut self) -> RawSensors<1> {
            RawSensors::default()
        }
        fn set_duty(&mut self, _: [i16; 1]) {}
        fn set_outputs(&mut self, _: bool) {}
        fn feed_watchdog(&mut self) {}
        fn read_byte(&mut self) -> Option<u8> {
            None
        }
        fn write(&mut self, _: &[u8]) {}
        fn cycles(&mut self) -> u32 {
            0
        }
        fn cycles_per_tick(&self) -> u32 {
            0
        }
    }

    fn device(hand_n: f32) -> Simulated<Nothing, 1> {
        Simulated::new(
            Nothing,
            [SimAxis::excalibur(hand_n)],
            [IoScale::EXCALIBUR],
            crate::excalibur::ENCODER,
            1e-3,
        )
    }

    /// The hand alone (the motor at zero duty) accelerates the mass
    /// against its damping: the velocity follows `F/b (1 - e^(-b t/m))`
    /// to 1%, the encoder reads the position to its count, and the load
    /// cell the hand.
    #[test]
    fn the_hand_moves_the_mass_as_its_equation_says() {
        let mut d = device(2.0);
        d.set_outputs(true);
        let mut s = RawSensors::default();
        for _ in 0..500 {
            s = d.sample();
        }
        let (f, b, m) = (2.0f32, 4.0f32, 0.93f32);
        let want = f / b * (1.0 - (-b * 0.5 / m).exp());
        let v = d.velocity_mps()[0];
        assert!((v / want - 1.0).abs() < 0.01, "{v} against {want}");
        let x = d.position_m()[0];
        assert_eq!(s.encoder_raw[0], ((x * 1e6).round() as u32) & 0xFFFF);
        assert_eq!(IoScale::EXCALIBUR.load_cell_n(s.load_cell_counts[0]), 2.0);
        assert!(s.dead_man_closed);
    }

    /// With the outputs off nothing pushes (the hand lets go). With them
    /// on, a duty for 2 N balances the hand's 2 N to its step (6 mN), and
    /// in 0.1 s the mass moves a five-hundredth of the 11 mm the hand alone
    /// moves it.
    #[test]
    fn the_motor_and_the_hand_push_only_with_the_outputs_on() {
        let mut d = device(2.0);
        d.set_duty([IoScale::EXCALIBUR.duty(-5.0)]);
        let s = d.sample();
        assert_eq!((d.velocity_mps()[0], s.load_cell_counts[0]), (0.0, 0));
        let mut d = device(2.0);
        d.set_duty([IoScale::EXCALIBUR.duty(2.0)]);
        d.set_outputs(true);
        for _ in 0..100 {
            d.sample();
        }
        assert!(d.position_m()[0].abs() < 2e-5, "{:?}", d.position_m());
    }

    /// A motor pushing toward the stop stops dead on it and stays, and the
    /// hand lifts the mass off it again.
    #[test]
    fn the_stop_holds_the_mass_and_lets_it_go() {
        let mut d = device(2.0);
        d.set_outputs(true);
        d.set_duty([IoScale::EXCALIBUR.duty(5.0)]);
        for _ in 0..2000 {
            d.sample();
        }
        assert_eq!((d.position_m()[0], d.velocity_mps()[0]), (-0.03, 0.0));
        d.set_duty([0]);
        for _ in 0..100 {
            d.sample();
        }
        assert!(d.position_m()[0] > -0.03 && d.velocity_mps()[0] > 0.0);
    }

    /// Counts round to the nearest, on either side of zero, and wrap to
    /// the counter's bits.
    #[test]
    fn counts_round_to_the_nearest_and_wrap() {
        let d = device(0.0);
        assert_eq!(d.count(0.4e-6), 0);
        assert_eq!(d.count(-0.4e-6), 0);
        assert_eq!(d.count(-0.6e-6), 0xFFFF);
        assert_eq!(d.count(-2.6e-6), 0xFFFD);
        assert_eq!(d.count(65.536e-3), 0);
    }
}
